#pragma once
// FNV-1a, for fingerprints that only need to tell things apart (bridge sets between active-set rounds, a network
// file's content in a sweep checkpoint), not for random numbers (random.hpp). One step folds in a 32-bit unit: a
// byte of a file or an int of a key.
#include <cstdint>
#include <string>

namespace fibernet {

constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;
constexpr std::uint64_t fnv1a(std::uint64_t h, std::uint32_t unit) { return (h ^ unit) * 1099511628211ull; }

// A file's (or any text's) fingerprint: its bytes, one step each.
inline std::uint64_t fnv1a_bytes(const std::string& bytes) {
    std::uint64_t h = kFnvOffset;
    for (unsigned char c : bytes) h = fnv1a(h, c);
    return h;
}

}  // namespace fibernet
