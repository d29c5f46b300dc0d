#pragma once
// Internal helpers shared by the solvers in src/solve/ (not a public header): a stopwatch for the timings split and
// max|v|. The loop, the counts, progress and the stop tests are the SolverRun's (solver_loop.hpp).
#include <Eigen/Core>
#include <chrono>

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

}  // namespace fibernet::detail
