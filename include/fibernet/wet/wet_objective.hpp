#pragma once
// What the wet moduli and stress need of a wet energy beyond a solver's view (objective.hpp): the dry energy it adds
// to, its box deformation, and its derivatives along a strain path. Implemented by the event model's WetEnergy
// (wet_energy.hpp) and the smooth model's SmoothWetEnergy (smooth_wet_energy.hpp).
#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/objective.hpp"

namespace fibernet {

class WetObjective : public Objective {
public:
    // dE/dt, d2E/dq dt, d2E/dt2 along F(t) = F + t dF at fixed q (comoving: along the affine path of every node,
    // kComoving); `out` gets the dry terms' and the capillary terms' (its gradient is not filled).
    virtual void strain_derivatives(const Eigen::VectorXd& q, const Eigen::Matrix2d& dF, EnergyEval& out,
                                    bool comoving = false) const = 0;
    virtual const NetworkEnergy& dry() const = 0;
    virtual const Eigen::Matrix2d& F() const = 0;
};

// Adds one capillary element's strain terms to `out` (WetObjective::strain_derivatives): the element of M nodes
// (node[a] < 0: absent, its coordinates zero) at local coordinates X with gradient g and Hessian H there. Its nodes
// move with F only through their periodic images and fixed nodes (X_a = x_a + F B0 shift_a, x_a = F x_ref for a fixed
// node), so dX_a/dt = w_a = dF r_a with r_a = B0 shift_a (+ x_ref for a fixed node), and its terms are g.w, H w and
// w.H w. comoving: along the affine path of every node, w_a = dF F^-1 (X_a - X_first) (each element is translation
// invariant, so only its own extent enters).
// The rate dX/dt = w of an element's local coordinates along the strain path (add_strain_terms below).
template <int M>
Eigen::Matrix<double, 2 * M, 1> strain_rate(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const Eigen::Matrix2d& dF,
                                            bool comoving, const int* node, const Eigen::Vector2i* shift,
                                            const Eigen::Matrix<double, 2 * M, 1>& X) {
    const Model& m = dry.model();
    const Eigen::Matrix2d B0 = m.box.B0(), V = dF * F.inverse();
    Eigen::Matrix<double, 2 * M, 1> w = Eigen::Matrix<double, 2 * M, 1>::Zero();
    int first = -1;
    for (int a = 0; a < M; ++a) {
        if (node[a] < 0) continue;
        if (first < 0) first = a;
        if (comoving) {
            w.template segment<2>(2 * a) = V * (X.template segment<2>(2 * a) - X.template segment<2>(2 * first));
            continue;
        }
        Eigen::Vector2d r = B0 * shift[a].template cast<double>();
        if (dry.dof(node[a], 0) < 0) r += m.x.segment<2>(2 * node[a]);  // a fixed node sits at F x_ref
        w.template segment<2>(2 * a) = dF * r;
    }
    return w;
}

template <int M>
void add_strain_terms(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const Eigen::Matrix2d& dF, bool comoving,
                      const int* node, const Eigen::Vector2i* shift, const Eigen::Matrix<double, 2 * M, 1>& X,
                      const Eigen::Matrix<double, 2 * M, 1>& g, const Eigen::Matrix<double, 2 * M, 2 * M>& H,
                      EnergyEval& out) {
    const Eigen::Matrix<double, 2 * M, 1> w = strain_rate<M>(dry, F, dF, comoving, node, shift, X);
    Eigen::Matrix<double, 2 * M, 1> Hw;
    Hw.noalias() = H * w;
    out.dE_dt += g.dot(w);
    const double tt = w.dot(Hw);
    out.d2E_dt2 += tt;
    out.d2E_dt2_size += std::abs(tt);
    for (int a = 0; a < M; ++a)
        for (int c = 0; c < 2 && node[a] >= 0; ++c) {
            const int r = dry.dof(node[a], c);
            if (r >= 0) out.d2E_dqdt[r] += Hw[2 * a + c];
        }
}

}  // namespace fibernet
