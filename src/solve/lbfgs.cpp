#include "fibernet/solve/lbfgs.hpp"

#include <cmath>
#include <vector>

#include "hessian_factor.hpp"
#include "solver_util.hpp"

namespace fibernet {

void LbfgsParams::check(const std::string& where) const {
    check_value(m >= 1 && m <= 1000, m, where, "m", "must lie in [1, 1000]");
    line_search.check(where);
    check_value(shift > 0 && shift < 1, shift, where, "shift", "must lie in (0, 1)");
    check_value(refactor_stall >= 0, refactor_stall, where, "refactor_stall", "must be >= 0 (0 = never)");
    check_value(max_restarts >= 0, max_restarts, where, "max_restarts", "must be >= 0");
    check_value(stall_iterations >= 1, stall_iterations, where, "stall_iterations", "must be >= 1");
    check_value(max_move > 0, max_move, where, "max_move", "must be > 0");
}

LbfgsSolver::LbfgsSolver(const SolverOptions& opt, const LbfgsParams& p) : opt_(opt), p_(p) {
    detail::check_solver_options(opt_, name());
    p_.check(name());
}

SolveResult LbfgsSolver::minimize(Objective& f_in, Eigen::VectorXd& q) {
    using Eigen::VectorXd;
    detail::Clock clock;
    detail::check_start(f_in, q, name());
    detail::Counted f(f_in);
    detail::Progress progress(name(), opt_.verbose);
    const StrongWolfeLineSearch ls(p_.line_search);
    const int n = f.size();
    SolveResult r;
    r.solver = name();

    VectorXd g(n);
    double fx = f.gradient(q, g);
    double gmax = detail::max_abs(g);

    // Memory: ring buffer of the newest m pairs.
    const int m = p_.m;
    Eigen::MatrixXd S(n, m), Y(n, m);
    std::vector<double> rho(m);
    int count = 0, newest = -1;
    double gamma = 1;

    detail::HessianFactor factor;
    Eigen::SparseMatrix<double> H = f.hessian_pattern();
    VectorXd gh(n);
    int factor_iter = -1, factored_at = -1;  // window start; iteration of the last factorization
    double gmax_at_factor = gmax;
    int k = 0;
    auto refactor = [&]() {
        detail::Clock c;
        f.hessian(q, gh, H, true);
        r.timings.assembly += c.seconds();
        detail::Clock c2;
        const bool ok = factor.factorize(H, p_.shift);
        r.timings.factorization += c2.seconds();
        ++r.factorizations;
        factor_iter = factored_at = k, gmax_at_factor = gmax;
        return ok;
    };
    // d = -H_k g by the two-loop recursion.
    VectorXd d(n), alpha_i(m);
    auto direction = [&]() {
        VectorXd v = g;
        for (int c = 0, i = newest; c < count; ++c, i = (i + m - 1) % m) {
            alpha_i[i] = rho[i] * S.col(i).dot(v);
            v -= alpha_i[i] * Y.col(i);
        }
        if (p_.hessian_h0) {
            detail::Clock c;
            v = factor.solve(v);
            r.timings.solve += c.seconds();
        } else {
            v *= gamma;
        }
        for (int c = 0, i = (newest - count + 1 + m) % m; c < count; ++c, i = (i + 1) % m) {
            const double b = rho[i] * Y.col(i).dot(v);
            v += (alpha_i[i] - b) * S.col(i);
        }
        d = -v;
    };
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
    if (p_.hessian_h0 && !refactor()) return finish(SolveStatus::Failed, "Hessian factorization failed at the start");

    direction();
    // Without curvature information, the first step of plain L-BFGS has unit length (LBFGSpp).
    double alpha0 = p_.hessian_h0 ? 1.0 : 1.0 / d.norm();
    int restarts = 0, no_decrease = 0;
    VectorXd xn(n), gn(n);
    while (true) {
        if (gmax <= opt_.tol) return finish(SolveStatus::Converged, "max|g| <= tol");
        if (k >= opt_.max_iter) return finish(SolveStatus::IterationLimit, "iteration limit reached");
        if (opt_.max_seconds > 0 && clock.seconds() >= opt_.max_seconds)
            return finish(SolveStatus::IterationLimit, "time limit reached");

        // A Hessian-scaled direction can be huge along near-null (floppy) modes: cap the first trial move.
        const double dmax = detail::max_abs(d);
        if (dmax * alpha0 > p_.max_move) alpha0 = p_.max_move / dmax;
        detail::Clock cls;
        const LineSearchResult lr = ls.search(f, q, fx, g, d, alpha0, xn, gn, f_scale);
        r.timings.line_search += cls.seconds();
        if (!lr.ok()) {
            // Recover once per failure: forget the memory (and refactor at the current point), go along -H0 g.
            const bool stale = count > 0 || (p_.hessian_h0 && factored_at != k);
            if (restarts < p_.max_restarts && stale) {
                ++restarts;
                count = 0, newest = -1;
                if (p_.hessian_h0 && factored_at != k && !refactor())
                    return finish(SolveStatus::Failed, "Hessian factorization failed");
                direction();
                alpha0 = p_.hessian_h0 ? 1.0 : 1.0 / d.norm();
                continue;
            }
            const SolveStatus st = lr.outcome == LineSearchOutcome::NonFinite ? SolveStatus::NonFinite
                                                                              : SolveStatus::LineSearchFailed;
            return finish(st, "line search: " + to_string(lr.outcome) + " after " + std::to_string(lr.evals) +
                                  " evaluations at max|g| = " + show(gmax));
        }
        restarts = 0;
        ++k;
        // Progress: an energy decrease beyond round-off, or a new lowest max|g| (below round-off the energy
        // cannot tell, the gradient still can). A gradient inconsistent with the energy shows neither.
        {
            const double gn_max = detail::max_abs(gn);
            const double noise = 1e-16 * std::abs(fx);  // any decrease beyond the last bits
            const bool progress = lr.f < fx - noise || gn_max < 0.9 * gmax_best;
            gmax_best = std::min(gmax_best, gn_max);
            no_decrease = progress ? 0 : no_decrease + 1;
        }
        // New pair.
        const int slot = (newest + 1) % m;
        S.col(slot) = xn - q;
        Y.col(slot) = gn - g;
        const double sy = S.col(slot).dot(Y.col(slot)), yy = Y.col(slot).squaredNorm();
        if (sy > 1e-14 * yy && yy > 0) {  // keep only pairs with positive curvature
            rho[slot] = 1 / sy;
            gamma = sy / yy;
            newest = slot;
            count = std::min(count + 1, m);
        }
        q.swap(xn), g.swap(gn), fx = lr.f, gmax = detail::max_abs(g);
        progress.tick(clock, k, fx, gmax);
        if (gmax <= opt_.tol) continue;
        if (no_decrease >= p_.stall_iterations)
            return finish(SolveStatus::Stalled, "no energy decrease beyond round-off and no new minimum of max|g| for " +
                                                    std::to_string(no_decrease) + " iterations at max|g| = " + show(gmax));
        if (p_.hessian_h0 && p_.refactor_stall > 0 && k - factor_iter >= p_.refactor_stall) {
            // A window of refactor_stall iterations since the last check: refactor if max|g| did not halve.
            if (gmax > 0.5 * gmax_at_factor) {
                if (!refactor()) return finish(SolveStatus::Failed, "Hessian factorization failed");
            } else {
                factor_iter = k, gmax_at_factor = gmax;  // progress: keep the factor, start a new window
            }
        }
        direction();
        if (!(g.dot(d) < 0)) {
            count = 0, newest = -1;
            direction();
        }
        alpha0 = 1.0;
    }
}

}  // namespace fibernet
