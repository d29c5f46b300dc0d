#include "fibernet/solve/fire.hpp"

#include <cmath>

#include "fibernet/solve/solver_loop.hpp"
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
    opt_.check(name());
    p_.check(name());
}

SolverCapabilities FireSolver::capabilities() const {
    SolverCapabilities c;
    c.hessian = p_.dt == 0;  // the automatic time step's Gershgorin bound
    return c;
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


using Eigen::VectorXd;

// FIRE (Bitzek et al. 2006; FIRE 2.0, Guenole et al. 2020) as one iteration of the solver loop (solver_loop.hpp): a
// damped semi-implicit Euler step per iteration.
class Fire : public IterativeMethod {
public:
    explicit Fire(const FireParams& p) : p_(p) {}

    Step start(SolverRun& run, VectorXd& x) override {
        Objective& f = run.objective();
        const int n = f.size();
        g_.resize(n);
        fx_ = f.gradient(x, g_);
        gmax_ = detail::max_abs(g_);
        if (!std::isfinite(fx_) || !g_.allFinite())
            return Step::stop(SolveStatus::NonFinite, "non-finite energy or gradient at the start");
        double dt0 = p_.dt;
        if (dt0 == 0) {
            Eigen::SparseMatrix<double> H = f.hessian_pattern();
            VectorXd gh(n);
            detail::Clock c;
            f.hessian(x, gh, H, false);
            run.result().timings.assembly += c.seconds();
            const double lam = gershgorin(H);
            dt0 = lam > 0 && std::isfinite(lam) ? 1.0 / std::sqrt(lam) : 0.1;
        }
        dt_max_ = p_.dt_max_factor * dt0, dt_min_ = p_.dt_min_factor * dt0;
        dt_ = dt0, alpha_ = p_.alpha0;
        v_ = VectorXd::Zero(n);
        return Step::again();
    }

    // Every iteration counts, also one whose step was undone.
    Step iterate(SolverRun& run, VectorXd& x, int k) override {
        const int it = k + 1;
        // Force F = -g.
        const double P = -g_.dot(v_);
        if (P > 0) {
            ++n_pos_, n_neg_ = 0;
            if (n_pos_ > p_.n_delay) dt_ = std::min(dt_ * p_.f_inc, dt_max_), alpha_ *= p_.f_alpha;
        } else {
            n_pos_ = 0, ++n_neg_;
            if (n_neg_ > p_.n_neg_max)
                return Step::stop(SolveStatus::Stalled, "power F.v <= 0 for " + std::to_string(n_neg_ - 1) +
                                                            " consecutive steps at max|g| = " + show(gmax_), true);
            if (!(p_.initial_delay && it < p_.n_delay)) {
                if (dt_ * p_.f_dec >= dt_min_) dt_ *= p_.f_dec;
                alpha_ = p_.alpha0;
            }
            if (p_.half_step_back) x -= 0.5 * dt_ * v_;
            v_.setZero();
        }
        // Semi-implicit Euler with FIRE mixing.
        v_ -= dt_ * g_;
        const double vn = v_.norm(), fn = g_.norm();
        if (fn > 0) v_ = (1 - alpha_) * v_ - (alpha_ * vn / fn) * g_;
        double step = dt_;
        const double vmax = detail::max_abs(v_);
        if (p_.max_move > 0 && step * vmax > p_.max_move) step = p_.max_move / vmax;
        xold_ = x, gold_ = g_;
        const double fold = fx_;
        x += step * v_;
        fx_ = run.objective().gradient(x, g_);
        if (!std::isfinite(fx_) || !g_.allFinite()) {
            // Undo: like an uphill step, with a smaller time step.
            x = xold_, g_ = gold_, fx_ = fold, v_.setZero();
            dt_ = std::max(dt_ * p_.f_dec, dt_min_), alpha_ = p_.alpha0, n_pos_ = 0;
            if (++n_bad_ >= p_.max_nonfinite)
                return Step::stop(SolveStatus::NonFinite, "non-finite energy for " + std::to_string(n_bad_) +
                                                              " consecutive steps", true);
            return Step::moved();
        }
        n_bad_ = 0;
        gmax_ = detail::max_abs(g_);
        return Step::moved();
    }

    double energy() const override { return fx_; }
    double grad_max() const override { return gmax_; }

private:
    const FireParams p_;
    VectorXd g_, v_, xold_, gold_;
    double fx_ = 0, gmax_ = 0, dt_ = 0, dt_max_ = 0, dt_min_ = 0, alpha_ = 0;
    int n_pos_ = 0, n_neg_ = 0, n_bad_ = 0;
};
}  // namespace

SolveResult FireSolver::minimize(Objective& f, Eigen::VectorXd& x) {
    SolverRun run(name(), opt_, f, x);
    Fire method(p_);
    return run_iterations(run, method, x);
}

}  // namespace fibernet
