#include "fibernet/wet/wet_run.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "fibernet/util/error.hpp"
#include "fibernet/wet/wet_moduli.hpp"

namespace fibernet {

namespace {
double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
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
    SmoothWetEnergy W(dry, F, sp, dry_pairs, s.q);  // its pattern fresh at s.q: every non-zero pair's block
    const Modulus M = wet_linear_moduli(W, s.q, {shear_mode(F, A)}).front();
    s.shear_modulus = M.ok ? M.value : std::numeric_limits<double>::quiet_NaN();
    s.shear_modulus_error = M.ok ? M.error : std::numeric_limits<double>::quiet_NaN();
}

// The dry crossings of the smooth model: those the rule leaves dry and every crosslink (a crosslinked pair gets no
// capillary term at its crosslink, issue 22).
FiberPairs smooth_dry_pairs(const Network& net, const WettingRule& rule) {
    FiberPairs out = dry_pairs(net, rule);
    for (const Crossing& c : net.crossings)
        if (c.crosslink) out.insert({std::min(c.f1, c.f2), std::max(c.f1, c.f2)});
    return out;
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
    run.wet.q = run.dry.q;
    SmoothWetEnergy W(dry, F, sp, dry_pairs, run.wet.q);
    run.initial_bridges = W.bridges(run.wet.q);
    run.smooth = relax_smooth_wet(W, solver, run.wet.q, opt.smooth_relax);
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
    double t0 = now();
    const Eigen::VectorXd x = dry.positions(run.wet.q, F);
    run.wet.pores = pores(m, x, B, wall_width(opt, m));
    run.bundles = bundles(m, x, B, run.active.bridges, opt.bundle_angle_deg);
    run.seconds_pores += now() - t0;
    if (opt.moduli && run.wet.converged) {
        t0 = now();
        smooth_shear_moduli(run.wet, dry, F, dry_pairs, sp, opt.smooth_relax, opt.modulus_strain, solver);
        run.seconds_moduli += now() - t0;
    }
    if (opt.free_box.enabled) {
        run.free_box.F0 = run.free_box.F = F;
        run.free_box.message = "not attempted: the free box is not yet available on the smooth model";
    }
}
}  // namespace

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
        run.dry.pores = pores(m, dry.positions(run.dry.q, F), B, wall_width(opt, m));
        run.seconds_pores += now() - t0;
        if (opt.moduli && run.dry.converged) {
            t0 = now();
            shear_moduli(run.dry, dry, F, {}, none, *solver, opt.modulus_strain);
            run.seconds_moduli += now() - t0;
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
    t0 = now();
    const Eigen::VectorXd x = dry.positions(run.wet.q, F);
    run.wet.pores = pores(m, x, B, wall_width(opt, m));
    run.bundles = bundles(m, x, B, run.active.bridges, opt.bundle_angle_deg);
    run.seconds_pores += now() - t0;
    if (opt.moduli && run.wet.converged && run.active.stable) {  // the moduli of a consistent bridge set only
        t0 = now();
        shear_moduli(run.wet, dry, F, run.active.bridges, opt.params, *solver, opt.modulus_strain);
        run.seconds_moduli += now() - t0;
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
                t0 = now();
                linear_shear_modulus(dry, run.free_box.F, run.free_box.q, run.free_box.bridges, opt.params,
                                     run.free_box.shear_modulus, run.free_box.shear_modulus_error);
                run.seconds_moduli += now() - t0;
            }
        } else {
            run.free_box.F0 = run.free_box.F = F;
            run.free_box.message = "not attempted: the wet relaxation at the fixed box is not a stable equilibrium";
        }
    }
    return run;
}

Stress wet_stress(const NetworkEnergy& dry, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                  const std::vector<Bridge>& bridges, const WetParams& params) {
    Stress s = stress(dry, q, F);
    if (params.beta == 0 || bridges.empty()) return s;
    const Model& m = dry.model();
    const Eigen::Matrix2d B0 = m.box.B0(), B = F * B0;
    const Eigen::VectorXd x = dry.positions(q, F);
    Vector16d g;
    for (const Bridge& b : bridges) {
        const BridgeElement e = resolve(m, b);
        bridge_element_energy(e, element_coordinates(e, x, B), params.beta, params.law, &g, nullptr);
        for (int a = 0; a < 8; ++a) {
            if (e.node[a] < 0) continue;
            // X_a = x_a + F B0 shift_a, with x_a = F x_ref,a for a fixed node: dX_a / dF_ij = e_i r_j.
            Eigen::Vector2d r = B0 * e.shift[a].cast<double>();
            if (dry.dof(e.node[a], 0) < 0) r += m.x.segment<2>(2 * e.node[a]);
            s.P += g.segment<2>(2 * a) * r.transpose();
        }
    }
    if (s.area > 0) s.sigma = s.P * F.transpose() / s.area;
    return s;
}

double free_box_stress_scale(const Model& m, const Eigen::Matrix2d& F0, double beta) {
    double length = 0;
    for (const Segment& sg : m.segments) length += sg.l0;
    const double A = std::abs((F0 * m.box.B0()).determinant());
    return (beta > 0 ? beta : 1.0) * length / A;
}

namespace {
// U of the free box from its unknowns: full (U_xx - 1, U_yy - 1, U_xy), isotropic (s - 1).
Eigen::Matrix2d stretch_of(const Eigen::VectorXd& u) {
    Eigen::Matrix2d U;
    if (u.size() == 1) return (1 + u[0]) * Eigen::Matrix2d::Identity();
    U << 1 + u[0], u[2], u[2], 1 + u[1];
    return U;
}

Eigen::Vector3d components(const Stress& s) {
    return {s.sigma(0, 0), s.sigma(1, 1), 0.5 * (s.sigma(0, 1) + s.sigma(1, 0))};
}

// A point of the search: an equilibrium of its bridge set at F = U(u) F0, with its controlled residual r (stress
// components in units of sigma_c: full xx, yy, xy; isotropic the mean normal stress) and, once computed, its relaxed
// response (bridge set frozen): J = dr/du, K = d2E*/du2 (symmetrized), dQ = dq/du.
struct BoxState {
    Eigen::VectorXd u, q, r;
    Eigen::Matrix2d F;
    std::vector<Bridge> bridges;
    Stress stress;
    double E = 0;
    WetEvents events;  // of the relaxation that produced it
    Eigen::MatrixXd J, K, dQ;
    bool has_response = false;
    double residual() const { return r.cwiseAbs().maxCoeff(); }
};

class BoxSearch {
public:
    BoxSearch(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const WetParams& params, Solver& solver,
              const ActiveSetOptions& active_set, const FreeBoxOptions& opt, FreeBoxResult& R)
        : dry_(dry), F0_(F0), params_(params), solver_(solver), as_(active_set), opt_(opt), R_(R),
          n_(opt.isotropic ? 1 : 3), t0_(now()) {
        sc_ = free_box_stress_scale(dry.model(), F0, params.beta);
        // dE*/du_j = P : (dU_j F0) = A sigma : (dU_j U^-1) at an equilibrium (E* the relaxed energy).
        dU_.assign(n_, Eigen::Matrix2d::Zero());
        if (n_ == 1) dU_[0].setIdentity();
        else dU_[0](0, 0) = 1, dU_[1](1, 1) = 1, dU_[2](0, 1) = dU_[2](1, 0) = 1;
    }
    int n() const { return n_; }
    double sc() const { return sc_; }
    double elapsed() const { return now() - t0_; }

    BoxState make(const Eigen::VectorXd& u, const Eigen::VectorXd& q, std::vector<Bridge> bridges) const {
        BoxState S;
        S.u = u, S.F = stretch_of(u) * F0_, S.q = q, S.bridges = std::move(bridges);
        S.stress = wet_stress(dry_, S.q, S.F, S.bridges, params_);
        S.r = controlled(S.stress);
        S.E = WetEnergy(dry_, S.F, S.bridges, params_).value(S.q);
        return S;
    }

    // Central differences of relaxations at u +- h e_j with the bridge set frozen (2 n short solves).
    bool response(BoxState& S, int iter) {
        if (S.has_response) return true;
        S.J.resize(n_, n_), S.K.resize(n_, n_), S.dQ.resize(S.q.size(), n_);
        for (int j = 0; j < n_; ++j) {
            Eigen::VectorXd rr[2], gg[2], qq[2];
            for (int k = 0; k < 2; ++k) {
                Eigen::VectorXd uj = S.u;
                uj[j] += (k == 0 ? 1 : -1) * opt_.fd_strain;
                const Eigen::Matrix2d Fj = stretch_of(uj) * F0_;
                qq[k] = dry_.affine_map(S.q, S.F, Fj);
                WetEnergy W(dry_, Fj, S.bridges, params_);
                SolveResult sr = solver_.minimize(W, qq[k]);
                ++R_.stiffness_solves, R_.solver_iterations += sr.iterations;
                SolverOptions& so = solver_.options();
                if (sr.status == SolveStatus::LineSearchFailed && !so.ldl && as_.newton_ldl && params_.beta > 0) {
                    // Retried from the same start with Newton's LDL^T rung (as the relaxations use): on one free-box
                    // seed of docs/wet.md the shifted ladder's line search failed here and the retry converged.
                    struct Restore {
                        SolverOptions& so;
                        ~Restore() { so.ldl = false; }
                    } restore{so};
                    qq[k] = dry_.affine_map(S.q, S.F, Fj);
                    so.ldl = true;
                    sr = solver_.minimize(W, qq[k]);
                    ++R_.stiffness_retries, R_.solver_iterations += sr.iterations;
                }
                if (!sr.converged()) {
                    R_.message = "iteration " + std::to_string(iter) + ": a stiffness relaxation failed (" +
                                 to_string(sr.status) + ")";
                    return false;
                }
                const Stress sj = wet_stress(dry_, qq[k], Fj, S.bridges, params_);
                rr[k] = controlled(sj);
                gg[k].resize(n_);
                for (int i = 0; i < n_; ++i) gg[k][i] = sj.P.cwiseProduct(dU_[i] * F0_).sum();
            }
            const double h2 = 2 * opt_.fd_strain;
            S.J.col(j) = (rr[0] - rr[1]) / h2, S.K.col(j) = (gg[0] - gg[1]) / h2, S.dQ.col(j) = (qq[0] - qq[1]) / h2;
        }
        S.K = 0.5 * (S.K + S.K.transpose()).eval();
        S.has_response = true;
        return true;
    }

    // Relaxation with the active set at u, from S moved by its linear relaxed response (if known) or mapped
    // affinely, whichever start has the lower energy: the affine map of a bending-dominated network stretches its
    // fibers, so its energy rises with the affine, not the relaxed, stiffness, and a relaxation from high up may
    // land in another branch of the path-dependent wet landscape. False (why says so) if not stable.
    bool trial(const BoxState& S, const Eigen::VectorXd& u, BoxState& out, FreeBoxIteration& it, std::string& why) {
        const Eigen::Matrix2d Ft = stretch_of(u) * F0_;
        Eigen::VectorXd q = dry_.affine_map(S.q, S.F, Ft);
        if (S.has_response) {
            const Eigen::VectorXd ql = S.q + S.dQ * (u - S.u);
            WetEnergy W(dry_, Ft, S.bridges, params_);
            const double El = W.value(ql);
            if (std::isfinite(El) && El < W.value(q)) q = ql;
        }
        const ActiveSetResult a = relax_wet(dry_, Ft, params_, S.bridges, solver_, q, as_);
        ++R_.relaxations, ++it.trials;
        R_.solver_iterations += a.solver_iterations;
        it.relax_rounds += a.rounds, it.solver_iterations += a.solver_iterations;
        if (!(a.stable && a.last.converged())) {
            why = a.message;
            if (opt_.progress) {
                std::fprintf(stderr, "free box trial %2d: F = [%.6f %.6f; %.6f %.6f] not stable (%s)\n", it.iteration,
                             Ft(0, 0), Ft(0, 1), Ft(1, 0), Ft(1, 1), a.message.c_str());
            }
            return false;
        }
        out = make(u, q, a.bridges);
        out.events = a.events;
        return true;
    }

    FreeBoxIteration record(const BoxState& S, int iter, double step, FreeBoxIteration it) const {
        it.iteration = iter, it.F = S.F, it.sigma = components(S.stress) / sc_, it.residual = S.residual();
        it.step = step, it.energy = S.E, it.seconds = elapsed();
        return it;
    }

    void progress(const FreeBoxIteration& it, const char* what, const std::string& extra = "") const {
        if (!opt_.progress) return;
        const Eigen::Matrix2d& F = it.F;
        std::fprintf(stderr,
                     "free box %s %2d: F = [%.6f %.6f; %.6f %.6f], sigma/sigma_c = (%.3e, %.3e, %.3e), residual%s "
                     "%.3e, E %.10g, step %.4g, %d trial(s), %d round(s), %d solver iterations, %.1f s%s\n",
                     what, it.iteration, F(0, 0), F(0, 1), F(1, 0), F(1, 1), it.sigma[0], it.sigma[1], it.sigma[2],
                     n_ == 1 ? " (mean normal)" : "", it.residual, it.energy, it.step, it.trials, it.relax_rounds,
                     it.solver_iterations, it.seconds, extra.c_str());
    }

    void add_events(const WetEvents& e) {
        R_.events.moves += e.moves, R_.events.ruptures += e.ruptures, R_.events.formed += e.formed;
        R_.events.merged += e.merged, R_.events.locked += e.locked;
        R_.events.capped = e.capped;  // the last relaxation's state count
    }

private:
    Eigen::VectorXd controlled(const Stress& s) const {
        const Eigen::Vector3d c = components(s) / sc_;
        if (n_ == 1) return Eigen::VectorXd::Constant(1, 0.5 * (c[0] + c[1]));
        return c;
    }

    const NetworkEnergy& dry_;
    Eigen::Matrix2d F0_;
    const WetParams& params_;
    Solver& solver_;
    const ActiveSetOptions& as_;
    const FreeBoxOptions& opt_;
    FreeBoxResult& R_;
    int n_;
    double t0_, sc_ = 1;
    std::vector<Eigen::Matrix2d> dU_;
};

// The head of an outer iteration of both searches: 1 = the stress is below tolerance, -1 = stop (the iteration
// budget is spent, or the relaxed response failed; R.message says which), 0 = go on with A's response filled.
int iteration_head(BoxSearch& S, BoxState& A, const FreeBoxOptions& opt, FreeBoxResult& R, int iter) {
    if (A.residual() <= opt.tol) {
        R.message = "stress below tolerance after " + std::to_string(iter - 1) + " iteration(s)";
        return 1;
    }
    if (iter > opt.max_iter) {
        R.message = "stress not below tolerance after " + std::to_string(opt.max_iter) + " iterations";
        return -1;
    }
    return S.response(A, iter) ? 0 : -1;
}

// Full box: damped Newton on r(u) = 0 with the finite-difference J, halving until |r| decreases.
bool newton_box(BoxSearch& S, BoxState& A, const FreeBoxOptions& opt, FreeBoxResult& R) {
    const int n = S.n();
    for (int iter = 1;; ++iter) {
        if (const int h = iteration_head(S, A, opt, R, iter); h != 0) return h > 0;
        // du = -J^+ r; directions without stiffness (floppy: singular values below 1e-7 of the largest) get no step.
        const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A.J, Eigen::ComputeFullU | Eigen::ComputeFullV);
        const Eigen::VectorXd sv = svd.singularValues();
        if (!(sv[0] > 0) || !std::isfinite(sv[0])) {
            R.message = "iteration " + std::to_string(iter) + ": the relaxed stiffness is zero or not finite";
            return false;
        }
        Eigen::VectorXd du = Eigen::VectorXd::Zero(n);
        const Eigen::VectorXd ur = svd.matrixU().transpose() * A.r;
        for (int k = 0; k < n; ++k)
            if (sv[k] > 1e-7 * sv[0]) du -= svd.matrixV().col(k) * (ur[k] / sv[k]);
        const double big = du.cwiseAbs().maxCoeff();
        if (big > opt.max_step) du *= opt.max_step / big;
        const double norm0 = A.r.norm();
        double t = 1;
        bool accepted = false;
        FreeBoxIteration it;
        it.iteration = iter;
        for (int h = 0; h <= opt.max_halvings; ++h, t *= 0.5) {
            BoxState T;
            std::string why;
            if (S.trial(A, A.u + t * du, T, it, why)) {
                if (T.r.norm() <= (1 - 1e-4 * t) * norm0 || T.residual() <= opt.tol) {
                    A = std::move(T);
                    S.add_events(A.events);
                    accepted = true;
                    break;
                }
                S.progress(S.record(T, iter, t, it), "reject");
            }
        }
        R.iterations = iter;
        if (!accepted) {
            R.message = "iteration " + std::to_string(iter) + ": no step in " + std::to_string(opt.max_halvings + 1) +
                        " halvings reduced the stress (or the trial relaxations were not stable)";
            return false;
        }
        R.history.push_back(S.record(A, iter, t, it));
        S.progress(R.history.back(), "iter");
    }
}

// Isotropic box: the path from s = 1 in the direction the mean stress pulls (tension: shrink), each point relaxed
// from the last one with the same sign of the stress; Newton steps (finite-difference stiffness) capped at max_step
// until the stress changes sign, then safeguarded Newton inside the bracket (regula falsi, Illinois variant, where the
// Newton step would leave it), each trial again relaxed from the bracket's path end. A bracket narrower than snap_width without a point below tolerance is a snap: the stress jumps
// across zero on this path (bridges forming or rupturing) and there is no zero-stress box on it.
bool bracket_box(BoxSearch& S, BoxState& A, const FreeBoxOptions& opt, FreeBoxResult& R) {
    BoxState B;
    bool bracket = false;
    double fa = A.r[0], fb = 0;  // the bracket ends' residuals as regula falsi uses them (Illinois-halved)
    int side = 0;
    for (int iter = 1;; ++iter) {
        if (const int h = iteration_head(S, A, opt, R, iter); h != 0) return h > 0;
        const double ua = A.u[0], ra = A.r[0];
        double ut;
        if (!bracket) {
            const double dir = ra > 0 ? -1 : 1;  // tension: shrink
            const double newton = -ra / A.J(0, 0);
            const double step = std::isfinite(newton) && newton * dir > 0 ? std::min(std::abs(newton), opt.max_step)
                                                                           : opt.max_step;
            ut = ua + dir * step;
        } else {
            // Safeguarded: the Newton step from the path end if it stays inside the bracket, else regula falsi.
            const double ub = B.u[0];
            const double lo = std::min(ua, ub), hi = std::max(ua, ub), w = hi - lo;
            ut = ua - ra / A.J(0, 0);
            if (!(std::isfinite(ut) && ut > lo + 0.01 * w && ut < hi - 0.01 * w)) {
                ut = (ua * fb - ub * fa) / (fb - fa);
                ut = std::clamp(std::isfinite(ut) ? ut : 0.5 * (lo + hi), lo + 0.01 * w, hi - 0.01 * w);
            }
        }
        BoxState T;
        FreeBoxIteration it;
        it.iteration = iter;
        bool ok = false;
        std::string why;
        for (int h = 0; h <= opt.max_halvings && !ok; ++h) {
            ok = S.trial(A, Eigen::VectorXd::Constant(1, ut), T, it, why);
            if (!ok) ut = ua + 0.5 * (ut - ua);
        }
        R.iterations = iter;
        if (!ok) {
            R.message = "iteration " + std::to_string(iter) + ": the relaxations at " +
                        std::to_string(opt.max_halvings + 1) + " trial boxes were not stable (" + why + ")";
            return false;
        }
        const double rt = T.r[0];
        const bool to_a = T.residual() <= opt.tol || (rt > 0) == (ra > 0);
        std::ostringstream extra;
        if (to_a) {
            if (bracket && side == +1) fb *= 0.5;  // Illinois: the same end kept twice
            side = +1;
            A = std::move(T), fa = rt;
            S.add_events(A.events);
        } else {
            if (bracket && side == -1) fa *= 0.5;
            side = -1;
            B = std::move(T), fb = rt, bracket = R.bracketed = true;
        }
        const BoxState& now_pt = to_a ? A : B;
        if (bracket) extra << ", bracket s in [" << std::min(A.u[0], B.u[0]) + 1 << ", " << std::max(A.u[0], B.u[0]) + 1 << "]";
        R.history.push_back(S.record(now_pt, iter, ut - ua, it));
        S.progress(R.history.back(), to_a ? "iter" : "over", extra.str());
        if (bracket && A.residual() > opt.tol && std::abs(B.u[0] - A.u[0]) <= opt.snap_width) {
            R.snap = true;
            R.snap_s = {1 + A.u[0], 1 + B.u[0]};
            R.snap_residual = {A.r[0], B.r[0]};
            std::ostringstream m;
            m << "snap: the mean stress jumps from " << A.r[0] << " to " << B.r[0] << " sigma_c between s = "
              << 1 + A.u[0] << " and " << 1 + B.u[0] << " (bridge events); no zero-stress box on this path";
            R.message = m.str();
            return false;
        }
        if (1 + A.u[0] < 0.5 || 1 + A.u[0] > 2) {
            R.message = std::string("the box ") + (A.u[0] < 0 ? "shrank below half" : "grew beyond twice") +
                        " its side without reaching zero stress";
            return false;
        }
    }
}
}  // namespace

FreeBoxResult free_box(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const WetParams& params,
                       const Eigen::VectorXd& q0, const std::vector<Bridge>& bridges0, Solver& solver,
                       const ActiveSetOptions& active_set, const FreeBoxOptions& opt) {
    FreeBoxResult R;
    R.attempted = true;
    R.F0 = R.F = F0;
    BoxSearch S(dry, F0, params, solver, active_set, opt, R);
    R.stress_scale = S.sc();
    if (R.stress_scale == 0) {
        // No fiber length (an empty network): no stress at any box, so the given box is the free one, exactly.
        // (The search would divide by the zero stress scale and walk the box out to twice its side.)
        R.converged = true;
        R.message = "no fibers: the network carries no stress at any box, so the free box is the given one";
        R.q = q0, R.bridges = bridges0;
        R.stress0 = R.stress = wet_stress(dry, q0, F0, bridges0, params);
        R.energy = WetEnergy(dry, F0, R.bridges, params).split(R.q);
        R.seconds = S.elapsed();
        return R;
    }
    BoxState A = S.make(Eigen::VectorXd::Zero(S.n()), q0, bridges0);
    R.stress0 = A.stress;
    R.residual0 = A.residual();
    R.history.push_back(S.record(A, 0, 0, {}));
    S.progress(R.history.back(), "start");
    R.converged = opt.isotropic ? bracket_box(S, A, opt, R) : newton_box(S, A, opt, R);
    // Stability of the box found: the relaxed stiffness there, per unit box area.
    if (R.converged && opt.stability) {
        const std::string msg = R.message;
        A.has_response = false;
        if (S.response(A, R.iterations + 1)) {
            const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A.K);
            R.stiffness_eigenvalues = es.eigenvalues() / std::abs((A.F * dry.model().box.B0()).determinant());
            R.message = msg;
        } else {
            R.message = msg + "; stability not checked (" + R.message + ")";
        }
    }
    R.F = A.F;
    R.q = A.q;
    R.bridges = A.bridges;
    R.stress = A.stress;
    R.residual = A.residual();
    const double ratio = A.F.determinant() / F0.determinant();
    R.areal_shrinkage = 1 - ratio;
    R.s = opt.isotropic ? 1 + A.u[0] : std::sqrt(ratio);
    R.energy = WetEnergy(dry, A.F, R.bridges, params).split(R.q);
    R.seconds = S.elapsed();
    return R;
}

}  // namespace fibernet
