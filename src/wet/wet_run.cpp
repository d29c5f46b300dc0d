#include "fibernet/wet/wet_run.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "fibernet/util/error.hpp"
#include "fibernet/util/stopwatch.hpp"
#include "fibernet/wet/wet_moduli.hpp"

namespace fibernet {

namespace {
// Faces narrower than the contact distance are walls, not pores, in either model (pores.hpp).
double wall_width(const WetRunOptions& opt, const Model& m) {
    return opt.smooth.pair.contact > 0 ? opt.smooth.pair.contact : default_wall_width(m);
}
}  // namespace

namespace {
// The linear shear modulus at (q, F) with the bridge set frozen and its error bound; NaN for both if it failed.
void linear_shear_modulus(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const Eigen::VectorXd& q,
                          const std::vector<Bridge>& bridges, const WetParams& params, double& G, double& error) {
    WetEnergy W(dry, F, bridges, params);
    const Modulus M = wet_linear_moduli(W, q, {shear_mode(F, std::abs((F * dry.model().box.B0()).determinant()))}).front();
    G = M.ok ? M.value : std::numeric_limits<double>::quiet_NaN();
    error = M.ok ? M.error : std::numeric_limits<double>::quiet_NaN();
}

// WetState's two shear moduli at (q, F) with the bridge set frozen: the second difference first (its solves leave
// the solver as before the exact modulus existed, so what follows, e.g. the free box, takes the same path).
void shear_moduli(WetState& s, const NetworkEnergy& dry, const Eigen::Matrix2d& F, const std::vector<Bridge>& bridges,
                  const WetParams& params, Solver& solver, double h) {
    s.shear_modulus_fd = relaxed_shear_modulus(dry, F, s.q, bridges, params, solver, h);
    linear_shear_modulus(dry, F, s.q, bridges, params, s.shear_modulus, s.shear_modulus_error);
}
}  // namespace

namespace {
// The smooth energy's exact linear shear modulus at (q, F) and its error bound; NaN for both if it failed.
void smooth_linear_shear_modulus(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const Eigen::VectorXd& q,
                                 const FiberPairs& dry_pairs, const SmoothWetParams& sp, double& G, double& error) {
    SmoothWetEnergy W(dry, F, sp, dry_pairs, q);  // its pattern fresh at q: every non-zero pair's block
    const double A = std::abs((F * dry.model().box.B0()).determinant());
    const Modulus M = wet_linear_moduli(W, q, {shear_mode(F, A)}).front();
    G = M.ok ? M.value : std::numeric_limits<double>::quiet_NaN();
    error = M.ok ? M.error : std::numeric_limits<double>::quiet_NaN();
}

// The smooth model's two shear moduli (as shear_moduli): the second difference of relaxed smooth energies at
// gamma = +-h and the exact linear modulus of the smooth energy.
// sp: the resolved pair parameters (widths from the model), as the relaxation had them.
void smooth_shear_moduli(WetState& s, const NetworkEnergy& dry, const Eigen::Matrix2d& F, const FiberPairs& dry_pairs,
                         const SmoothWetParams& sp, const SmoothRelaxOptions& ro, double h, Solver& solver) {
    double E[3];
    const double A = std::abs((F * dry.model().box.B0()).determinant());
    s.shear_modulus_fd = std::numeric_limits<double>::quiet_NaN();
    bool ok = true;
    for (int k = -1; k <= 1 && ok; ++k) {
        Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
        S(0, 1) = k * h;
        const Eigen::Matrix2d Fk = S * F;
        Eigen::VectorXd qk = dry.affine_map(s.q, F, Fk);
        SmoothWetEnergy W(dry, Fk, sp, dry_pairs, qk);
        ok = relax_smooth_wet(W, solver, qk, ro).converged;
        E[k + 1] = W.value(qk);
    }
    if (ok) s.shear_modulus_fd = (E[0] - 2 * E[1] + E[2]) / (A * h * h);
    smooth_linear_shear_modulus(dry, F, s.q, dry_pairs, sp, s.shear_modulus, s.shear_modulus_error);
}


// The smooth model's free box from the fixed-box wet state, with its pores, bundles and linear shear modulus.
void smooth_run_free_box(WetRun& run, const NetworkEnergy& dry, const Eigen::Matrix2d& F, const FiberPairs& dry_pairs,
                         const SmoothWetParams& sp, const WetRunOptions& opt, Solver& solver) {
    if (!run.wet.converged) {
        run.free_box.F0 = run.free_box.F = F;
        run.free_box.message = "not attempted: the wet relaxation at the fixed box did not converge";
        return;
    }
    FreeBoxResult& fb = run.free_box;
    fb = smooth_free_box(dry, F, sp, dry_pairs, opt.smooth_relax, run.wet.q, solver, opt.free_box);
    const Model& m = dry.model();
    const Eigen::Matrix2d Bf = fb.F * m.box.B0();
    const Eigen::VectorXd xf = dry.positions(fb.q, fb.F);
    fb.pores = pores(m, xf, Bf, wall_width(opt, m));
    fb.bundles = bundles(m, xf, Bf, fb.bridges, opt.bundle_angle_deg);
    if (opt.moduli) {
        const double t0 = wall_seconds();
        smooth_linear_shear_modulus(dry, fb.F, fb.q, dry_pairs, sp, fb.shear_modulus, fb.shear_modulus_error);
        run.seconds_moduli += wall_seconds() - t0;
    }
}

// The smooth model's wet relaxation and what follows it (run_wet's second half).
void run_wet_smooth(WetRun& run, const Network& net, const NetworkEnergy& dry, const Eigen::Matrix2d& F,
                    const WetRunOptions& opt, Solver& solver) {
    const Model& m = dry.model();
    const Eigen::Matrix2d B = F * m.box.B0();
    const FiberPairs dry_pairs = smooth_dry_pairs(net, opt.rule);
    SmoothWetParams sp = opt.smooth;
    sp.pair.beta = opt.params.beta, sp.pair.law = opt.params.law;
    // Widths not given (0): the fiber's own sizes, radius 1/a and diameter 2/a (seed units).
    const double r = 1 / m.aspect_ratio;
    if (sp.pair.crossing_width <= 0) sp.pair.crossing_width = r;
    if (sp.pair.contact <= 0) sp.pair.contact = 2 * r;
    if (sp.pair.overlap_width <= 0) sp.pair.overlap_width = r;
    run.wet.q = opt.wet_start.size() ? opt.wet_start : run.dry.q;
    SmoothWetEnergy W(dry, F, sp, dry_pairs, run.wet.q);
    run.initial_bridges = W.bridges(run.wet.q);
    SmoothRelaxOptions ro = opt.smooth_relax;
    ro.observe = opt.observe_wet;
    ro.observe_within = opt.observe_wet_within;
    run.smooth = relax_smooth_wet(W, solver, run.wet.q, ro);
    run.seconds_wet_solve = run.smooth.seconds;
    run.active.seconds_solve = run.smooth.seconds;
    run.wet.converged = run.smooth.converged;
    run.active.last = run.smooth.last;
    run.active.rounds = run.smooth.rounds;
    run.active.solver_iterations = run.smooth.iterations;
    run.active.factorizations = run.smooth.factorizations;
    run.active.timings = run.smooth.timings;
    run.active.stable = run.smooth.converged;
    run.active.message = run.smooth.message;
    run.active.bridges = W.bridges(run.wet.q);
    const SmoothWetSplit split = W.split(run.wet.q);
    run.wet.energy.stretch = split.stretch, run.wet.energy.bend = split.bend;
    run.wet.energy.capillary = split.capillary();
    double t0 = wall_seconds();
    const Eigen::VectorXd x = dry.positions(run.wet.q, F);
    run.wet.pores = pores(m, x, B, wall_width(opt, m));
    run.bundles = bundles(m, x, B, run.active.bridges, opt.bundle_angle_deg);
    run.seconds_pores += wall_seconds() - t0;
    if (opt.moduli && run.wet.converged) {
        t0 = wall_seconds();
        smooth_shear_moduli(run.wet, dry, F, dry_pairs, sp, opt.smooth_relax, opt.modulus_strain, solver);
        run.seconds_moduli += wall_seconds() - t0;
    }
    if (opt.free_box.enabled) smooth_run_free_box(run, dry, F, dry_pairs, sp, opt, solver);
}
}  // namespace

FiberPairs smooth_dry_pairs(const Network& net, const WettingRule& rule) {
    FiberPairs out = dry_pairs(net, rule);
    for (const Crossing& c : net.crossings)
        if (c.crosslink) out.insert({std::min(c.f1, c.f2), std::max(c.f1, c.f2)});
    return out;
}

WetModel parse_wet_model(const std::string& s) {
    if (s == "events") return WetModel::Events;
    if (s == "smooth") return WetModel::Smooth;
    throw InputError("wet model '" + s + "' is not one of: events, smooth");
}

std::string to_string(WetModel m) { return m == WetModel::Smooth ? "smooth" : "events"; }

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
    // What the CLI refuses up front, refused here too: a library caller got a crash (a trimmed model) or a
    // meaningless "converged" (a free box without a periodic box).
    if (m.chains.size() != net.fibers.size() || m.crossing_node.size() != net.crossings.size())
        throw InputError("run_wet: the model (" + std::to_string(m.chains.size()) + " fibers, " +
                         std::to_string(m.crossing_node.size()) + " crossings) was not discretized from this network (" +
                         std::to_string(net.fibers.size()) + " fibers, " + std::to_string(net.crossings.size()) + ")");
    for (size_t k = 0; k < net.crossings.size(); ++k)  // same counts, other crosslinks (another pl): still another network
        if ((m.crossing_node[k] >= 0) != net.crossings[k].crosslink)
            throw InputError("run_wet: crossing " + std::to_string(k) + " is " +
                             (net.crossings[k].crosslink ? "a crosslink" : "free") + " in the network but not in the model: "
                             "the model was not discretized from this network");
    for (size_t f = 0; f < m.chains.size(); ++f) {
        const FiberChain& ch = m.chains[f];
        const double len = net.fibers[f].length * m.fiber_length;
        if (ch.s.size() < 2 || ch.s.front() > 1e-9 * len || ch.s.back() < len * (1 - 1e-9))
            throw InputError("run_wet: fiber " + std::to_string(f) +
                             " is not whole in the model (end arms trimmed or fiber dropped, e.g. by trim_ends): "
                             "capillary bridges sit on the end arms");
    }
    if (opt.free_box.enabled && !m.box.periodic)
        throw InputError("run_wet: the free box needs a periodic network (an open network has no box stress)");
    if (opt.wet_start.size() && opt.model != WetModel::Smooth)
        throw InputError("run_wet: a start state applies to the smooth model only (the event model's state includes its "
                         "bridge set)");
    WetRun run;
    NetworkEnergy dry(m);
    if (opt.wet_start.size() && opt.wet_start.size() != dry.num_dofs())
        throw InputError("run_wet: the start state has " + std::to_string(opt.wet_start.size()) +
                         " coordinates, the model " + std::to_string(dry.num_dofs()));
    const Eigen::Matrix2d B = F * m.box.B0();
    auto solver = make_solver(opt.solver, opt.solver_options);
    const WetParams none;  // beta = 0: the dry energy
    double t0 = wall_seconds();
    if (dry_start) {
        run.dry = *dry_start;
    } else {
        run.dry.q = dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F);
        WetEnergy D(dry, F, {}, none);
        run.dry_solve = solver->minimize(D, run.dry.q);
        run.dry.converged = run.dry_solve.converged();
        run.dry.energy = D.split(run.dry.q);
        run.seconds_dry = wall_seconds() - t0;
        t0 = wall_seconds();
        run.dry.pores = pores(m, dry.positions(run.dry.q, F), B, wall_width(opt, m));
        run.seconds_pores += wall_seconds() - t0;
        if (opt.moduli && run.dry.converged) {
            t0 = wall_seconds();
            shear_moduli(run.dry, dry, F, {}, none, *solver, opt.modulus_strain);
            run.seconds_moduli += wall_seconds() - t0;
        }
    }
    if (opt.model == WetModel::Smooth) {
        run_wet_smooth(run, net, dry, F, opt, *solver);
        return run;
    }
    // Wet: bridges at the dry equilibrium's crossings (the network's crossings, which the dry relaxation moved by
    // little), made consistent with the geometry before the first solve.
    run.initial_bridges = wet_crossings(net, m, dry.positions(run.dry.q, F), B, opt.rule);
    std::vector<Bridge> bridges = run.initial_bridges;
    ActiveSetOptions options = opt.active_set;
    if (opt.rule.which != WetWhich::All) options.dry_pairs = std::make_shared<const FiberPairs>(dry_pairs(net, opt.rule));
    ActiveSetOptions first = options;
    first.form_new = false;
    update_bridges(dry, run.dry.q, F, bridges, first);
    run.wet.q = run.dry.q;
    // Rounds are capped in Newton iterations (active_set.hpp); first-order solvers' iterations are cheap and many.
    // Local rounds were designed and measured with Newton (docs/wet.md, "Local rounds"): other solvers solve globally.
    ActiveSetOptions as = options;
    if (!solver->capabilities().newton_steps) as.round_iterations = 0, as.local_fraction = 0;
    run.active = relax_wet(dry, F, opt.params, bridges, *solver, run.wet.q, as);
    run.seconds_wet_solve = run.active.seconds_solve;
    run.seconds_events = run.active.seconds_events;
    run.wet.converged = run.active.last.converged();
    run.wet.energy = WetEnergy(dry, F, run.active.bridges, opt.params).split(run.wet.q);
    t0 = wall_seconds();
    const Eigen::VectorXd x = dry.positions(run.wet.q, F);
    run.wet.pores = pores(m, x, B, wall_width(opt, m));
    run.bundles = bundles(m, x, B, run.active.bridges, opt.bundle_angle_deg);
    run.seconds_pores += wall_seconds() - t0;
    if (opt.moduli && run.wet.converged && run.active.stable) {  // the moduli of a consistent bridge set only
        t0 = wall_seconds();
        shear_moduli(run.wet, dry, F, run.active.bridges, opt.params, *solver, opt.modulus_strain);
        run.seconds_moduli += wall_seconds() - t0;
    }
    if (opt.free_box.enabled) {
        if (run.wet.converged && run.active.stable) {
            run.free_box = free_box(dry, F, opt.params, run.wet.q, run.active.bridges, *solver, as,
                                    opt.free_box);
            const Eigen::Matrix2d Bf = run.free_box.F * m.box.B0();
            const Eigen::VectorXd xf = dry.positions(run.free_box.q, run.free_box.F);
            run.free_box.pores = pores(m, xf, Bf, wall_width(opt, m));
            run.free_box.bundles = bundles(m, xf, Bf, run.free_box.bridges, opt.bundle_angle_deg);
            if (opt.moduli) {
                t0 = wall_seconds();
                linear_shear_modulus(dry, run.free_box.F, run.free_box.q, run.free_box.bridges, opt.params,
                                     run.free_box.shear_modulus, run.free_box.shear_modulus_error);
                run.seconds_moduli += wall_seconds() - t0;
            }
        } else {
            run.free_box.F0 = run.free_box.F = F;
            run.free_box.message = "not attempted: the wet relaxation at the fixed box is not a stable equilibrium";
        }
    }
    return run;
}

}  // namespace fibernet
