#pragma once
// Network -> Model. Two schemes (DESIGN.md §2, "Discretization"):
//  seed: n_seg equal segments per fiber, each split at every crosslink (seed §4.1.1); makes very short segments.
//  even: crosslinks (and fiber ends) are nodes; each piece between them is split into ceil(length / h) equal segments.
#include <string>

#include "fibernet/model/model.hpp"
#include "fibernet/network/network.hpp"

namespace fibernet {

enum class Scheme { Seed, Even };
Scheme parse_scheme(const std::string& s);  // "seed" | "even"
std::string to_string(Scheme s);

struct DiscretizationParams {
    Scheme scheme = Scheme::Seed;
    int n_seg = 10;             // seed scheme: segments per fiber before splitting
    double h = 1.0;             // even scheme: target segment length (seed units)
    double fiber_length = 10;   // lf in seed units (ls = lf / 10 defines the unit of length)
    double aspect_ratio = 10;   // a = ls / r
    // Drop each fiber's end arms beyond its outermost crosslinks (and fibers with no crosslink). Exact for dry
    // equilibria and moduli: a load-free arm stays straight with zero energy and exerts no force or moment on its
    // pin whatever the pin does, so the kept nodes and their equilibrium are unchanged (docs/moduli.md, "Pruning").
    // Not for wet networks or clamped open boxes: bridges and clamps act on the arms.
    bool trim_ends = false;

    void check(const std::string& where) const;  // throws InputError naming the bad value
};

Model discretize(const Network& net, const DiscretizationParams& p);

}  // namespace fibernet
