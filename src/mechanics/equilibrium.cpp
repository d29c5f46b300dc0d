#include "fibernet/mechanics/equilibrium.hpp"

#include <chrono>

#include "fibernet/mechanics/moduli.hpp"

namespace fibernet {

Eigen::VectorXd affine_start(const NetworkEnergy& e, const Eigen::Matrix2d& F) {
    return e.affine_map(e.dofs(e.model().x), Eigen::Matrix2d::Identity(), F);
}

Equilibrium relax(const NetworkEnergy& e, const Eigen::Matrix2d& F, Solver& solver, const Eigen::VectorXd* start,
                  const Eigen::Matrix2d& F_start, bool linear_start) {
    Equilibrium eq;
    eq.F = F;
    eq.start = "affine";
    const auto t0 = std::chrono::steady_clock::now();
    if (!start && F == Eigen::Matrix2d::Identity()) {
        // The reference state at F = I: every stretch and bend term is non-negative and vanishes at its rest
        // vectors, so E = 0 there is an exact global minimum. Its computed gradient is round-off (strain ~ 1e-16
        // on segments of 1e-5 gives 1e-11..1e-10 at L = 80), and Newton would chase it along floppy modes
        // (measured at L = 80: 61 iterations, 73 s, drifting the state far enough to move G by 4e-4). So the
        // reference is returned as it is when its energy is at round-off level.
        EnergyEval ev;
        eq.q = e.dofs(e.model().x);
        e.evaluate(eq.q, F, Eigen::Matrix2d::Zero(), kGradient, ev);
        const double elements = static_cast<double>(e.model().segments.size() + e.model().hinges.size());
        if (ev.energy <= 1e-20 * std::max(1.0, elements)) {
            eq.result.solver = solver.name();
            eq.result.status = SolveStatus::Converged;
            eq.result.message = "rest state: exact minimum (E = 0 up to round-off), no iterations";
            eq.result.energy = ev.energy;
            eq.result.grad_max = e.num_dofs() > 0 ? ev.gradient.lpNorm<Eigen::Infinity>() : 0.0;
            eq.result.timings.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            eq.energy = ev.energy, eq.stretch = ev.stretch, eq.bend = ev.bend;
            return eq;
        }
    }
    int extra_factorizations = 0;
    double extra_factor_time = 0;
    if (start) {
        eq.q = e.affine_map(*start, F_start, F);
    } else if (linear_start && !F.isIdentity(0) && e.num_dofs() > 0) {
        // Linear response of the reference state along F(t) = I + t (F - I), taken to t = 1.
        const Eigen::VectorXd q_ref = e.dofs(e.model().x);
        ModuliInfo info;
        LinearSolver* llt = solver.factorization_for(e.hessian_pattern());  // share the solver's symbolic analysis
        const StrainMode mode{"start", F - Eigen::Matrix2d::Identity(), 1.0};
        const auto m = linear_moduli(e, q_ref, Eigen::Matrix2d::Identity(), {mode}, {}, &info, llt);
        extra_factorizations = info.factorizations;
        extra_factor_time = info.seconds_factorization;
        if (m.front().ok && m.front().response.allFinite()) {
            eq.q = q_ref - m.front().response;
            eq.start = "linear_response";
        } else {
            eq.q = affine_start(e, F);
        }
    } else {
        eq.q = affine_start(e, F);
    }
    const double t_start = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    StrainedEnergy obj(e, F);
    eq.result = solver.minimize(obj, eq.q);
    eq.result.factorizations += extra_factorizations;
    eq.result.timings.factorization += extra_factor_time;
    eq.result.timings.total += t_start;
    EnergyEval ev;
    e.evaluate(eq.q, F, Eigen::Matrix2d::Zero(), kValue, ev);
    eq.energy = ev.energy, eq.stretch = ev.stretch, eq.bend = ev.bend;
    return eq;
}

}  // namespace fibernet
