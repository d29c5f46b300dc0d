#pragma once
// A solver that holds one wall-time budget across all its minimize() calls (the benchmarks' stability maps): each call
// gets what is left (the event model's active-set loop and the smooth model's rounds call it once per round); once
// it is spent, minimize() returns Failed at once, which ends the relaxation.
#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <utility>

#include "fibernet/solve/solver.hpp"
#include "fibernet/solve/solver_registry.hpp"
#include "fibernet/util/stopwatch.hpp"

namespace fibernet::bench {

class DeadlineSolver : public Solver {
public:
    DeadlineSolver(std::string name, SolverOptions opt, double seconds)
        : name_(std::move(name)), opt_(opt), seconds_(seconds), t0_(std::chrono::steady_clock::now()) {}
    std::string name() const override { return name_; }
    SolverOptions& options() override { return opt_; }
    SolverCapabilities capabilities() const override { return solver_capabilities(name_); }
    std::unique_ptr<Solver> clone() const override { return std::make_unique<DeadlineSolver>(*this); }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override {
        const double left = seconds_ - seconds_since(t0_);
        if (left <= 0) {
            spent = true;
            SolveResult r;
            r.status = SolveStatus::Failed, r.solver = name_;
            r.message = "the bench's wall budget for the whole relaxation is spent";
            Eigen::VectorXd g;
            r.energy = f.gradient(q, g);
            r.grad_max = g.size() ? g.lpNorm<Eigen::Infinity>() : 0.0;
            return r;
        }
        SolverOptions o = opt_;
        o.max_seconds = o.max_seconds > 0 ? std::min(o.max_seconds, left) : left;
        return make_solver(name_, o)->minimize(f, q);
    }
    bool spent = false;

private:
    std::string name_;
    SolverOptions opt_;
    double seconds_;
    std::chrono::steady_clock::time_point t0_;
};

}  // namespace fibernet::bench
