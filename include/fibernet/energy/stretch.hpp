#pragma once
// Stretching energy of one segment (seed eq. 4.14) with a softcore below eps* (seed §4.1.4).
//
//   E(d) = 4 a^2 l0 f(eps),  eps = |d| / l0 - 1
//   f(eps) = eps^2                          for eps >= eps*   (harmonic; eps* = -0.95)
//   f(eps) = eps^2 + k_sc h(u)              for eps <  eps*,  u = 1 + eps = l / l0,  u* = 1 + eps*
//   h(u)   = 1/u - 1/u* + (u - u*)/u*^2 - (u - u*)^2/u*^3,   k_sc = u*^3
//
// h(u*) = h'(u*) = h''(u*) = 0, so f is C2 at eps* (Newton sees a continuous Hessian), and h ~ 1/u diverges as
// the segment collapses (eps -> -1). With k_sc = u*^3 the softcore adds k_sc h''(u) = 2 (u*/u)^3 - 2 to f''=2: the
// curvature doubles at u = u*/2^(1/3) and grows like u^-3 below.
#include <Eigen/Core>
#include <vector>

#include "fibernet/energy/element_term.hpp"

namespace fibernet {

struct StretchLaw {
    double eps_star = -0.95;

    // f, f' and f'' at eps (f = +inf for eps <= -1).
    void eval(double eps, double& f, double& df, double& d2f) const;
};

// One segment as a function of its vector d. Writes the value and, where non-null, the gradient and Hessian
// with respect to d. k = 4 a^2.
double stretch_energy(const Eigen::Vector2d& d, double l0, double k, const StretchLaw& law, Eigen::Vector2d* grad,
                      Eigen::Matrix2d* hess);

// The stretching term over a model's segments (element: the segment's nodes i, j).
class StretchTerm : public ElementTerm {
public:
    StretchTerm(const Model& m, StretchLaw law);  // keeps a reference to m
    const char* name() const override { return "stretch"; }
    int valence() const override { return 2; }
    std::size_t size() const override { return m_.segments.size(); }
    void nodes(std::size_t e, int* out) const override;
    void evaluate(std::size_t e, const ElementFrame& frame, const ElementWant& want, ElementResult& out) const override;

private:
    const Model& m_;
    StretchLaw law_;
    double k_;                             // 4 a^2
    std::vector<Eigen::Vector2d> d0_;      // rest vectors
};

}  // namespace fibernet
