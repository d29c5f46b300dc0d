#pragma once
// Newton's method with an exact sparse Hessian, CHOLMOD supernodal LL^T and Armijo backtracking (issue 3).
//
// The step ladder (newton_ladder.hpp; docs/moduli.md, "Newton ladder"), tried in order at each iteration until a
// factorization succeeds and the direction passes the descent check g.d < -1e-12 |g| |d|:
//   0. exact H + mu I          mu: a Levenberg-Marquardt shift, 1e-8 * mean diag(H) at the start (or the previous
//                              solve's with SolverOptions::warm_start), cut 10x after a full step the quadratic model
//                              predicted well (so mu -> 0 and convergence is quadratic, also on singular H:
//                              translations, floppy clusters), raised after backtracking; floored at
//                              mu_floor = 1e-13 * median diag(H) with SolverOptions::median_floor, else * mean diag
//                              (round-off scale of a null pivot: the floppy modes live on the soft coordinates, which
//                              the median represents; the mean is set by the stiffest columns). If H + mu I does
//                              not factor, the shift on the exact H is raised 4x at a time up to 0.2 mean diag;
//      With SolverOptions::ldl, rung 0 is first a simplicial LDL^T of H + mu I with its negative pivots replaced by
//      their magnitudes (cholmod_ldl.hpp): negative curvature is handled where it occurs, with no shift for the rest
//      of the Hessian (the wet relaxations of large networks, docs/wet.md); the escalation follows if that fails (a
//      zero pivot, no descent direction, or a line search that finds no step: then in the same iteration);
//   1. per-element PSD-projected H + mu I  (buckled or compressed segments make H indefinite);
//   2. projected H + lambda I, lambda = 1e-8 * mean diag(H) * 10^j, j = 0..10;
//   3. steepest descent d = -g.
// The next iteration starts one rung above the one that worked (polysolve's up-and-down strategy).
// Line search: Armijo backtracking from alpha = 1 (halving); +inf or NaN energies are failed trials (softcore,
// stretch.hpp). Near convergence the energy decrease falls below round-off; a full step is then accepted when
// the energy did not rise beyond round-off and max|g| fell.
// With SolverOptions::eliminate, each iteration first solves the hot places to local equilibrium and the line search
// re-solves them at every trial point (nonlinear_elimination.hpp); iterations and factorizations count the global
// ones, SolveResult::local_* the local solves.
// The iterations run in the solver loop (solver_loop.hpp), which owns the clock, the counts and the stop tests;
// Newton adds one of its own after each assembly, the round-off floor (below).
#include <memory>
#include <string>
#include <vector>

#include "fibernet/solve/cholmod_ldl.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/solver.hpp"

namespace fibernet {

// The round-off floor of max|g| at q (H: the Hessian there, upper triangle): max_i sum_j |H_ij| ulp(max(|q_j|, 1)),
// the gradient error of rounding every coordinate to its floating-point spacing. Newton accepts a state at this
// floor when it stalls above tol (docs/moduli.md, "Round-off floor"); linear_moduli accepts an equilibrium there.
double roundoff_floor(const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& q);

// What the last minimize() did at each iteration, and the shift it ended with (for SolverOptions::warm_start).
struct NewtonTrace {
    std::vector<double> history;  // max|g| after each assembly (index 0: the start)
    std::vector<int> rungs;       // the ladder's rung of each iteration (0..3)
    std::vector<double> shifts;   // the shift it factored with (0 on rung 3)
    double shift_rel = -1;        // the final shift / mean diag(H); < 0: none yet
};

class NewtonSolver : public Solver {
public:
    explicit NewtonSolver(SolverOptions opt) : opt_(opt) { opt_.check(name()); }
    std::string name() const override { return "newton"; }
    SolverOptions& options() override { return opt_; }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override;
    SolverCapabilities capabilities() const override;
    std::unique_ptr<Solver> clone() const override { return std::make_unique<NewtonSolver>(opt_); }
    // The CHOLMOD LL^T of the ladder, analyzed for `pattern` (analyzing it only if the pattern changed).
    LinearSolver* factorization_for(const Eigen::SparseMatrix<double>& pattern) override;

    // max|g| after each iteration of the last minimize() (index 0: the start), for convergence-rate checks.
    const std::vector<double>& history() const { return trace_.history; }
    // The rung of the ladder each iteration used (0..3), and the shift it factored with (0 on rung 3).
    const std::vector<int>& rungs() const { return trace_.rungs; }
    const std::vector<double>& shifts() const { return trace_.shifts; }
    // The CHOLMOD wrapper of the last minimize(), symbolically analyzed for that objective's Hessian pattern (kept
    // across calls: a strain sweep or the modulus after an equilibrium reuses the analysis); null before any call.
    CholmodLLT* factorization() { return llt_.get(); }

private:
    CholmodLLT& analyzed_for(const Eigen::SparseMatrix<double>& pattern, double* seconds = nullptr);

    SolverOptions opt_;
    NewtonTrace trace_;
    std::unique_ptr<CholmodLLT> llt_;
    std::unique_ptr<CholmodLDL> ldl_;
    Eigen::SparseMatrix<double> analyzed_;  // the pattern llt_ was analyzed for
};

}  // namespace fibernet
