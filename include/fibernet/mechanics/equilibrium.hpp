#pragma once
// Mechanical equilibrium of a network at a fixed box deformation F: minimize E(q, F) over the free coordinates.
// A changed strain starts from the affinely mapped state (issue 3): the reference positions, or a previous
// equilibrium at F_start, mapped by F F_start^{-1}. Optionally (linear_start), a start from the reference adds the
// linear non-affine response: q0 = q_ref + dq/dt along F(t) = I + t (F - I), dq/dt = -H^+ E_xt from one
// factorization at the reference (moduli.hpp). It is not the default: at gamma = 0.01 it cut Newton's
// iterations on the L = 10 benchmark network from 80 to 28 but raised them on L = 20 from 160 to over 300
// (the linear response overshoots where compressed fibers buckle); it falls back to the affine start if the
// linear solve fails.
#include <Eigen/Core>
#include <string>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct Equilibrium {
    Eigen::VectorXd q;       // free coordinates at the returned state
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    SolveResult result;      // status says whether q is an equilibrium
    double energy = 0, stretch = 0, bend = 0;
    std::string start;       // "affine" or "linear_response"

    bool converged() const { return result.converged(); }
};

// The reference state (model.x) mapped affinely to F.
Eigen::VectorXd affine_start(const NetworkEnergy& e, const Eigen::Matrix2d& F);

// Minimizes E(., F) with `solver` from `start` (taken at F_start) mapped affinely to F; from affine_start(F)
// when start is null.
// linear_start: use the linear-response start when starting from the reference (start == nullptr). Its one
// factorization and its time are added to the result's counts.
Equilibrium relax(const NetworkEnergy& e, const Eigen::Matrix2d& F, Solver& solver,
                  const Eigen::VectorXd* start = nullptr, const Eigen::Matrix2d& F_start = Eigen::Matrix2d::Identity(),
                  bool linear_start = false);

}  // namespace fibernet
