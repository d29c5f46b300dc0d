#pragma once
// Bending energy of one hinge (seed eq. 4.15): E = (2 / lt0) (1 - cos phi), cos phi = d1.d2 / (|d1| |d2|),
// with d1, d2 the two consecutive segment vectors of one fiber at the hinge node. Exact for any angle
// (the cosine form is smooth through phi = pi, no arccos).
#include <Eigen/Core>

namespace fibernet {

// Value, and where non-null the gradient (d1, d2 stacked) and 4x4 Hessian with respect to (d1, d2).
double bend_energy(const Eigen::Vector2d& d1, const Eigen::Vector2d& d2, double lt0, Eigen::Vector4d* grad,
                   Eigen::Matrix4d* hess);

}  // namespace fibernet
