#include "fibernet/wet/smooth_wet_relax.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstdio>

#include "fibernet/util/stopwatch.hpp"

namespace fibernet {

namespace {
using Clock = std::chrono::steady_clock;

// Restores a solver's options and the energy's pattern mode on every exit.
struct OptionsGuard {
    Solver& s;
    SmoothWetEnergy& W;
    SolverOptions saved;
    OptionsGuard(Solver& solver, SmoothWetEnergy& energy) : s(solver), W(energy), saved(solver.options()) {}
    ~OptionsGuard() {
        s.options() = saved;
        W.follow_pattern(false);
    }
};

// The options of a wet solve: the step capped at the skin, the rung that suits the wet Hessian. beta = 0: the dry
// solve, bit for bit.
void configure(SolverOptions& o, const SolverOptions& base, const SolverCapabilities& caps, const SmoothWetEnergy& W,
               const SmoothRelaxOptions& opt) {
    const bool wet = W.params().pair.beta > 0;
    if (base.max_step == 0 && wet) o.max_step = opt.max_step < 0 ? W.params().skin : opt.max_step;
    o.projected = base.projected || (opt.projected && caps.projected && wet);
    o.ldl = !o.projected && (base.ldl || (opt.ldl && caps.ldl && wet));
    if (opt.observe) o.observe = opt.observe;
    if (opt.observe_within) o.observe_within = opt.observe_within;
}

void add(SmoothRelaxResult& R, const SolveResult& s) {
    R.last = s;
    R.iterations += s.iterations, R.factorizations += s.factorizations, R.evaluations += s.evaluations;
    R.local_solves += s.local_solves, R.local_iterations += s.local_iterations;
    R.eliminating_iterations += s.eliminating_iterations;
    R.timings += s.timings;
    R.energy = s.energy, R.grad_max = s.grad_max;
}

void converged(SmoothRelaxResult& R) {
    R.converged = true;
    char m[120];
    std::snprintf(m, sizeof m, "equilibrium of the whole energy: max|g| = %.3g", R.grad_max);
    R.message = m;
}

// One solve whose Hessian pattern follows the state (SmoothWetEnergy::follow_pattern), with the iteration budget of
// all the rounds.
void solve_following(SmoothWetEnergy& W, Solver& solver, Eigen::VectorXd& q, const SmoothRelaxOptions& opt,
                     const SolverOptions& base, SmoothRelaxResult& R) {
    SolverOptions& o = solver.options();
    configure(o, base, solver.capabilities(), W, opt);
    const std::int64_t per_round = opt.round_iterations > 0 ? opt.round_iterations : base.max_iter;
    o.max_iter = static_cast<int>(std::min<std::int64_t>(INT_MAX, per_round * opt.max_rounds));
    o.progress = base.progress || opt.progress;
    W.follow_pattern(true);
    add(R, solver.minimize(W, q));
    R.rounds = 1;
    if (R.last.converged()) return converged(R);
    char m[200];
    std::snprintf(m, sizeof m, "no equilibrium after %d solver iterations, max|g| = %.3g: ", R.iterations, R.grad_max);
    R.message = m + R.last.message;
}

// The relaxation's message when a solver's own max_iter, the budget of all its rounds, is spent.
void out_of_budget(SmoothRelaxResult& R, int max_iter) {
    --R.rounds;  // the rounds that ran
    char m[200];
    std::snprintf(m, sizeof m, "no equilibrium after %d solver iterations (the solver's max_iter = %d, in %d round%s), "
                  "max|g| = %.3g", R.iterations, max_iter, R.rounds, R.rounds == 1 ? "" : "s", R.grad_max);
    R.message = m;
}

// Rounds of at most round_iterations solver iterations with the pattern fixed in each, rebuilt between them where
// it no longer covers the state: for solvers that need a fixed pattern. A solver whose iterations are not Newton
// steps has its own max_iter as the budget of all its rounds together, as a user who sets it expects.
void solve_in_rounds(SmoothWetEnergy& W, Solver& solver, Eigen::VectorXd& q, const SmoothRelaxOptions& opt,
                     const SolverOptions& base, SmoothRelaxResult& R) {
    const SolverCapabilities caps = solver.capabilities();
    const bool budget = !caps.newton_steps;
    const int cap = caps.newton_steps && opt.round_iterations > 0 ? opt.round_iterations : base.max_iter;
    for (R.rounds = 1; R.rounds <= opt.max_rounds; ++R.rounds) {
        if (budget && R.iterations >= base.max_iter) return out_of_budget(R, base.max_iter);
        SolverOptions& o = solver.options();
        o.max_iter = budget ? base.max_iter - R.iterations : cap;
        o.warm_start = base.warm_start || (R.rounds > 1 && caps.warm_start);
        configure(o, base, caps, W, opt);
        add(R, solver.minimize(W, q));
        const bool stale = W.pattern_stale();
        const bool outdated = stale || !W.pattern_current();  // a reason the solve may have been held back
        if (stale) ++R.stale_patterns;
        const bool rebuilt = outdated && !R.last.converged();
        if (rebuilt) W.rebuild(q);
        if (opt.progress)
            std::fprintf(stderr, "  round %d: %s, %d iterations, E = %.10g, max|g| = %.3g%s\n", R.rounds,
                         to_string(R.last.status).c_str(), R.last.iterations, R.energy, R.grad_max,
                         rebuilt ? (stale ? ", pattern rebuilt (stale)" : ", pattern rebuilt") : "");
        if (R.last.converged()) return converged(R);
        const bool cut = R.last.status == SolveStatus::IterationLimit && cap < base.max_iter;
        if (!cut && !outdated) {  // a failure with the Hessian's pattern up to date: not the list's doing
            R.message = "the solver stopped: " + R.last.message;
            return;
        }
    }
    R.rounds = opt.max_rounds;
    char m[160];
    std::snprintf(m, sizeof m, "no equilibrium after %d rounds (%d solver iterations), max|g| = %.3g", opt.max_rounds,
                  R.iterations, R.grad_max);
    R.message = m;
}
}  // namespace

SmoothRelaxResult relax_smooth_wet(SmoothWetEnergy& W, Solver& solver, Eigen::VectorXd& q,
                                   const SmoothRelaxOptions& opt) {
    const auto t0 = Clock::now();
    OptionsGuard guard(solver, W);
    const int lists0 = W.list_builds(), patterns0 = W.pattern_builds();
    const double seconds_lists0 = W.seconds_lists(), seconds_patterns0 = W.seconds_patterns();
    SmoothRelaxResult R;
    if (W.params().pair.beta > 0 && solver.capabilities().follows_pattern && opt.follow_pattern)
        solve_following(W, solver, q, opt, guard.saved, R);
    else
        solve_in_rounds(W, solver, q, opt, guard.saved, R);
    R.list_builds = W.list_builds() - lists0, R.pattern_builds = W.pattern_builds() - patterns0;
    R.seconds_lists = W.seconds_lists() - seconds_lists0, R.seconds_patterns = W.seconds_patterns() - seconds_patterns0;
    R.seconds = seconds_since(t0);
    return R;
}

}  // namespace fibernet
