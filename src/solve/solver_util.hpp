#pragma once
// Internal helpers shared by the solvers in src/solve/ (not a public header): option checks, wall clock,
// evaluation counting, once-a-second progress lines, and the final max|g| check.
#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "fibernet/energy/objective.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::detail {

// Throws InputError naming the bad SolverOptions value; `where` names the solver.
inline void check_solver_options(const SolverOptions& o, const std::string& where) {
    check_value(o.tol > 0, o.tol, where, "tol", "must be > 0");
    check_value(o.max_iter > 0, o.max_iter, where, "max_iter", "must be > 0");
    check_value(o.max_seconds >= 0, o.max_seconds, where, "max_seconds", "must be >= 0 (0 = no limit)");
}

inline double max_abs(const Eigen::VectorXd& v) { return v.size() ? v.lpNorm<Eigen::Infinity>() : 0.0; }

inline bool all_finite(const Eigen::VectorXd& v) { return v.allFinite(); }

// Status of a returned state evaluated afresh, never the backend's word for it: NonFinite if the energy or gradient
// is; Converged exactly when max|g| <= tol; a backend that claimed convergence above tol gets `claimed_above_tol`.
inline SolveStatus verified_status(SolveStatus claimed, double energy, const Eigen::VectorXd& g, double tol,
                                   SolveStatus claimed_above_tol) {
    if (!std::isfinite(energy) || !g.allFinite()) return SolveStatus::NonFinite;
    if (max_abs(g) <= tol) return SolveStatus::Converged;
    return claimed == SolveStatus::Converged ? claimed_above_tol : claimed;
}

class Clock {
public:
    Clock() : t0_(std::chrono::steady_clock::now()) {}
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    }

private:
    std::chrono::steady_clock::time_point t0_;
};

// Forwards to an objective, counting value/gradient/Hessian evaluations.
class Counted : public Objective {
public:
    explicit Counted(Objective& f) : f_(f) {}
    int size() const override { return f_.size(); }
    double value(const Eigen::VectorXd& q) override {
        ++evals;
        return f_.value(q);
    }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        ++evals;
        return f_.gradient(q, g);
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                   bool psd) override {
        ++evals;
        return f_.hessian(q, g, H, psd);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return f_.hessian_pattern(); }
    int evals = 0;

private:
    Objective& f_;
};

// Throws InputError unless q has f's size.
inline void check_start(const Objective& f, const Eigen::VectorXd& q, const std::string& where) {
    if (q.size() != f.size())
        throw InputError(where + ": start vector has " + std::to_string(q.size()) + " entries, the objective " +
                         std::to_string(f.size()));
}

// Prints "<solver> it <k> E <e> max|g| <g> t <s>" to stderr at most once a second, when enabled.
class Progress {
public:
    Progress(std::string name, bool on) : name_(std::move(name)), on_(on) {}
    void tick(const Clock& c, int it, double e, double gmax, const char* extra = "") {
        if (!on_) return;
        const double t = c.seconds();
        if (t < next_) return;
        next_ = t + 1.0;
        std::fprintf(stderr, "%s: it %d  E %.15g  max|g| %.3e  t %.1fs%s%s\n", name_.c_str(), it, e, gmax, t,
                     *extra ? "  " : "", extra);
    }
    void done(const Clock& c, const std::string& status, int it, double e, double gmax) {
        if (!on_) return;
        std::fprintf(stderr, "%s: %s after %d it  E %.15g  max|g| %.3e  t %.2fs\n", name_.c_str(), status.c_str(), it,
                     e, gmax, c.seconds());
    }

private:
    std::string name_;
    bool on_;
    double next_ = 1.0;
};

}  // namespace fibernet::detail
