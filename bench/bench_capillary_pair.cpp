// Cost of the smooth wet model's pair term (capillary_pair.hpp) per call: value alone, value and gradient, value,
// gradient and Hessian, on random segment pairs of length l (our RNG, so the same pairs on every machine): half of
// them crossings at 25-85 deg (crossing term, through the angle blend at the low end), half near-parallel contacts at
// 0-15 deg within the contact distance (contact term and blend). The best of the repetitions is reported, with a
// checksum of the results (the same on one machine for two builds that compute the same numbers).
// Segment length l: 0.1 by default (then every crossing lies within the crossing width eps = 0.1 of a node, inside
// its shares' smoothing); 0.8 is the mean segment of the networks the wet studies use (seed scheme, a = 10), where most
// crossings and contacts lie outside their smoothing windows.
//   bench_capillary_pair [pairs=20000] [reps=7] [seed=1] [length=0.1]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fibernet/util/random.hpp"
#include "fibernet/wet/capillary_pair.hpp"

using namespace fibernet;

namespace {
using Clock = std::chrono::steady_clock;

// Segment a from the origin along x, segment b through a point near a's middle at angle `deg`, offset across a by up
// to `offset`.
Vector8d pair_at(Rng& rng, double l, double deg, double offset) {
    const double t = deg * M_PI / 180, cx = rng.uniform(0.2, 0.8) * l, cy = rng.uniform(-offset, offset);
    const double s = rng.uniform(0.3, 0.7) * l;
    Vector8d X;
    X << 0, 0, l, 0, cx - s * std::cos(t), cy - s * std::sin(t), cx + (l - s) * std::cos(t), cy + (l - s) * std::sin(t);
    return X;
}
}  // namespace

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 20000;
    const int reps = argc > 2 ? std::atoi(argv[2]) : 7;
    Rng rng(argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 1);
    CapillaryPairParams p;  // the defaults of a = 10: crossing width 0.1, contact 0.2, overlap width 0.1
    p.beta = 1;
    const double l = argc > 4 ? std::atof(argv[4]) : 0.1;
    std::vector<Vector8d> X;
    for (int k = 0; k < n; ++k)
        X.push_back(k % 2 ? pair_at(rng, l, rng.uniform(25, 85), 0.0) : pair_at(rng, l, rng.uniform(0, 15), p.contact));
    Vector8d g;
    Matrix8d H;
    const char* names[3] = {"value", "gradient", "hessian"};
    for (int mode = 0; mode < 3; ++mode) {
        double best = HUGE_VAL, sum = 0;
        int nonzero = 0;
        for (int r = 0; r < reps; ++r) {
            sum = 0, nonzero = 0;
            const auto t0 = Clock::now();
            for (const Vector8d& x : X) {
                const double e = capillary_pair_energy(x, l, l, true, p, mode >= 1 ? &g : nullptr,
                                                       mode == 2 ? &H : nullptr, false);
                sum += e + (mode >= 1 ? g[3] : 0.0) + (mode == 2 ? H(2, 5) : 0.0);
                nonzero += e != 0;
            }
            best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
        }
        std::printf("%-8s %.3f us per pair  (%d of %d pairs non-zero; checksum %.17g)\n", names[mode], 1e6 * best / n,
                    nonzero, n, sum);
    }
    return 0;
}
