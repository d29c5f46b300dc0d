#pragma once
// The result every solver returns (Newton, L-BFGS, NLopt, Ipopt, FIRE, CG): one status type, never a hidden failure.
#include <Eigen/Core>
#include <string>

namespace fibernet {

enum class SolveStatus {
    Converged,          // max|g| <= tol (Newton also: at the round-off floor with progress stopped; see message)
    IterationLimit,     // budget spent before tol
    LineSearchFailed,   // no acceptable step along a descent direction
    NonFinite,          // NaN/inf energy or gradient met
    Stalled,            // no progress possible (e.g. round-off limited, NLopt ROUNDOFF_LIMITED)
    Failed,             // any other failure the backend reported (message says which)
};
std::string to_string(SolveStatus s);

struct SolveTimings {
    double assembly = 0, factorization = 0, solve = 0, line_search = 0, total = 0;  // seconds
    SolveTimings& operator+=(const SolveTimings& o) {
        assembly += o.assembly, factorization += o.factorization, solve += o.solve, line_search += o.line_search;
        total += o.total;
        return *this;
    }
};

struct SolveResult {
    SolveStatus status = SolveStatus::Failed;
    std::string solver;                 // name, e.g. "newton"
    std::string message;                // detail from the backend or the ladder
    int iterations = 0;
    int factorizations = 0;
    int ldl_retries = 0;                // Newton: iterations whose LDL^T direction failed its line search (SolverOptions::ldl)
    int evaluations = 0;                // energy/gradient evaluations
    int local_solves = 0;               // Newton with elimination: part solves, their iterations and factorizations
    int local_iterations = 0;           // (not counted in iterations and factorizations above, which are global)
    int local_factorizations = 0;
    int eliminating_iterations = 0;     // Newton with elimination: global iterations that solved hot parts first (the
                                        // others found none, or a grown set above EliminationOptions::max_fraction)
    double energy = 0;
    double grad_max = 0;                // max |g| at the returned state
    double grad_floor = 0;              // round-off floor of max |g| at the returned state (Newton; 0: not estimated)
    SolveTimings timings;

    bool converged() const { return status == SolveStatus::Converged; }
};

}  // namespace fibernet
