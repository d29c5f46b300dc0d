#include "fibernet/solve/cg.hpp"

#include <cmath>

#include "solver_util.hpp"

namespace fibernet {

void CgParams::check(const std::string& where) const {
    line_search.check(where);
    check_value(restart_every >= 0, restart_every, where, "restart_every", "must be >= 0 (0 = number of unknowns)");
    check_value(stall_iterations >= 1, stall_iterations, where, "stall_iterations", "must be >= 1");
}

CgSolver::CgSolver(const SolverOptions& opt, const CgParams& p) : opt_(opt), p_(p) {
    detail::check_solver_options(opt_, name());
    p_.check(name());
}

SolveResult CgSolver::minimize(Objective& f_in, Eigen::VectorXd& q) {
    using Eigen::VectorXd;
    detail::Clock clock;
    detail::check_start(f_in, q, name());
    detail::Counted f(f_in);
    detail::Progress progress(name(), opt_.verbose);
    const StrongWolfeLineSearch ls(p_.line_search);
    const int n = f.size();
    const int restart = p_.restart_every > 0 ? p_.restart_every : std::max(n, 1);
    SolveResult r;
    r.solver = name();

    VectorXd g(n);
    double fx = f.gradient(q, g);
    double gmax = detail::max_abs(g);
    int k = 0;
    auto finish = [&](SolveStatus st, const std::string& msg) {
        r.status = st, r.message = msg, r.iterations = k, r.evaluations = f.evals;
        r.energy = fx, r.grad_max = gmax;
        r.timings.total = clock.seconds();
        progress.done(clock, to_string(st), k, fx, gmax);
        return r;
    };
    if (!std::isfinite(fx) || !g.allFinite()) return finish(SolveStatus::NonFinite, "non-finite energy or gradient at the start");
    const double f_scale = std::abs(fx);  // energy scale for the line search's round-off allowance
    double gmax_best = gmax;

    VectorXd d = -g, xn(n), gn(n);
    bool steepest = true;
    double alpha0 = 1.0 / std::max(g.norm(), 1e-300);
    int no_decrease = 0, since_restart = 0;
    while (true) {
        if (gmax <= opt_.tol) return finish(SolveStatus::Converged, "max|g| <= tol");
        if (k >= opt_.max_iter) return finish(SolveStatus::IterationLimit, "iteration limit reached");
        if (opt_.max_seconds > 0 && clock.seconds() >= opt_.max_seconds)
            return finish(SolveStatus::IterationLimit, "time limit reached");

        detail::Clock cls;
        const LineSearchResult lr = ls.search(f, q, fx, g, d, alpha0, xn, gn, f_scale);
        r.timings.line_search += cls.seconds();
        if (!lr.ok()) {
            if (!steepest) {  // restart along -g once
                d = -g, steepest = true, since_restart = 0;
                alpha0 = 1.0 / std::max(g.norm(), 1e-300);
                continue;
            }
            const SolveStatus st = lr.outcome == LineSearchOutcome::NonFinite ? SolveStatus::NonFinite
                                                                              : SolveStatus::LineSearchFailed;
            return finish(st, "line search: " + to_string(lr.outcome) + " after " + std::to_string(lr.evals) +
                                  " evaluations at max|g| = " + show(gmax));
        }
        ++k, ++since_restart;
        // Progress: an energy decrease beyond round-off, or a new lowest max|g| (below round-off the energy
        // cannot tell, the gradient still can). A gradient inconsistent with the energy shows neither.
        {
            const double gn_max = detail::max_abs(gn);
            const double noise = 1e-16 * std::abs(fx);  // any decrease beyond the last bits
            const bool progress = lr.f < fx - noise || gn_max < 0.9 * gmax_best;
            gmax_best = std::min(gmax_best, gn_max);
            no_decrease = progress ? 0 : no_decrease + 1;
        }
        const double gd_old = g.dot(d);
        double beta = std::max(0.0, gn.dot(gn - g) / g.squaredNorm());
        if (since_restart >= restart) beta = 0, since_restart = 0;
        q.swap(xn), g.swap(gn), fx = lr.f, gmax = detail::max_abs(g);
        progress.tick(clock, k, fx, gmax);
        if (gmax <= opt_.tol) continue;
        if (no_decrease >= p_.stall_iterations)
            return finish(SolveStatus::Stalled, "no energy decrease beyond round-off and no new minimum of max|g| for " +
                                                    std::to_string(no_decrease) + " iterations at max|g| = " + show(gmax));
        d = -g + beta * d;
        steepest = beta == 0;
        if (!(g.dot(d) < 0)) d = -g, steepest = true, since_restart = 0;
        const double gd = g.dot(d);
        alpha0 = lr.alpha * gd_old / gd;
        if (!(alpha0 > 0) || !std::isfinite(alpha0)) alpha0 = 1.0 / std::max(g.norm(), 1e-300);
    }
}

}  // namespace fibernet
