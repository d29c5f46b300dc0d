#pragma once
// Adapters to NLopt's gradient-based local optimizers (Luksan's codes): "nlopt-lbfgs" (LD_LBFGS),
// "nlopt-tnewton" (LD_TNEWTON_PRECOND_RESTART) and "nlopt-var2" (LD_VAR2, shifted limited-memory
// variable metric, rank 2).
//
// NLopt stops on its own criteria (relative x/f changes, round-off), not on max|g|. The adapter therefore
// watches every gradient NLopt asks for and stops NLopt (forced_stop) at the first point with max|g| <= tol;
// whatever NLopt's own reason for stopping otherwise, the result is Converged only if max|g| <= tol at the
// returned point (re-evaluated), and NLopt's reason is kept in the message:
//   SUCCESS/FTOL/XTOL/STOPVAL_REACHED, ROUNDOFF_LIMITED -> Stalled;  MAXEVAL/MAXTIME_REACHED -> IterationLimit;
//   FAILURE and others -> Failed (NonFinite if the returned point has a non-finite energy or gradient).
// The returned point is the lowest energy NLopt evaluated. SolverOptions::max_iter bounds evaluations
// (NLopt counts no iterations); max_seconds maps to maxtime and is also checked at every evaluation, since NLopt
// checks maxtime only between its outer iterations (TNEWTON overran a 4 s budget to 31 s without this).
#include <memory>
#include <string>

#include "fibernet/solve/solver.hpp"

namespace fibernet {

enum class NloptMethod { Lbfgs, TNewton, Var2 };

struct NloptParams {
    int vector_storage = 10;  // memory m of the quasi-Newton updates (NLopt's vector_storage), 0 = NLopt's default
    double xtol_rel = 0;      // NLopt's own stopping tests, off by default: max|g| <= tol decides
    double ftol_rel = 0;

    void check(const std::string& where) const;
};

class NloptSolver : public Solver {
public:
    NloptSolver(NloptMethod method, const SolverOptions& opt, const NloptParams& p = {});
    std::string name() const override;
    SolverOptions& options() override { return opt_; }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override;
    SolverCapabilities capabilities() const override { return {}; }
    std::unique_ptr<Solver> clone() const override { return std::make_unique<NloptSolver>(method_, opt_, p_); }

private:
    NloptMethod method_;
    SolverOptions opt_;
    NloptParams p_;
};

}  // namespace fibernet
