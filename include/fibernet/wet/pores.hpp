#pragma once
// Pores of a fiber network (issue 6): the faces of the planar graph formed by all fibers at their current positions,
// with every crossing of two segments (free or crosslinked) as a vertex. In a periodic box the graph lives on a
// torus: edges carry their unwrapped vectors and each face is traced as a closed polygon of them.
//
// Faces are traced with the face on the left (half-edge `next` = the outgoing edge just clockwise of the reverse
// edge), so a pore's boundary runs counter-clockwise and its shoelace area is positive. Each crossing is one point
// on both segments, and pieces shorter than 1e-9 L are contracted (fibers zipped on top of each other). A traced
// cycle that winds around the torus (`open_cycles`), or has no positive area (the outer boundary of a component: the
// outside of an open network, or an island), bounds no pore; a closed face with an island inside (the smallest such
// face of another component around a point of it) is not a disk and is no pore either. The box area not covered by
// pores is reported as `remainder`.
#include <Eigen/Core>
#include <vector>

#include "fibernet/model/model.hpp"

namespace fibernet {

struct Pore {
    double area = 0;
    double diameter = 0;   // equivalent diameter sqrt(4 A / pi)
    int edges = 0;
};

struct PoreStats {
    std::vector<Pore> pores;   // every closed face of positive area that is a disk (no island inside)
    double box_area = 0;
    double remainder = 0;      // box area - sum of pore areas (outer / non-disk faces)
    int vertices = 0, edges = 0;
    int open_cycles = 0;  // face boundaries that wind around the torus (whole box vectors summing to non-zero)
    int islands = 0;      // components inside a closed face (which then goes to the remainder)
};

// Pores at node positions x in the box with matrix B (model units).
PoreStats pores(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B);

}  // namespace fibernet
