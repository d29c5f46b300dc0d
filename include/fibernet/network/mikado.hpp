#pragma once
// Mikado generator (DESIGN.md §2): N = round(q L^2) fibers of unit length, centres uniform in the L x L box,
// orientations uniform in [0, pi); every crossing is a crosslink with probability pl.
#include <cstdint>
#include <string>

#include "fibernet/network/network.hpp"

namespace fibernet {

struct MikadoParams {
    double L = 10;       // box side in fiber lengths
    double q = 8;        // density N lf^2 / A
    double pl = 1;       // crosslink probability
    std::uint64_t seed = 1;
    bool periodic = true;

    // Throws InputError naming the bad value; `where` says where the values came from.
    void check(const std::string& where) const;
};

Network generate_mikado(const MikadoParams& p);

// Finds every crossing with a cell list (O(N)); periodic images included. Crossings come out sorted by
// (f1, f2) with crosslink = false.
std::vector<Crossing> find_crossings(const Network& net);

// Reference O(N^2) search over all pairs and all 9 images; for tests.
std::vector<Crossing> find_crossings_brute_force(const Network& net);

// Marks each crossing as a crosslink with probability pl, from its own random stream.
void assign_crosslinks(Network& net, double pl, std::uint64_t seed);

}  // namespace fibernet
