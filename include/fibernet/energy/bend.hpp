#pragma once
// Bending energy of one hinge (seed eq. 4.15): E = (2 / lt0) (1 - cos phi), cos phi = d1.d2 / (|d1| |d2|),
// with d1, d2 the two consecutive segment vectors of one fiber at the hinge node. Exact for any angle
// (the cosine form is smooth through phi = pi, no arccos).
#include <Eigen/Core>
#include <vector>

#include "fibernet/energy/element_term.hpp"

namespace fibernet {

// Value, and where non-null the gradient (d1, d2 stacked) and 4x4 Hessian with respect to (d1, d2).
double bend_energy(const Eigen::Vector2d& d1, const Eigen::Vector2d& d2, double lt0, Eigen::Vector4d* grad,
                   Eigen::Matrix4d* hess);

// The bending term over a model's hinges (element: the hinge's nodes i, j, k; d1 = x_j - x_i, d2 = x_k - x_j plus
// their box images).
class BendTerm : public ElementTerm {
public:
    explicit BendTerm(const Model& m);  // keeps a reference to m
    const char* name() const override { return "bend"; }
    int valence() const override { return 3; }
    std::size_t size() const override { return m_.hinges.size(); }
    void nodes(std::size_t e, int* out) const override;
    void evaluate(std::size_t e, const ElementFrame& frame, const ElementWant& want, ElementResult& out) const override;

private:
    const Model& m_;
    std::vector<Eigen::Vector2d> d0_;  // 2 rest vectors per hinge
};

}  // namespace fibernet
