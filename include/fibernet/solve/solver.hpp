#pragma once
// A minimizer of an Objective: it sees only value, gradient and Hessian. Every solver in solve/ implements this and
// is created by name (make_solver) so that `--solver` can pick any of them.
#include <memory>
#include <string>

#include "fibernet/energy/objective.hpp"
#include "fibernet/solve/nonlinear_elimination.hpp"
#include "fibernet/solve/result.hpp"

namespace fibernet {

struct SolverOptions {
    double tol = 1e-10;      // stop at max|g| <= tol
    int max_iter = 500;      // iteration budget (solver-specific meaning: Newton steps, L-BFGS iterations, ...)
    double max_seconds = 0;  // wall-time budget, 0 = none
    bool verbose = false;    // progress to stderr
    bool warm_start = false; // start from the state the previous minimize() adapted (Newton: its shift), for a caller
                             // that resumes an interrupted solve of a slightly changed objective; others ignore it
    bool ldl = false;        // Newton: rung 0 by a simplicial LDL^T of the exact H + mu I with negative pivots flipped
                             // (cholmod_ldl.hpp) instead of the escalated shift; others ignore it
    bool eliminate = false;  // Newton: nonlinear elimination of the hot places before and inside each global step
                             // (nonlinear_elimination.hpp); others ignore it
    EliminationOptions elimination;
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
};

// Throws InputError naming the solver if unknown.
std::unique_ptr<Solver> make_solver(const std::string& name, const SolverOptions& opt);

}  // namespace fibernet
