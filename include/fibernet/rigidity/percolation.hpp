#pragma once
// Rigidity and connectivity percolation samples (issue 4 part 4; seed §3, figure 3.6): an open L x L Mikado
// network with clamps at the bottom and top edges spans rigidly when d = 0 and spans by connectivity when a
// chain of crosslinks joins the clamps.
#include <cstdint>

namespace fibernet {

struct PercolationSample {
    double pl = 0, L = 0, q = 0;
    int sample = 0;
    std::uint64_t seed = 0;
    int fibers = 0;     // fibers inside the clamped strip
    int d = 3;
    bool rigid = false, connected = false;
    double seconds = 0; // generation + clamping + pebble game
};

// The seed of sample `sample` at (L, q): derived from the values, so adding L or q values or samples to a run
// never changes another sample's network.
std::uint64_t percolation_seed(std::uint64_t base_seed, double L, double q, int sample);

PercolationSample percolation_sample(double pl, double L, double q, int sample, std::uint64_t base_seed);

}  // namespace fibernet
