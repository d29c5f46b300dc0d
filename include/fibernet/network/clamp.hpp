#pragma once
// Clamped open box (issue 4, DESIGN.md §2): fibers are cut at the bottom (y = 0) and top (y = L) edges; the
// parts outside 0 <= y <= L are dropped with their crossings, and each cut end is pinned to a clamp body:
// the bottom clamp (grounded) or the top clamp (moved sideways under shear). The sides stay free.
#include <vector>

#include "fibernet/network/network.hpp"

namespace fibernet {

enum class Clamp { Bottom = 0, Top = 1 };

struct ClampPin {
    int fiber = 0;   // fiber of ClampedNetwork::net
    double s = 0;    // arc position of the cut end (0 or the fiber's length)
    Clamp clamp = Clamp::Bottom;
};

struct ClampedNetwork {
    Network net;                     // trimmed fibers (start moved to the cut), crossings re-based and kept in order
    std::vector<ClampPin> pins;      // one per cut end
    std::vector<int> original_fiber;  // index in the input network of each kept fiber
};

// Throws InputError for a periodic network (clamps need an open box).
ClampedNetwork clamp_network(const Network& net);

}  // namespace fibernet
