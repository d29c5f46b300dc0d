#pragma once
// A minimizer of an Objective: it sees only value, gradient and Hessian. Every solver in solve/ implements this, runs
// its iterations in the one loop of solver_loop.hpp, and is created by name from the registry (solver_registry.hpp),
// so that `--solver` can pick any of them. Callers ask a solver what it can do (capabilities()) and copy it (clone()),
// never which one it is.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>

#include "fibernet/energy/objective.hpp"
#include "fibernet/solve/linear_solver.hpp"
#include "fibernet/solve/nonlinear_elimination.hpp"
#include "fibernet/solve/result.hpp"

namespace fibernet {

// A state between the local solves of an iteration, its energy below the last iterate's: not an iterate, so its
// gradient is not evaluated; energy() evaluates it, for a hook that writes it (SolverOptions::observe_within).
using WithinObserver = std::function<void(const Eigen::VectorXd& q, const std::function<double()>& energy)>;

struct SolverOptions {
    double tol = 1e-10;      // stop at max|g| <= tol
    int max_iter = 500;      // iteration budget (solver-specific meaning: Newton steps, L-BFGS iterations, ...)
    double max_seconds = 0;  // wall-time budget, 0 = none
    bool verbose = false;    // progress to stderr (Newton: a line per iteration)
    bool progress = false;   // the once-a-second progress line of verbose alone (solver_loop.hpp)
    bool warm_start = false; // start from the state the previous minimize() adapted (Newton: its shift), for a caller
                             // that resumes an interrupted solve of a slightly changed objective; others ignore it
    bool ldl = false;        // Newton: rung 0 by a simplicial LDL^T of the exact H + mu I with negative pivots flipped
                             // (cholmod_ldl.hpp) instead of the escalated shift; others ignore it
    bool projected = false;  // Newton: projected Newton (newton_ladder.hpp): the element-wise PSD-projected H + mu I
                             // by LL^T while far from a minimum, the exact H + mu I (not shifted further) once a full
                             // step was accepted; excludes ldl. Others ignore it
    bool median_floor = false;  // Newton: the shift's floor relative to the median diagonal of H instead of the mean
                                // (newton.hpp); the dry commands set it, the wet relaxations keep the mean, with
                                // which their studies were measured (docs/solvers.md "Newton's shift floor")
    bool eliminate = false;  // Newton: nonlinear elimination of the hot places before and inside each global step
                             // (nonlinear_elimination.hpp); others ignore it
    EliminationOptions elimination;
    double max_step = 0;     // Newton: no coordinate moves more than this in one step (the line search starts at the
                             // step scaled down to it, and a capped step counts as a shortened one); 0 = no cap.
                             // The smooth wet model sets it to its neighbour list's skin (smooth_wet_relax.hpp)
    // Called with each accepted iterate q, its energy and max|g|, by the solvers that run the loop of solver_loop.hpp
    // (Newton, L-BFGS, CG, FIRE; not NLopt or Ipopt, whose loops are their own): a caller's hook for checkpoints of
    // long solves (`fibernet wet --checkpoint-seconds`). Empty: none.
    std::function<void(const Eigen::VectorXd& q, double energy, double grad_max)> observe;
    // Newton with the Schwarz sweep or elimination: called between the parts of the local solves before a global step
    // (WithinObserver). A sweep of a large network takes minutes to hours (docs/wet.md, "The Schwarz sweep"), and a
    // checkpoint at iterates only would lose it to an interrupt. Empty: none.
    WithinObserver observe_within;

    // The one check of these options (every solver's constructor calls it): throws InputError("<where>: <name> = <v>
    // must ..."), `where` naming the solver.
    void check(const std::string& where) const;
};

// What a solver does with the options and the objective, for callers that adapt to it.
struct SolverCapabilities {
    bool hessian = false;       // assembles the sparse Hessian
    bool ldl = false;           // SolverOptions::ldl acts
    bool projected = false;     // SolverOptions::projected acts
    bool eliminate = false;     // SolverOptions::eliminate acts
    bool warm_start = false;    // SolverOptions::warm_start acts
    bool newton_steps = false;  // an iteration is a factorized Newton step, so a few of them make a round of the wet
                                // active-set loop and its local rounds are solved with it (docs/wet.md, "Local rounds")
    bool shares_factorization = false;  // factorization_for() offers its analyzed positive definite factorization
    bool follows_pattern = false;  // takes an objective whose Hessian pattern changes during a solve
                                   // (Objective::pattern_version): analyzes each new pattern as it comes
};

class Solver {
public:
    virtual ~Solver() = default;
    virtual std::string name() const = 0;
    // Minimizes f starting from q, overwriting q with the final state. The result's status says whether q is
    // an equilibrium; callers must not report an unconverged q as one.
    virtual SolveResult minimize(Objective& f, Eigen::VectorXd& q) = 0;
    // The options the next minimize() uses; a caller may change them between calls (the wet active-set loop caps
    // the iterations of a round while its bridge set is still changing).
    virtual SolverOptions& options() = 0;
    virtual SolverCapabilities capabilities() const = 0;
    // A solver of the same kind, options and parameters, without what earlier minimize() calls adapted (shifts,
    // analyses): for a caller that needs another one (a thread's, a corrector's).
    virtual std::unique_ptr<Solver> clone() const = 0;
    // With capabilities().shares_factorization: the positive definite factorization this solver factors with,
    // analyzed for `pattern` (re-analyzed only if the pattern changed), for a caller that solves with the same
    // Hessian afterwards (the linear moduli at an equilibrium); else nullptr.
    virtual LinearSolver* factorization_for(const Eigen::SparseMatrix<double>& pattern) {
        (void)pattern;
        return nullptr;
    }
};

// The solver registered as `name` (solver_registry.hpp) with options `opt`; throws InputError naming an unknown
// solver or a bad option.
std::unique_ptr<Solver> make_solver(const std::string& name, const SolverOptions& opt);

}  // namespace fibernet
