#include "fibernet/solve/fire.hpp"

#include <cmath>

#include "solver_util.hpp"

namespace fibernet {

void FireParams::check(const std::string& where) const {
    check_value(dt >= 0, dt, where, "dt", "must be >= 0 (0 = automatic)");
    check_value(dt_max_factor >= 1, dt_max_factor, where, "dt_max_factor", "must be >= 1");
    check_value(dt_min_factor > 0 && dt_min_factor <= 1, dt_min_factor, where, "dt_min_factor", "must lie in (0, 1]");
    check_value(f_inc > 1, f_inc, where, "f_inc", "must be > 1");
    check_value(f_dec > 0 && f_dec < 1, f_dec, where, "f_dec", "must lie in (0, 1)");
    check_value(alpha0 > 0 && alpha0 < 1, alpha0, where, "alpha0", "must lie in (0, 1)");
    check_value(f_alpha > 0 && f_alpha <= 1, f_alpha, where, "f_alpha", "must lie in (0, 1]");
    check_value(n_delay >= 0, n_delay, where, "n_delay", "must be >= 0");
    check_value(n_neg_max >= 1, n_neg_max, where, "n_neg_max", "must be >= 1");
    check_value(max_move >= 0, max_move, where, "max_move", "must be >= 0 (0 = unlimited)");
    check_value(max_nonfinite >= 1, max_nonfinite, where, "max_nonfinite", "must be >= 1");
}

FireSolver::FireSolver(const SolverOptions& opt, const FireParams& p) : opt_(opt), p_(p) {
    detail::check_solver_options(opt_, name());
    p_.check(name());
}

namespace {
// Gershgorin bound on the largest |eigenvalue| of a symmetric matrix stored as its upper triangle.
double gershgorin(const Eigen::SparseMatrix<double>& H) {
    Eigen::VectorXd rs = Eigen::VectorXd::Zero(H.rows());
    for (int j = 0; j < H.outerSize(); ++j)
        for (Eigen::SparseMatrix<double>::InnerIterator it(H, j); it; ++it) {
            rs[it.row()] += std::abs(it.value());
            if (it.row() != it.col()) rs[it.col()] += std::abs(it.value());
        }
    return rs.size() ? rs.maxCoeff() : 0.0;
}
}  // namespace

SolveResult FireSolver::minimize(Objective& f_in, Eigen::VectorXd& x) {
    using Eigen::VectorXd;
    detail::Clock clock;
    detail::check_start(f_in, x, name());
    detail::Counted f(f_in);
    detail::Progress progress(name(), opt_.verbose);
    const int n = f.size();
    SolveResult r;
    r.solver = name();

    VectorXd g(n);
    double fx = f.gradient(x, g);
    double gmax = detail::max_abs(g);
    int it = 0;
    auto finish = [&](SolveStatus st, const std::string& msg) {
        r.status = st, r.message = msg, r.iterations = it, r.evaluations = f.evals;
        r.energy = fx, r.grad_max = gmax;
        r.timings.total = clock.seconds();
        progress.done(clock, to_string(st), it, fx, gmax);
        return r;
    };
    if (!std::isfinite(fx) || !g.allFinite()) return finish(SolveStatus::NonFinite, "non-finite energy or gradient at the start");

    double dt0 = p_.dt;
    if (dt0 == 0) {
        Eigen::SparseMatrix<double> H = f.hessian_pattern();
        VectorXd gh(n);
        detail::Clock c;
        f.hessian(x, gh, H, false);
        r.timings.assembly += c.seconds();
        const double lam = gershgorin(H);
        dt0 = lam > 0 && std::isfinite(lam) ? 1.0 / std::sqrt(lam) : 0.1;
    }
    const double dt_max = p_.dt_max_factor * dt0, dt_min = p_.dt_min_factor * dt0;
    double dt = dt0, alpha = p_.alpha0;
    int n_pos = 0, n_neg = 0, n_bad = 0;
    VectorXd v = VectorXd::Zero(n), xold(n), gold(n);

    while (true) {
        if (gmax <= opt_.tol) return finish(SolveStatus::Converged, "max|g| <= tol");
        if (it >= opt_.max_iter) return finish(SolveStatus::IterationLimit, "iteration limit reached");
        if (opt_.max_seconds > 0 && clock.seconds() >= opt_.max_seconds)
            return finish(SolveStatus::IterationLimit, "time limit reached");
        ++it;
        // Force F = -g.
        const double P = -g.dot(v);
        if (P > 0) {
            ++n_pos, n_neg = 0;
            if (n_pos > p_.n_delay) dt = std::min(dt * p_.f_inc, dt_max), alpha *= p_.f_alpha;
        } else {
            n_pos = 0, ++n_neg;
            if (n_neg > p_.n_neg_max)
                return finish(SolveStatus::Stalled, "power F.v <= 0 for " + std::to_string(n_neg - 1) +
                                                        " consecutive steps at max|g| = " + show(gmax));
            if (!(p_.initial_delay && it < p_.n_delay)) {
                if (dt * p_.f_dec >= dt_min) dt *= p_.f_dec;
                alpha = p_.alpha0;
            }
            if (p_.half_step_back) x -= 0.5 * dt * v;
            v.setZero();
        }
        // Semi-implicit Euler with FIRE mixing.
        v -= dt * g;
        const double vn = v.norm(), fn = g.norm();
        if (fn > 0) v = (1 - alpha) * v - (alpha * vn / fn) * g;
        double step = dt;
        const double vmax = detail::max_abs(v);
        if (p_.max_move > 0 && step * vmax > p_.max_move) step = p_.max_move / vmax;
        xold = x, gold = g;
        const double fold = fx;
        x += step * v;
        fx = f.gradient(x, g);
        if (!std::isfinite(fx) || !g.allFinite()) {
            // Undo: like an uphill step, with a smaller time step.
            x = xold, g = gold, fx = fold, v.setZero();
            dt = std::max(dt * p_.f_dec, dt_min), alpha = p_.alpha0, n_pos = 0;
            if (++n_bad >= p_.max_nonfinite)
                return finish(SolveStatus::NonFinite, "non-finite energy for " + std::to_string(n_bad) +
                                                          " consecutive steps");
            continue;
        }
        n_bad = 0;
        gmax = detail::max_abs(g);
        progress.tick(clock, it, fx, gmax);
    }
}

}  // namespace fibernet
