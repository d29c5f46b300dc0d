#pragma once
// Relaxing the smooth wet energy (smooth_wet_energy.hpp; issue 22): a solver minimizes the one energy directly. Its
// values and gradients are always the whole energy's (the energy rebuilds its neighbour list where needed). No bridge
// set, no events: a rebuild changes only which pairs are evaluated and which entries the Hessian holds. Converged when
// the solver reports an equilibrium, which then is one of the whole energy.
//   - A solver that follows a changing Hessian pattern (SolverCapabilities::follows_pattern: Newton) minimizes it in
//     one solve; the energy rebuilds the pattern at a Hessian that needs it (SmoothWetEnergy::follow_pattern), and
//     the solver analyzes the new one. The budget is max_rounds x round_iterations iterations.
//   - Any other solver runs rounds of at most `round_iterations` iterations, the pattern fixed in each and rebuilt
//     between them where it no longer covers the state (the list was rebuilt since, or a non-zero pair fell outside
//     it). A solver whose iterations are not Newton steps (L-BFGS, CG, FIRE, NLopt, Ipopt) has its own max_iter as
//     the budget of all its rounds together.
#include <Eigen/Core>
#include <functional>
#include <string>

#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/smooth_wet_energy.hpp"

namespace fibernet {

struct SmoothRelaxOptions {
    // Solver iterations per round for solvers whose iterations are Newton steps (SolverCapabilities::newton_steps;
    // others share their own max_iter over all rounds); 0: rounds are not cut.
    int round_iterations = 20;
    int max_rounds = 200;
    bool progress = false;  // a line per round on stderr (following: the solver's once-a-second line)
    double max_step = -1;   // Newton: largest coordinate change per step (SolverOptions::max_step); < 0: the skin
    bool ldl = true;        // Newton's first rung by LDL^T with flipped negative pivots (SolverOptions::ldl), beta > 0
    bool projected = false; // projected Newton (SolverOptions::projected), beta > 0; takes precedence over ldl
    bool follow_pattern = true;  // false: rounds for every solver (tests: the two ways agree)
    // Called with each accepted iterate of the relaxation, over all its rounds (SolverOptions::observe); empty: none.
    std::function<void(const Eigen::VectorXd& q, double energy, double grad_max)> observe;
    // Called between the local solves of a global iteration (SolverOptions::observe_within); empty: none.
    WithinObserver observe_within;
};

struct SmoothRelaxResult {
    bool converged = false;
    std::string message;
    SolveResult last;            // the last round's solve (the one solve's, when it follows the pattern)
    int rounds = 0, list_builds = 0, pattern_builds = 0, stale_patterns = 0;  // rounds = 1 when following
    int iterations = 0, factorizations = 0, evaluations = 0;
    int local_solves = 0, local_iterations = 0;  // nonlinear elimination's (SolverOptions::eliminate), summed
    int eliminating_iterations = 0;              // global iterations that eliminated (SolveResult), summed
    double grad_max = 0;         // max|g| of the whole energy at the returned state
    double energy = 0;
    SolveTimings timings;        // summed over the rounds
    double seconds_patterns = 0; // pattern builds (inside Newton's assembly when it follows the pattern)
    double seconds_lists = 0;    // list builds and region updates (inside the evaluations' time)
    double seconds = 0;
};

SmoothRelaxResult relax_smooth_wet(SmoothWetEnergy& W, Solver& solver, Eigen::VectorXd& q,
                                   const SmoothRelaxOptions& opt = {});

}  // namespace fibernet
