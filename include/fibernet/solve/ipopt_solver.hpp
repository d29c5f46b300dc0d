#pragma once
// Adapter to Ipopt (3.11, TNLP interface) for the unconstrained problem min f(q): no constraints, no bounds,
// the exact sparse Hessian (Ipopt wants the lower triangle: the upper pattern, transposed), so Ipopt runs a
// Newton method with its own inertia correction (H + delta I) and filter line search.
//
// Tolerance: with no constraints and no bounds Ipopt's optimality error is its dual infeasibility, the max norm
// of the gradient, once objective scaling is off (nlp_scaling_method = none) and "acceptable" termination is
// disabled (acceptable_iter = 0). So tol = dual_inf_tol = SolverOptions::tol. The status is decided from
// max|g| at the returned point, evaluated afresh, not from Ipopt's own measure. Ipopt's statuses map as
//   Solve_Succeeded / Solved_To_Acceptable_Level with max|g| > tol, Search_Direction_Becomes_Too_Small -> Stalled;
//   Maximum_Iterations/CpuTime_Exceeded, our wall-time stop -> IterationLimit; Restoration_Failed ->
//   LineSearchFailed; Invalid_Number_Detected -> NonFinite; anything else -> Failed.
// A point outside the domain (+inf energy) is an evaluation error, on which Ipopt cuts the step.
#include <memory>
#include <string>

#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct IpoptParams {
    std::string linear_solver;   // Ipopt's linear_solver option; empty = Ipopt's default (MUMPS on Debian)
    int print_level = 0;         // Ipopt's own output (0-12); progress lines come from the adapter
    bool exact_hessian = true;   // false = Ipopt's limited-memory quasi-Newton (hessian_approximation)

    void check(const std::string& where) const;
};

class IpoptSolver : public Solver {
public:
    IpoptSolver(const SolverOptions& opt, const IpoptParams& p = {});
    std::string name() const override { return "ipopt"; }
    SolverOptions& options() override { return opt_; }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override;
    SolverCapabilities capabilities() const override;
    std::unique_ptr<Solver> clone() const override { return std::make_unique<IpoptSolver>(opt_, p_); }

private:
    SolverOptions opt_;
    IpoptParams p_;
};

}  // namespace fibernet
