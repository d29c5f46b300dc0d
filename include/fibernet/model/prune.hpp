#pragma once
// Pruning parts of a network that cannot carry load (DESIGN.md §3). Each rule provably leaves the equilibrium
// energy, stress and moduli unchanged; tests/mechanics compare results with and without.
//  dangling:    repeatedly remove fibers with fewer than two crosslinks (a fiber pinned at one point or none
//               rotates/translates freely and stays stress-free).
//  nonspanning: in a periodic box, remove crosslink clusters that do not wrap around the box (such a cluster is
//               isometric to a finite one and relaxes to zero energy under any box strain).
#include <string>
#include <vector>

#include "fibernet/network/network.hpp"

namespace fibernet {

struct PruneOptions {
    bool dangling = false;
    bool nonspanning = false;
};

// Returns the pruned network; kept[i] is the original index of fiber i of the result. Where a pruned fiber was
// pinned to a kept one, the kept fiber gets a breakpoint there, so its nodes and segments are exactly those of the
// unpruned model and results agree to solver precision, not just to discretization error.
Network prune(const Network& net, const PruneOptions& opt, std::vector<int>* kept = nullptr);

// True per fiber if its crosslink cluster wraps around the periodic box (false for every fiber in an open box).
std::vector<char> wrapping_fibers(const Network& net);

}  // namespace fibernet
