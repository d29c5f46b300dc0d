#include "fibernet/wet/wet_run.hpp"

#include <chrono>
#include <cmath>
#include <limits>

namespace fibernet {

namespace {
double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

double relaxed_shear_modulus(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const Eigen::VectorXd& q,
                             const std::vector<Bridge>& bridges, const WetParams& params, Solver& solver, double h) {
    double E[3];
    const double A = std::abs((F * dry.model().box.B0()).determinant());
    for (int k = -1; k <= 1; ++k) {
        Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
        S(0, 1) = k * h;
        const Eigen::Matrix2d Fk = S * F;  // simple shear of the current state (area kept)
        Eigen::VectorXd qk = dry.affine_map(q, F, Fk);
        WetEnergy W(dry, Fk, bridges, params);
        const SolveResult r = solver.minimize(W, qk);
        if (!r.converged()) return std::numeric_limits<double>::quiet_NaN();
        E[k + 1] = W.value(qk);
    }
    return (E[0] - 2 * E[1] + E[2]) / (A * h * h);
}

WetRun run_wet(const Network& net, const Model& m, const Eigen::Matrix2d& F, const WetRunOptions& opt,
               const WetState* dry_start) {
    WetRun run;
    NetworkEnergy dry(m);
    const Eigen::Matrix2d B = F * m.box.B0();
    auto solver = make_solver(opt.solver, opt.solver_options);
    const WetParams none;  // beta = 0: the dry energy
    double t0 = now();
    if (dry_start) {
        run.dry = *dry_start;
    } else {
        run.dry.q = dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F);
        WetEnergy D(dry, F, {}, none);
        run.dry_solve = solver->minimize(D, run.dry.q);
        run.dry.converged = run.dry_solve.converged();
        run.dry.energy = D.split(run.dry.q);
        run.seconds_dry = now() - t0;
        t0 = now();
        run.dry.pores = pores(m, dry.positions(run.dry.q, F), B);
        run.seconds_pores += now() - t0;
        run.dry.shear_modulus = std::numeric_limits<double>::quiet_NaN();
        if (opt.moduli && run.dry.converged) {
            t0 = now();
            run.dry.shear_modulus = relaxed_shear_modulus(dry, F, run.dry.q, {}, none, *solver, opt.modulus_strain);
            run.seconds_moduli += now() - t0;
        }
    }
    // Wet: bridges at the dry equilibrium's crossings (the network's crossings, which the dry relaxation moved by
    // little), made consistent with the geometry before the first solve.
    run.initial_bridges = wet_crossings(net, m, dry.positions(run.dry.q, F), B, opt.rule);
    std::vector<Bridge> bridges = run.initial_bridges;
    ActiveSetOptions first = opt.active_set;
    first.form_new = false;
    update_bridges(dry, run.dry.q, F, bridges, first);
    run.wet.q = run.dry.q;
    run.active = relax_wet(dry, F, opt.params, bridges, *solver, run.wet.q, opt.active_set);
    run.seconds_wet_solve = run.active.seconds_solve;
    run.seconds_events = run.active.seconds_events;
    run.wet.converged = run.active.last.converged();
    run.wet.energy = WetEnergy(dry, F, run.active.bridges, opt.params).split(run.wet.q);
    t0 = now();
    const Eigen::VectorXd x = dry.positions(run.wet.q, F);
    run.wet.pores = pores(m, x, B);
    run.bundles = bundles(m, x, B, run.active.bridges, opt.bundle_angle_deg);
    run.seconds_pores += now() - t0;
    run.wet.shear_modulus = std::numeric_limits<double>::quiet_NaN();
    if (opt.moduli && run.wet.converged) {
        t0 = now();
        run.wet.shear_modulus =
            relaxed_shear_modulus(dry, F, run.wet.q, run.active.bridges, opt.params, *solver, opt.modulus_strain);
        run.seconds_moduli += now() - t0;
    }
    return run;
}

}  // namespace fibernet
