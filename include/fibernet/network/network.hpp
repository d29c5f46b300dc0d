#pragma once
// A network of straight fibers in a square box, in units of the fiber length (a Mikado fiber has length 1).
// Crossings are the points where two fibers (or a fiber and a periodic image of another) intersect;
// each is a crosslink (a pin, seed §3.2) or a free crossing (a site for a capillary bridge).
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

namespace fibernet {

struct Fiber {
    Eigen::Vector2d start;  // one end, unwrapped; the fiber runs start -> start + length * direction()
    double theta = 0;       // orientation in [0, pi)
    double length = 1;
    // Extra node positions (arc, fiber lengths) the discretization must keep: where pruned fibers were pinned to
    // this one, so that pruning leaves the discretization of every kept fiber unchanged (model/prune.hpp).
    std::vector<double> breakpoints;

    Eigen::Vector2d direction() const { return {std::cos(theta), std::sin(theta)}; }
    Eigen::Vector2d point(double s) const { return start + s * direction(); }
    Eigen::Vector2d center() const { return point(0.5 * length); }
};

struct Crossing {
    int f1 = 0, f2 = 0;       // fiber indices, f1 < f2
    double s1 = 0, s2 = 0;    // arc positions along f1 and f2 from their starts
    Eigen::Vector2i image{0, 0};  // fiber f2 is taken at its periodic image shifted by L * image
    bool crosslink = false;
};

struct Network {
    double L = 1;          // box side in fiber lengths (the Model's Box::L is in seed units, 10x larger)
    bool periodic = true;
    std::vector<Fiber> fibers;
    std::vector<Crossing> crossings;  // sorted by (f1, f2)

    // Provenance, written to files; not used by any computation.
    std::uint64_t seed = 0;
    double q = 0, pl = 0;

    int num_crosslinks() const;
};

// Crossing of fiber a with fiber b shifted by `shift`; true and the arc positions if the segments intersect.
bool intersect(const Fiber& a, const Fiber& b, const Eigen::Vector2d& shift, double& sa, double& sb);
// The same with the fibers given by start, unit direction and length (directions precomputed in hot loops).
bool intersect(const Eigen::Vector2d& a0, const Eigen::Vector2d& ua, double la, const Eigen::Vector2d& b0,
               const Eigen::Vector2d& ub, double lb, double& sa, double& sb);

struct NetworkStats {
    int fibers = 0, crossings = 0, crosslinks = 0;
    double crossings_per_fiber = 0, crosslinks_per_fiber = 0;
    int components = 0;          // connected components of the crosslink graph (isolated fibers count)
    int largest_component = 0;   // fibers in the largest one
};
NetworkStats statistics(const Network& net);

// Component label of each fiber in the crosslink graph (labels 0..k-1, ordered by first fiber).
std::vector<int> crosslink_components(const Network& net);

}  // namespace fibernet
