#include "fibernet/solve/solver_loop.hpp"

#include <cmath>
#include <cstdio>

#include "fibernet/util/error.hpp"

namespace fibernet {

double CountedObjective::value(const Eigen::VectorXd& q) {
    ++evaluations;
    return f_.value(q);
}

double CountedObjective::gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) {
    ++evaluations;
    return f_.gradient(q, g);
}

double CountedObjective::hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                                 bool psd) {
    ++evaluations;
    return f_.hessian(q, g, H, psd);
}

SolverRun::SolverRun(std::string name, const SolverOptions& opt, Objective& f, const Eigen::VectorXd& q)
    : name_(std::move(name)), opt_(opt), f_(f), t0_(std::chrono::steady_clock::now()) {
    if (q.size() != f.size())
        throw InputError(name_ + ": start vector has " + std::to_string(q.size()) + " entries, the objective " +
                         std::to_string(f.size()));
    r_.solver = name_;
}

double SolverRun::seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

bool SolverRun::stop_test(int k, double grad_max, Step& out) const {
    if (grad_max <= opt_.tol) {
        out = Step::stop(SolveStatus::Converged, "max|g| <= tol");
        return true;
    }
    if (k >= opt_.max_iter) {
        out = Step::stop(SolveStatus::IterationLimit, "iteration limit " + std::to_string(opt_.max_iter) + " reached");
        return true;
    }
    if (out_of_time()) {
        out = Step::stop(SolveStatus::IterationLimit, "time limit reached");
        return true;
    }
    return false;
}

void SolverRun::tick(int k, double energy, double grad_max, const std::string& extra) {
    if (!opt_.verbose && !opt_.progress) return;
    const double t = seconds();
    if (t < next_tick_) return;
    next_tick_ = t + 1.0;
    std::fprintf(stderr, "%s: it %d  E %.15g  max|g| %.3e  t %.1fs%s%s\n", name_.c_str(), k, energy, grad_max, t,
                 extra.empty() ? "" : "  ", extra.c_str());
}

void SolverRun::tick_within(int k, int done, int total, double spent) {
    if (!opt_.verbose && !opt_.progress) return;
    const double t = seconds();
    if (t < next_tick_ || done <= 0) return;
    next_tick_ = t + 1.0;
    std::fprintf(stderr, "%s: it %d  local solves %d of %d  t %.1fs  (about %.0f s more for them)\n", name_.c_str(), k,
                 done, total, t, spent / done * (total - done));
}

SolveResult SolverRun::finish(SolveStatus status, const std::string& message, int iterations, double energy,
                              double grad_max) {
    r_.status = status, r_.message = message, r_.iterations = iterations, r_.evaluations = f_.evaluations;
    r_.energy = energy, r_.grad_max = grad_max;
    r_.timings.total = seconds();
    if (opt_.verbose)
        std::fprintf(stderr, "%s: %s after %d it, %d factorizations (%d local solves, %d local iterations)  E %.15g  "
                     "max|g| %.3e  t %.2fs\n", name_.c_str(), to_string(status).c_str(), iterations, r_.factorizations,
                     r_.local_solves, r_.local_iterations, energy, grad_max, r_.timings.total);
    return r_;
}

SolveResult SolverRun::finish_verified(SolveStatus claimed, const std::string& message, const Eigen::VectorXd& q,
                                       SolveStatus claimed_above_tol) {
    Eigen::VectorXd g(q.size());
    const double e = f_.gradient(q, g);
    const double gmax = g.size() ? g.lpNorm<Eigen::Infinity>() : 0.0;
    SolveStatus st = claimed;
    if (!std::isfinite(e) || !g.allFinite()) st = SolveStatus::NonFinite;
    else if (gmax <= opt_.tol) st = SolveStatus::Converged;
    else if (claimed == SolveStatus::Converged) st = claimed_above_tol;
    return finish(st, message, r_.iterations, e, gmax);
}

SolveResult run_iterations(SolverRun& run, IterativeMethod& method, Eigen::VectorXd& q) {
    Step s = method.start(run, q);
    int k = 0;
    while (!s.done) {
        if (run.stop_test(k, method.grad_max(), s)) break;
        s = method.iterate(run, q, k);
        if (s.advanced) {
            ++k;
            if (!method.reports_every_iteration()) run.tick(k, method.energy(), method.grad_max(), method.note());
            if (run.options().observe) run.options().observe(q, method.energy(), method.grad_max());
        }
    }
    method.complete(run.result(), s, q);
    return run.finish(s.status, s.message, k, method.energy(), method.grad_max());
}

}  // namespace fibernet
