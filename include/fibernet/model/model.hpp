#pragma once
// The discretized elastic network (seed §4.1.1): nodes joined by straight segments along each fiber,
// hinges at interior nodes, crosslinks as shared supernodes (free pins: no bending couples two fibers).
// Lengths in seed units: ls = lf / 10, so a fiber has length `fiber_length` = 10 unless a scene says otherwise.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "fibernet/box/box.hpp"

namespace fibernet {

struct Segment {
    int i = 0, j = 0;           // nodes; d = x_j - x_i + B shift
    Eigen::Vector2i shift{0, 0};
    double l0 = 0;              // rest length
    int fiber = 0;
    // Rest vector (length l0 along the straight fiber). NaN: derive it from the reference positions.
    Eigen::Vector2d d0{NAN, NAN};
};

struct Hinge {
    int i = 0, j = 0, k = 0;    // the bend is at j; d1 = x_j - x_i + B shift1, d2 = x_k - x_j + B shift2
    Eigen::Vector2i shift1{0, 0}, shift2{0, 0};
    double lt0 = 0;             // rest effective length (l0_left + l0_right) / 2 (seed eq. 4.9)
    int fiber = 0;
    Eigen::Vector2d d10{NAN, NAN}, d20{NAN, NAN};  // rest vectors of the two segments (NaN: from positions)
};

struct Supernode {
    int node = 0;
    std::vector<int> crossings;  // network crossings pinned here (one, unless hand-made pins coincide)
};

// The node chain of one fiber, in order from its start.
struct FiberChain {
    std::vector<int> nodes;
    std::vector<double> s;         // arc position of each node from the fiber start (seed units)
    std::vector<int> segments;     // segments[k] joins nodes[k] and nodes[k+1]
};

struct Model {
    Box box;                        // model units
    double aspect_ratio = 10;       // a = ls / r (seed eq. 4.13)
    double fiber_length = 10;       // lf in seed units
    Eigen::VectorXd x;              // reference node positions, interleaved (x0, y0, x1, y1, ...), wrapped into the box
    std::vector<char> fixed;        // per node: position prescribed as F * x_ref (clamps); default none
    std::vector<Segment> segments;
    std::vector<Hinge> hinges;
    std::vector<Supernode> supernodes;
    std::vector<FiberChain> chains;  // one per network fiber
    std::vector<int> crossing_node;  // per network crossing: its supernode's node, or -1 for a free crossing

    int num_nodes() const { return static_cast<int>(x.size() / 2); }
};

struct ModelSummary {
    int nodes = 0, dofs = 0, segments = 0, hinges = 0, supernodes = 0, fibers = 0;
    double shortest_segment = 0, longest_segment = 0, mean_segment = 0;
};
ModelSummary summarize(const Model& m);

}  // namespace fibernet
