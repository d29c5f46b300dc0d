#include "fibernet/solve/newton_ladder.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "fibernet/util/stopwatch.hpp"

namespace fibernet {

namespace {
constexpr double kDescent = 1e-12;  // g.d < -kDescent |g| |d|
constexpr double kLambda0 = 1e-8;   // escalations start here, relative to mean diag
constexpr int kLambdaSteps = 11;    // level 2: lambda0 10^j, j = 0..10
constexpr double kExactGrow = 4;    // level 0 escalation factor
constexpr double kExactCap = 0.2;   // level 0 escalation stops above this x mean diag
}  // namespace

bool LadderState::descent(const Eigen::VectorXd& d) const {
    return d.allFinite() && g.dot(d) < -kDescent * g.norm() * d.norm();
}

bool LadderState::factor_and_solve(LinearSolver& lin, double shift, Eigen::VectorXd& d) {
    const auto tf = std::chrono::steady_clock::now();
    const bool ok = lin.factorize(H, shift);
    result.timings.factorization += seconds_since(tf);
    ++result.factorizations;
    if (!ok) return false;
    const auto ts = std::chrono::steady_clock::now();
    d = -lin.solve(g);
    result.timings.solve += seconds_since(ts);
    return descent(d);
}

void LadderState::make_projected() {
    if (projected) return;
    Eigen::VectorXd gt(g.size());
    const auto ta = std::chrono::steady_clock::now();
    const long version = f.pattern_version();
    f.hessian(q, gt, H, true);
    // At the q of the exact Hessian, whose pattern already holds every non-zero element there.
    if (f.pattern_version() != version)
        throw std::logic_error("Newton: the Hessian pattern changed between two evaluations at the same state");
    result.timings.assembly += seconds_since(ta);
    projected = true;
}

// The exact H + mu I with its negative pivots replaced by their magnitudes: a positive definite matrix equal to
// H + mu I wherever H is positive definite. Negative curvature is handled where it occurs, with no shift for the rest
// of the Hessian, which on a large wet network would be set by its worst spot and shorten the step of every other
// part. Not on the retry (pass 1), which exists because this direction's line search failed.
bool ModifiedLdlRung::direction(LadderState& s, Eigen::VectorXd& d, double& shift) {
    modified_ = false;
    if (s.pass != 0 || !s.factor_and_solve(lin_, s.mu, d)) return false;
    shift = s.mu;
    // No negative pivot: H + mu I is positive definite (Sylvester's law of inertia) and this is the LL^T direction
    // itself, so a failed line search has nothing to retry.
    modified_ = lin_.negative_pivots() > 0;
    return true;
}

// Exact H + lambda I with lambda raised 4x at a time (Nocedal & Wright, Alg. 3.3) before giving up the exact Hessian:
// negative curvature (capillary torques, buckling) is kept in every direction but the few unstable ones, where
// projecting each element's block would overstate the stiffness of the whole assembly and turn Newton into a
// linearly converging method (docs/moduli.md, "Newton ladder"). On the retry H + mu I is known to be indefinite: the
// escalation starts above mu.
bool ShiftedHessianRung::direction(LadderState& s, Eigen::VectorXd& d, double& shift) {
    if (s.pass == 0 && s.factor_and_solve(lin_, s.mu, d)) {
        shift = s.mu;
        return true;
    }
    if (!escalate_) return false;
    for (double lam = std::max(kExactGrow * s.mu, kLambda0 * s.dm); lam <= kExactCap * s.dm; lam *= kExactGrow)
        if (s.factor_and_solve(lin_, lam, d)) {
            shift = lam;
            return true;
        }
    return false;
}

// Buckled or compressed segments make H indefinite: the per-element PSD projection is positive semidefinite.
bool ProjectedHessianRung::direction(LadderState& s, Eigen::VectorXd& d, double& shift) {
    s.make_projected();
    if (!s.factor_and_solve(lin_, s.mu, d)) return false;
    shift = s.mu;
    return true;
}

bool ProjectedShiftRung::direction(LadderState& s, Eigen::VectorXd& d, double& shift) {
    s.make_projected();
    double lam = std::max(s.mu, kLambda0 * s.dm);
    for (int j = 0; j < kLambdaSteps; ++j, lam *= 10)
        if (s.factor_and_solve(lin_, lam, d)) {
            shift = lam;
            return true;
        }
    return false;
}

bool SteepestDescentRung::direction(LadderState& s, Eigen::VectorXd& d, double& shift) {
    d = -s.g / s.dm;
    shift = 0;
    return true;
}

NewtonLadder::NewtonLadder(LinearSolver& llt, LinearSolver* ldl, bool escalate) {
    if (ldl) {
        auto r = std::make_unique<ModifiedLdlRung>(*ldl);
        ldl_ = r.get();
        rungs_.push_back(std::move(r));
    }
    rungs_.push_back(std::make_unique<ShiftedHessianRung>(llt, escalate));
    rungs_.push_back(std::make_unique<ProjectedHessianRung>(llt));
    rungs_.push_back(std::make_unique<ProjectedShiftRung>(llt));
    rungs_.push_back(std::make_unique<SteepestDescentRung>());
}

NewtonRung& NewtonLadder::descend(LadderState& s, int start_level, Eigen::VectorXd& d, double& shift) {
    for (auto& rung : rungs_)
        if (rung->level() >= start_level && rung->direction(s, d, shift)) return *rung;
    return steepest();  // not reached: the last rung always has a direction
}

}  // namespace fibernet
