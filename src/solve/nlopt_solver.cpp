#include "fibernet/solve/nlopt_solver.hpp"

#include <cmath>
#include <limits>
#include <nlopt.hpp>
#include <vector>

#include "fibernet/solve/solver_loop.hpp"
#include "solver_util.hpp"

namespace fibernet {

void NloptParams::check(const std::string& where) const {
    check_value(vector_storage >= 0, vector_storage, where, "vector_storage", "must be >= 0 (0 = NLopt's default)");
    check_value(xtol_rel >= 0, xtol_rel, where, "xtol_rel", "must be >= 0");
    check_value(ftol_rel >= 0, ftol_rel, where, "ftol_rel", "must be >= 0");
}

NloptSolver::NloptSolver(NloptMethod method, const SolverOptions& opt, const NloptParams& p)
    : method_(method), opt_(opt), p_(p) {
    opt_.check(name());
    p_.check(name());
}

std::string NloptSolver::name() const {
    switch (method_) {
        case NloptMethod::Lbfgs: return "nlopt-lbfgs";
        case NloptMethod::TNewton: return "nlopt-tnewton";
        case NloptMethod::Var2: return "nlopt-var2";
    }
    return "nlopt-?";
}

namespace {
const char* result_name(nlopt::result r) {
    switch (r) {
        case nlopt::FAILURE: return "FAILURE";
        case nlopt::INVALID_ARGS: return "INVALID_ARGS";
        case nlopt::OUT_OF_MEMORY: return "OUT_OF_MEMORY";
        case nlopt::ROUNDOFF_LIMITED: return "ROUNDOFF_LIMITED";
        case nlopt::FORCED_STOP: return "FORCED_STOP";
        case nlopt::SUCCESS: return "SUCCESS";
        case nlopt::STOPVAL_REACHED: return "STOPVAL_REACHED";
        case nlopt::FTOL_REACHED: return "FTOL_REACHED";
        case nlopt::XTOL_REACHED: return "XTOL_REACHED";
        case nlopt::MAXEVAL_REACHED: return "MAXEVAL_REACHED";
        case nlopt::MAXTIME_REACHED: return "MAXTIME_REACHED";
        default: return "UNKNOWN";
    }
}

struct Watch {
    SolverRun* run;
    double tol;
    Eigen::VectorXd x, g;
    bool hit = false;        // a point with max|g| <= tol was met: NLopt was stopped there
    Eigen::VectorXd hit_x;
    double best_f = std::numeric_limits<double>::infinity();
    Eigen::VectorXd best_x;
    int nonfinite = 0;
    bool time_stop = false;  // NLopt checks maxtime only between its outer iterations (TNEWTON's inner CG loop can
                             // overrun it many times over), so the adapter enforces it too
};

double callback(unsigned n, const double* xp, double* grad, void* data) {
    auto& w = *static_cast<Watch*>(data);
    // Once stopped, NLopt's inner loops (TNEWTON's CG) may still call back until they check the stop flag:
    // answer at once, without evaluating.
    if (w.hit || w.time_stop) throw nlopt::forced_stop();
    if (w.run->out_of_time()) {
        w.time_stop = true;
        throw nlopt::forced_stop();
    }
    w.x = Eigen::Map<const Eigen::VectorXd>(xp, n);
    const double fx = w.run->objective().gradient(w.x, w.g);
    const bool finite = std::isfinite(fx) && w.g.allFinite();
    if (!finite) {
        ++w.nonfinite;
        if (grad) Eigen::Map<Eigen::VectorXd>(grad, n).setZero();
        return std::numeric_limits<double>::infinity();
    }
    if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = w.g;
    const double gmax = detail::max_abs(w.g);
    if (fx < w.best_f) w.best_f = fx, w.best_x = w.x;
    w.run->tick(w.run->objective().evaluations, fx, gmax);
    if (gmax <= w.tol) {
        w.hit = true, w.hit_x = w.x;
        throw nlopt::forced_stop();
    }
    return fx;
}
}  // namespace

SolveResult NloptSolver::minimize(Objective& f_in, Eigen::VectorXd& q) {
    SolverRun run(name(), opt_, f_in, q);
    CountedObjective& f = run.objective();
    const int n = f.size();
    // Every exit reports the state we return, evaluated afresh: never NLopt's word for it. NLopt reports no iteration
    // count: its evaluations stand for it.
    auto finish = [&](SolveStatus st, const std::string& msg) {
        run.result().iterations = f.evaluations + 1;
        return run.finish_verified(st, msg, q, SolveStatus::Failed);
    };

    // Start point first: a converged or non-finite start needs no NLopt call.
    Eigen::VectorXd g(n);
    const double f0 = f.gradient(q, g);
    if (!std::isfinite(f0) || !g.allFinite()) return finish(SolveStatus::NonFinite, "non-finite energy or gradient at the start");
    if (detail::max_abs(g) <= opt_.tol) return finish(SolveStatus::Converged, "max|g| <= tol at the start");
    if (n == 0) return finish(SolveStatus::Converged, "no unknowns");

    nlopt::algorithm alg = nlopt::LD_LBFGS;
    if (method_ == NloptMethod::TNewton) alg = nlopt::LD_TNEWTON_PRECOND_RESTART;
    if (method_ == NloptMethod::Var2) alg = nlopt::LD_VAR2;
    nlopt::opt o(alg, static_cast<unsigned>(n));
    Watch w;
    w.run = &run, w.tol = opt_.tol;
    w.best_f = f0, w.best_x = q;
    o.set_min_objective(callback, &w);
    o.set_maxeval(opt_.max_iter);
    if (opt_.max_seconds > 0) o.set_maxtime(opt_.max_seconds);
    if (p_.xtol_rel > 0) o.set_xtol_rel(p_.xtol_rel);
    if (p_.ftol_rel > 0) o.set_ftol_rel(p_.ftol_rel);
    if (p_.vector_storage > 0) o.set_vector_storage(static_cast<unsigned>(p_.vector_storage));

    std::vector<double> x(q.data(), q.data() + n);
    double fopt = 0;
    std::string what;
    try {
        o.optimize(x, fopt);
    } catch (const nlopt::forced_stop&) {
    } catch (const nlopt::roundoff_limited&) {
    } catch (const std::bad_alloc&) {
        what = "out of memory";
    } catch (const std::exception& e) {
        what = e.what();
    }
    const nlopt::result res = o.last_optimize_result();
    const std::string reason = std::string("NLopt ") + result_name(res) + (what.empty() ? "" : " (" + what + ")");
    if (w.hit) {
        q = w.hit_x;
        return finish(SolveStatus::Converged, "max|g| <= tol; NLopt stopped there");
    }
    q = w.best_x;  // the lowest energy evaluated
    SolveStatus st = SolveStatus::Failed;
    switch (res) {
        case nlopt::SUCCESS:
        case nlopt::STOPVAL_REACHED:
        case nlopt::FTOL_REACHED:
        case nlopt::XTOL_REACHED:
        case nlopt::ROUNDOFF_LIMITED: st = SolveStatus::Stalled; break;
        case nlopt::MAXEVAL_REACHED:
        case nlopt::MAXTIME_REACHED: st = SolveStatus::IterationLimit; break;
        default: st = SolveStatus::Failed; break;
    }
    std::string msg = reason + " before max|g| <= tol";
    if (w.time_stop) st = SolveStatus::IterationLimit, msg = "time limit reached (NLopt stopped by the adapter)";
    if (res == nlopt::FAILURE || res == nlopt::ROUNDOFF_LIMITED)
        msg += " (a gradient that does not match the energy, tol below the round-off floor, or a badly scaled"
               " start: docs/solvers.md)";
    if (w.nonfinite > 0) msg += "; " + std::to_string(w.nonfinite) + " non-finite evaluations";
    return finish(st, msg);
}

}  // namespace fibernet
