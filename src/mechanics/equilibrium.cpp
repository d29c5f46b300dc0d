#include "fibernet/mechanics/equilibrium.hpp"

#include <chrono>

#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/solve/newton.hpp"

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
    int extra_factorizations = 0;
    double extra_factor_time = 0;
    if (start) {
        eq.q = e.affine_map(*start, F_start, F);
    } else if (linear_start && !F.isIdentity(0) && e.num_dofs() > 0) {
        // Linear response of the reference state along F(t) = I + t (F - I), taken to t = 1.
        const Eigen::VectorXd q_ref = e.dofs(e.model().x);
        ModuliInfo info;
        auto* newton = dynamic_cast<NewtonSolver*>(&solver);  // share Newton's symbolic analysis
        CholmodLLT* llt = newton ? &newton->factorization_for(e.hessian_pattern()) : nullptr;
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
