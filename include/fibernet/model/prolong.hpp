#pragma once
// Carrying a state from one discretization of a network to another (mesh sequencing; docs/wet.md, "Mesh
// sequencing"). Both models discretize the same network, so each fiber is a chain of nodes at known arc positions in
// both, and every crosslink is a node of both. A node of `to` at arc position s of its fiber is placed on the
// segment of `from`'s chain that holds s, at the same fraction of its length: the deformed fiber of `from`, read as
// the polygon through its nodes, sampled at the nodes of `to`. Nodes at the same arc position (fiber ends,
// crosslinks, nodes both schemes share) land exactly where they were.
#include <Eigen/Core>

#include "fibernet/model/model.hpp"

namespace fibernet {

// x_from: positions of `from`'s nodes (2 per node, as Model::x), in a box of matrix B (= F B0); returns positions of
// `to`'s nodes in the same box, each in the periodic image of its reference position (so the fixed segment shifts
// of `to` hold). InputError if the two models do not discretize the same fibers.
Eigen::VectorXd prolong_positions(const Model& from, const Eigen::VectorXd& x_from, const Eigen::Matrix2d& B,
                                  const Model& to);

}  // namespace fibernet
