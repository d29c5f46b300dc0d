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
    opt_.check(name());
    p_.check(name());
}

namespace {
using Eigen::VectorXd;

// Polak-Ribiere+ conjugate gradients with restarts, as one iteration of the solver loop (solver_loop.hpp).
class NonlinearCg : public IterativeMethod {
public:
    explicit NonlinearCg(const CgParams& p) : p_(p), ls_(p.line_search) {}

    Step start(SolverRun& run, VectorXd& q) override {
        Objective& f = run.objective();
        const int n = f.size();
        restart_ = p_.restart_every > 0 ? p_.restart_every : std::max(n, 1);
        g_.resize(n), xn_.resize(n), gn_.resize(n);
        fx_ = f.gradient(q, g_);
        gmax_ = detail::max_abs(g_);
        if (!std::isfinite(fx_) || !g_.allFinite())
            return Step::stop(SolveStatus::NonFinite, "non-finite energy or gradient at the start");
        f_scale_ = std::abs(fx_);  // energy scale for the line search's round-off allowance
        watch_.start(gmax_);
        d_ = -g_;
        alpha0_ = 1.0 / std::max(g_.norm(), 1e-300);
        return Step::again();
    }

    Step iterate(SolverRun& run, VectorXd& q, int) override {
        detail::Clock cls;
        const LineSearchResult lr = ls_.search(run.objective(), q, fx_, g_, d_, alpha0_, xn_, gn_, f_scale_);
        run.result().timings.line_search += cls.seconds();
        if (!lr.ok()) {
            if (!steepest_) {  // restart along -g once
                d_ = -g_, steepest_ = true, since_restart_ = 0;
                alpha0_ = 1.0 / std::max(g_.norm(), 1e-300);
                return Step::again();
            }
            return detail::line_search_stop(lr, gmax_);
        }
        ++since_restart_;
        watch_.update(fx_, lr.f, detail::max_abs(gn_));
        const double gd_old = g_.dot(d_);
        double beta = std::max(0.0, gn_.dot(gn_ - g_) / g_.squaredNorm());
        if (since_restart_ >= restart_) beta = 0, since_restart_ = 0;
        q.swap(xn_), g_.swap(gn_), fx_ = lr.f, gmax_ = detail::max_abs(g_);
        if (gmax_ <= run.options().tol) return Step::moved();
        Step stop;
        if (watch_.stalled(p_.stall_iterations, gmax_, stop)) return stop;
        d_ = -g_ + beta * d_;
        steepest_ = beta == 0;
        if (!(g_.dot(d_) < 0)) d_ = -g_, steepest_ = true, since_restart_ = 0;
        const double gd = g_.dot(d_);
        alpha0_ = lr.alpha * gd_old / gd;
        if (!(alpha0_ > 0) || !std::isfinite(alpha0_)) alpha0_ = 1.0 / std::max(g_.norm(), 1e-300);
        return Step::moved();
    }

    double energy() const override { return fx_; }
    double grad_max() const override { return gmax_; }

private:
    const CgParams p_;
    const StrongWolfeLineSearch ls_;
    VectorXd g_, d_, xn_, gn_;
    detail::StallWatch watch_;
    int restart_ = 1, since_restart_ = 0;
    bool steepest_ = true;
    double fx_ = 0, gmax_ = 0, f_scale_ = 0, alpha0_ = 1;
};
}  // namespace

SolveResult CgSolver::minimize(Objective& f, Eigen::VectorXd& q) {
    SolverRun run(name(), opt_, f, q);
    NonlinearCg method(p_);
    return run_iterations(run, method, q);
}

}  // namespace fibernet
