#pragma once
// Portable random numbers: xoshiro256** seeded through splitmix64, with our own uniform and Bernoulli
// draws. std:: distributions differ between standard libraries, so none are used: the same seed gives
// the same network on every platform.
#include <cstdint>

namespace fibernet {

class Rng {
public:
    explicit Rng(std::uint64_t seed);
    std::uint64_t next();
    // Uniform double in [0, 1) with 53 random bits.
    double uniform();
    // Uniform double in [a, b).
    double uniform(double a, double b) { return a + (b - a) * uniform(); }
    // true with probability p (p = 1 is always true, p = 0 never).
    bool bernoulli(double p) { return uniform() < p; }

private:
    std::uint64_t s_[4];
};

// A stream independent of the parent's for sub-tasks (e.g. crosslink draws, wet fractions):
// derived from the seed and a fixed tag so adding draws in one stage never shifts another.
std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t tag);

}  // namespace fibernet
