#pragma once
// Internal helpers shared by the solvers in src/solve/ (not a public header): a stopwatch for the timings split,
// max|v|, and what the line-search methods (L-BFGS, CG) share: the stall watch and their two ends. The loop, the
// counts, progress and the stop tests are the SolverRun's (solver_loop.hpp).
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "fibernet/solve/line_search.hpp"
#include "fibernet/solve/solver_loop.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::detail {

inline double max_abs(const Eigen::VectorXd& v) { return v.size() ? v.lpNorm<Eigen::Infinity>() : 0.0; }

class Clock {
public:
    Clock() : t0_(std::chrono::steady_clock::now()) {}
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    }

private:
    std::chrono::steady_clock::time_point t0_;
};

// Progress of a line-search method: an energy decrease beyond round-off, or a new lowest max|g| (below round-off the
// energy cannot tell, the gradient still can). A gradient inconsistent with the energy shows neither.
class StallWatch {
public:
    void start(double grad_max) { best_ = grad_max, idle_ = 0; }
    // After a step from energy e to e_new with max|g| grad_max_new there.
    void update(double e, double e_new, double grad_max_new) {
        const double noise = 1e-16 * std::abs(e);  // any decrease beyond the last bits
        const bool progress = e_new < e - noise || grad_max_new < 0.9 * best_;
        best_ = std::min(best_, grad_max_new);
        idle_ = progress ? 0 : idle_ + 1;
    }
    int idle() const { return idle_; }
    // Stalled (after the step that made it so) once `limit` steps in a row made no progress.
    bool stalled(int limit, double grad_max, Step& out) const {
        if (idle_ < limit) return false;
        out = Step::stop(SolveStatus::Stalled, "no energy decrease beyond round-off and no new minimum of max|g| for " +
                                                   std::to_string(idle_) + " iterations at max|g| = " + show(grad_max),
                         true);
        return true;
    }

private:
    double best_ = 0;
    int idle_ = 0;
};

// The end of a solve whose line search failed with nothing left to retry.
inline Step line_search_stop(const LineSearchResult& lr, double grad_max) {
    const SolveStatus st =
        lr.outcome == LineSearchOutcome::NonFinite ? SolveStatus::NonFinite : SolveStatus::LineSearchFailed;
    return Step::stop(st, "line search: " + to_string(lr.outcome) + " after " + std::to_string(lr.evals) +
                              " evaluations at max|g| = " + show(grad_max));
}

}  // namespace fibernet::detail
