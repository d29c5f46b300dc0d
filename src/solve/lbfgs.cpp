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
    opt_.check(name());
    p_.check(name());
}

SolverCapabilities LbfgsSolver::capabilities() const {
    SolverCapabilities c;
    c.hessian = p_.hessian_h0;
    return c;
}

namespace {
using Eigen::VectorXd;

// Nocedal & Wright Alg. 7.4/7.5 as one iteration of the solver loop (solver_loop.hpp).
class Lbfgs : public IterativeMethod {
public:
    explicit Lbfgs(const LbfgsParams& p) : p_(p), ls_(p.line_search) {}

    Step start(SolverRun& run, VectorXd& q) override {
        Objective& f = run.objective();
        const int n = f.size(), m = p_.m;
        g_.resize(n), gh_.resize(n), d_.resize(n), xn_.resize(n), gn_.resize(n);
        fx_ = f.gradient(q, g_);
        gmax_ = detail::max_abs(g_);
        S_.resize(n, m), Y_.resize(n, m), rho_.assign(m, 0.0), alpha_i_.resize(m);
        H_ = f.hessian_pattern();
        gmax_at_factor_ = gmax_;
        if (!std::isfinite(fx_) || !g_.allFinite())
            return Step::stop(SolveStatus::NonFinite, "non-finite energy or gradient at the start");
        f_scale_ = std::abs(fx_);  // energy scale for the line search's round-off allowance
        watch_.start(gmax_);
        if (p_.hessian_h0 && !refactor(run, q))
            return Step::stop(SolveStatus::Failed, "Hessian factorization failed at the start");
        direction(run);
        // Without curvature information, the first step of plain L-BFGS has unit length (LBFGSpp).
        alpha0_ = p_.hessian_h0 ? 1.0 : 1.0 / d_.norm();
        return Step::again();
    }

    Step iterate(SolverRun& run, VectorXd& q, int) override {
        Objective& f = run.objective();
        // A Hessian-scaled direction can be huge along near-null (floppy) modes: cap the first trial move.
        const double dmax = detail::max_abs(d_);
        if (dmax * alpha0_ > p_.max_move) alpha0_ = p_.max_move / dmax;
        detail::Clock cls;
        const LineSearchResult lr = ls_.search(f, q, fx_, g_, d_, alpha0_, xn_, gn_, f_scale_);
        run.result().timings.line_search += cls.seconds();
        if (!lr.ok()) return recover(run, q, lr);
        restarts_ = 0;
        ++k_;
        watch_.update(fx_, lr.f, detail::max_abs(gn_));
        remember(q);
        q.swap(xn_), g_.swap(gn_), fx_ = lr.f, gmax_ = detail::max_abs(g_);
        if (gmax_ <= run.options().tol) return Step::moved();
        Step stop;
        if (watch_.stalled(p_.stall_iterations, gmax_, stop)) return stop;
        if (p_.hessian_h0 && p_.refactor_stall > 0 && k_ - factor_iter_ >= p_.refactor_stall) {
            // A window of refactor_stall iterations since the last check: refactor if max|g| did not halve.
            if (gmax_ > 0.5 * gmax_at_factor_) {
                if (!refactor(run, q)) return Step::stop(SolveStatus::Failed, "Hessian factorization failed", true);
            } else {
                factor_iter_ = k_, gmax_at_factor_ = gmax_;  // progress: keep the factor, start a new window
            }
        }
        direction(run);
        if (!(g_.dot(d_) < 0)) {
            count_ = 0, newest_ = -1;
            direction(run);
        }
        alpha0_ = 1.0;
        return Step::moved();
    }

    double energy() const override { return fx_; }
    double grad_max() const override { return gmax_; }

private:
    // A failed line search: forget the memory (and refactor at the current point) once per failure and go along
    // -H0 g; give up when there is nothing left to forget.
    Step recover(SolverRun& run, const VectorXd& q, const LineSearchResult& lr) {
        const bool stale = count_ > 0 || (p_.hessian_h0 && factored_at_ != k_);
        if (restarts_ < p_.max_restarts && stale) {
            ++restarts_;
            count_ = 0, newest_ = -1;
            if (p_.hessian_h0 && factored_at_ != k_ && !refactor(run, q))
                return Step::stop(SolveStatus::Failed, "Hessian factorization failed");
            direction(run);
            alpha0_ = p_.hessian_h0 ? 1.0 : 1.0 / d_.norm();
            return Step::again();
        }
        return detail::line_search_stop(lr, gmax_);
    }

    // The new pair (s, y) into the ring buffer of the newest m, if its curvature is positive.
    void remember(const VectorXd& q) {
        const int m = p_.m, slot = (newest_ + 1) % m;
        S_.col(slot) = xn_ - q;
        Y_.col(slot) = gn_ - g_;
        const double sy = S_.col(slot).dot(Y_.col(slot)), yy = Y_.col(slot).squaredNorm();
        if (sy > 1e-14 * yy && yy > 0) {
            rho_[slot] = 1 / sy;
            gamma_ = sy / yy;
            newest_ = slot;
            count_ = std::min(count_ + 1, m);
        }
    }

    bool refactor(SolverRun& run, const VectorXd& q) {
        SolveResult& r = run.result();
        detail::Clock c;
        run.objective().hessian(q, gh_, H_, true);
        r.timings.assembly += c.seconds();
        detail::Clock c2;
        const bool ok = factor_.factorize(H_, p_.shift);
        r.timings.factorization += c2.seconds();
        ++r.factorizations;
        factor_iter_ = factored_at_ = k_, gmax_at_factor_ = gmax_;
        return ok;
    }

    // d = -H_k g by the two-loop recursion.
    void direction(SolverRun& run) {
        const int m = p_.m;
        VectorXd v = g_;
        for (int c = 0, i = newest_; c < count_; ++c, i = (i + m - 1) % m) {
            alpha_i_[i] = rho_[i] * S_.col(i).dot(v);
            v -= alpha_i_[i] * Y_.col(i);
        }
        if (p_.hessian_h0) {
            detail::Clock c;
            v = factor_.solve(v);
            run.result().timings.solve += c.seconds();
        } else {
            v *= gamma_;
        }
        for (int c = 0, i = (newest_ - count_ + 1 + m) % m; c < count_; ++c, i = (i + 1) % m) {
            const double b = rho_[i] * Y_.col(i).dot(v);
            v += (alpha_i_[i] - b) * S_.col(i);
        }
        d_ = -v;
    }

    const LbfgsParams p_;
    const StrongWolfeLineSearch ls_;
    VectorXd g_, gh_, d_, xn_, gn_, alpha_i_;
    Eigen::MatrixXd S_, Y_;
    std::vector<double> rho_;
    int count_ = 0, newest_ = -1;
    double gamma_ = 1;
    detail::HessianFactor factor_;
    Eigen::SparseMatrix<double> H_;
    int k_ = 0, factor_iter_ = -1, factored_at_ = -1;  // iterations; window start; iteration of the last factorization
    double fx_ = 0, gmax_ = 0, gmax_at_factor_ = 0, f_scale_ = 0, alpha0_ = 1;
    int restarts_ = 0;
    detail::StallWatch watch_;
};
}  // namespace

SolveResult LbfgsSolver::minimize(Objective& f, Eigen::VectorXd& q) {
    SolverRun run(name(), opt_, f, q);
    Lbfgs method(p_);
    return run_iterations(run, method, q);
}

}  // namespace fibernet
