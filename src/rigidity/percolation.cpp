#include "fibernet/rigidity/percolation.hpp"

#include <chrono>
#include <cstring>

#include "fibernet/network/clamp.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/rigidity.hpp"
#include "fibernet/util/random.hpp"

namespace fibernet {

namespace {
std::uint64_t bits(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return b;
}
}  // namespace

std::uint64_t percolation_seed(std::uint64_t base, double L, double q, int sample) {
    return derive_seed(derive_seed(derive_seed(base, bits(L)), bits(q)), static_cast<std::uint64_t>(sample));
}

PercolationSample percolation_sample(double pl, double L, double q, int sample, std::uint64_t base) {
    const auto t0 = std::chrono::steady_clock::now();
    PercolationSample s;
    s.pl = pl, s.L = L, s.q = q, s.sample = sample;
    s.seed = percolation_seed(base, L, q, sample);
    const ClampedNetwork cl = clamp_network(generate_mikado({L, q, pl, s.seed, false}));
    const RigidityResult r = analyze_rigidity(body_pin_framework(cl));
    s.fibers = r.fibers;
    s.d = r.d;
    s.rigid = r.rigid_spanning;
    s.connected = r.connected_spanning;
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
}

}  // namespace fibernet
