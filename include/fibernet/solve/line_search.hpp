#pragma once
// Strong-Wolfe line search (Nocedal & Wright, Numerical Optimization, 2nd ed., Alg. 3.5 + 3.6 "zoom", with
// safeguarded cubic interpolation), shared by the native L-BFGS and nonlinear CG solvers.
//
// Two additions for this problem:
//  - The energy is +inf outside its domain (a collapsed segment) and may be NaN after overflow: a non-finite
//    trial point counts as "too far" and the bracket shrinks by 10 towards the last good step.
//  - Near a minimum the energy change of a step falls below round-off, where the Armijo test is noise. A step
//    is then also accepted by the approximate Wolfe test of Hager & Zhang (SIAM J. Optim. 16, 2005):
//    f(a) <= f0 + roundoff max(|f0|, f_scale) and phi'(a) <= (2 c1 - 1) phi'(0), i.e. by its slope alone.
#include <Eigen/Core>
#include <string>

#include "fibernet/energy/objective.hpp"

namespace fibernet {

struct LineSearchParams {
    double c1 = 1e-4;         // sufficient decrease (Armijo), 0 < c1 < c2
    double c2 = 0.9;          // curvature, |phi'(a)| <= c2 |phi'(0)|, c2 < 1 (use ~0.1 for nonlinear CG)
    int max_evals = 40;       // function+gradient evaluations per search
    double min_step = 1e-20;  // smallest step (relative to the initial one) before giving up
    double max_step = 1e20;   // largest step
    double extrapolate = 4;   // step growth factor while still descending, > 1
    double roundoff = 1e-10;  // energy change, relative to max(|f0|, f_scale), treated as round-off

    // Throws InputError("<where>: line_search.<name> = <v> must ...").
    void check(const std::string& where) const;
};

enum class LineSearchOutcome {
    Ok,          // strong Wolfe (or approximate Wolfe) step found
    Decrease,    // evaluation budget or bracket exhausted, but a step with sufficient decrease was found
    NotDescent,  // phi'(0) >= 0: d is not a descent direction
    Failed,      // no step with sufficient decrease (budget spent or the bracket shrank to nothing)
    NonFinite,   // every trial was NaN/inf, down to the smallest step
};
std::string to_string(LineSearchOutcome o);

struct LineSearchResult {
    LineSearchOutcome outcome = LineSearchOutcome::Failed;
    double alpha = 0;  // accepted step
    double f = 0;      // energy at x0 + alpha d
    int evals = 0;
    bool ok() const { return outcome == LineSearchOutcome::Ok || outcome == LineSearchOutcome::Decrease; }
};

class StrongWolfeLineSearch {
public:
    explicit StrongWolfeLineSearch(const LineSearchParams& p = {});
    const LineSearchParams& params() const { return p_; }

    // Searches phi(a) = f(x0 + a d) from a = alpha_init. On ok(): x = x0 + alpha d and g = grad f(x).
    // Otherwise x and g hold x0 and g0.
    // f_scale: a typical energy magnitude of the problem (e.g. |f| at the start of the minimization); the
    // round-off allowance is roundoff * max(|f0|, f_scale). Energies near zero (a floppy network that relaxes to
    // E ~ 1e-13) carry round-off from their terms (1 - cos(phi) at short hinges), not from their sum.
    LineSearchResult search(Objective& f, const Eigen::VectorXd& x0, double f0, const Eigen::VectorXd& g0,
                            const Eigen::VectorXd& d, double alpha_init, Eigen::VectorXd& x, Eigen::VectorXd& g,
                            double f_scale = 0) const;

private:
    LineSearchParams p_;
};

}  // namespace fibernet
