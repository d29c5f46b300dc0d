#include "fibernet/wet/smooth_wet_relax.hpp"

#include <chrono>
#include <cstdio>

namespace fibernet {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Restores a solver's options on every exit.
struct OptionsGuard {
    Solver& s;
    SolverOptions saved;
    explicit OptionsGuard(Solver& solver) : s(solver), saved(solver.options()) {}
    ~OptionsGuard() { s.options() = saved; }
};
}  // namespace

SmoothRelaxResult relax_smooth_wet(SmoothWetEnergy& W, Solver& solver, Eigen::VectorXd& q,
                                   const SmoothRelaxOptions& opt) {
    const auto t0 = Clock::now();
    OptionsGuard guard(solver);
    const SolverOptions base = guard.saved;
    const SolverCapabilities caps = solver.capabilities();
    const int cap = caps.newton_steps && opt.round_iterations > 0 ? opt.round_iterations : base.max_iter;
    const int lists0 = W.list_builds(), patterns0 = W.pattern_builds();
    SmoothRelaxResult R;
    for (R.rounds = 1; R.rounds <= opt.max_rounds; ++R.rounds) {
        SolverOptions& o = solver.options();
        o.max_iter = cap;
        o.warm_start = base.warm_start || (R.rounds > 1 && caps.warm_start);
        if (base.max_step == 0 && W.params().pair.beta > 0) o.max_step = opt.max_step < 0 ? W.params().skin : opt.max_step;
        // beta = 0: the dry solve, bit for bit
        const bool wet = W.params().pair.beta > 0;
        o.projected = base.projected || (opt.projected && caps.projected && wet);
        o.ldl = !o.projected && (base.ldl || (opt.ldl && caps.ldl && wet));
        R.last = solver.minimize(W, q);
        R.iterations += R.last.iterations, R.factorizations += R.last.factorizations;
        R.evaluations += R.last.evaluations;
        R.local_solves += R.last.local_solves, R.local_iterations += R.last.local_iterations;
        R.timings += R.last.timings;
        R.energy = R.last.energy, R.grad_max = R.last.grad_max;
        const bool stale = W.pattern_stale();
        const bool outdated = stale || !W.pattern_current();  // a reason the solve may have been held back
        const bool rebuild = opt.always_rebuild || outdated;
        if (stale) ++R.stale_patterns;
        const bool rebuilt = rebuild && !R.last.converged();
        if (rebuilt) {
            const auto tl = Clock::now();
            W.rebuild(q);
            R.seconds_patterns += since(tl);
        }
        if (opt.progress)
            std::fprintf(stderr, "  round %d: %s, %d iterations, E = %.10g, max|g| = %.3g%s\n", R.rounds,
                         to_string(R.last.status).c_str(), R.last.iterations, R.energy, R.grad_max,
                         rebuilt ? (stale ? ", pattern rebuilt (stale)" : ", pattern rebuilt") : "");
        if (R.last.converged()) {
            R.converged = true;
            char m[120];
            std::snprintf(m, sizeof m, "equilibrium of the whole energy: max|g| = %.3g", R.grad_max);
            R.message = m;
            break;
        }
        const bool cut = R.last.status == SolveStatus::IterationLimit && cap < base.max_iter;
        if (!cut && !outdated) {  // a failure with the Hessian's pattern up to date: not the list's doing
            R.message = "the solver stopped: " + R.last.message;
            break;
        }
    }
    if (!R.converged && R.message.empty()) {
        char m[160];
        std::snprintf(m, sizeof m, "no equilibrium after %d rounds (%d solver iterations), max|g| = %.3g",
                      opt.max_rounds, R.iterations, R.grad_max);
        R.message = m;
    }
    if (R.rounds > opt.max_rounds) R.rounds = opt.max_rounds;
    R.list_builds = W.list_builds() - lists0, R.pattern_builds = W.pattern_builds() - patterns0;
    R.seconds = since(t0);
    return R;
}

}  // namespace fibernet
