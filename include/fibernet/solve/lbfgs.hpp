#pragma once
// Native limited-memory BFGS (Nocedal & Wright Alg. 7.4/7.5, two-loop recursion) with the strong-Wolfe line
// search of line_search.hpp; parameters after LBFGSpp's LBFGSParam (check() names the bad value).
//
// Two variants, one class:
//  "lbfgs":          H0 = gamma I with gamma = s.y / y.y of the newest pair (the usual scaling).
//  "lbfgs-hessian":  H0 = (H(q_k) + shift I)^-1 from a sparse Cholesky factorization (CHOLMOD, supernodal LL^T)
//                    of the element-wise PSD-projected Hessian at some earlier iterate q_k. The factorization is
//                    reused across iterations and redone only when the line search fails, when the direction is
//                    not a descent direction, or when max|g| has not halved in `refactor_stall` iterations.
//                    Its first step is a (projected) Newton step; later steps are quasi-Newton corrections of it.
#include <memory>
#include <string>

#include "fibernet/solve/line_search.hpp"
#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct LbfgsParams {
    int m = 10;                      // number of (s, y) pairs kept
    LineSearchParams line_search;    // strong Wolfe, c2 = 0.9
    bool hessian_h0 = false;         // "lbfgs-hessian": factorized Hessian as H0
    double shift = 1e-10;            // H0 = (H + shift * max(diag H) I)^-1, raised x100 while factorization fails
    int refactor_stall = 20;         // refactor when max|g| has not halved in this many iterations (0 = never)
    int max_restarts = 3;            // consecutive memory resets after a failed line search before giving up
    int stall_iterations = 20;       // Stalled after this many iterations with neither an energy decrease beyond
                                     // round-off nor a new minimum of max|g|
    double max_move = 1.0;           // first trial step moves no coordinate by more than this (seed units);
                                     // the line search extrapolates beyond it when the energy keeps falling

    // Throws InputError("<where>: <name> = <v> must ...").
    void check(const std::string& where) const;
};

class LbfgsSolver : public Solver {
public:
    LbfgsSolver(const SolverOptions& opt, const LbfgsParams& p = {});
    std::string name() const override { return p_.hessian_h0 ? "lbfgs-hessian" : "lbfgs"; }
    SolverOptions& options() override { return opt_; }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override;
    SolverCapabilities capabilities() const override;
    std::unique_ptr<Solver> clone() const override { return std::make_unique<LbfgsSolver>(opt_, p_); }

private:
    SolverOptions opt_;
    LbfgsParams p_;
};

}  // namespace fibernet
