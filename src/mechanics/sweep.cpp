#include "fibernet/mechanics/sweep.hpp"

#include <algorithm>

#include <chrono>
#include <cmath>

#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/mechanics/stress.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

void SweepParams::check(const std::string& where) const {
    check_value(t_max != 0, t_max, where, "gamma_max", "must be non-zero");
    check_value(std::abs(t_max) < 10, t_max, where, "gamma_max", "must be below 10 in magnitude");
    // F(t) is upper triangular and linear in t, with F(0) = I: the box keeps its orientation on [0, t_max] iff both
    // diagonal entries are positive at t_max (det F alone is (1 + t)^2 > 0 on the isotropic path through t = -1).
    const Eigen::Matrix2d Fm = deformation(kind, t_max);
    check_value(Fm(0, 0) > 0 && Fm(1, 1) > 0, t_max, where, "gamma_max",
                "flips or collapses the box on the " + to_string(kind) + " path (need > -1)");
    check_value(step > 0, step, where, "step", "must be > 0");
    check_value(min_step > 0 && min_step <= step, min_step, where, "min_step", "must be > 0 and <= step");
    check_value(max_step >= step, max_step, where, "max_step", "must be >= step");
    check_value(grow >= 1, grow, where, "grow", "must be >= 1");
    check_value(max_iterations >= 1, max_iterations, where, "max_iterations", "must be >= 1");
}

namespace {
struct Response {
    SweepRow row;
    Eigen::VectorXd dq_dt;
    bool ok = false;
    std::string message;
};

// Stress, differential modulus and tangent at an equilibrium q of F(t).
// tol: the solver's; a state it accepted is an equilibrium for linear_moduli too.
Response respond(const NetworkEnergy& e, const Eigen::VectorXd& q, double t, StrainKind kind, double tol) {
    Response r;
    const Eigen::Matrix2d F = deformation(kind, t);
    const double A0 = e.model().box.reference_area();
    StrainMode mode{"path", strain_direction(kind), 1.0 / A0};
    ModuliInfo info;
    ModuliOptions mo;
    mo.equilibrium_tol = std::max(mo.equilibrium_tol, tol);
    mo.state_error = false;  // the rows report no error; the step's own check would double the modulus cost
    const auto mods = linear_moduli(e, q, F, {mode}, mo, &info);
    const Modulus& M = mods.front();
    r.ok = M.ok;
    r.message = info.message;
    if (!r.ok) return r;
    EnergyEval ev;
    e.evaluate(q, F, mode.dF, kStrain, ev);
    const Stress st = stress(e, q, F);
    r.row.t = t;
    r.row.sigma = st.sigma;
    r.row.stress_path = ev.dE_dt / A0;
    r.row.K = M.value;
    r.row.K_affine = M.E_tt / A0;
    r.row.energy = ev.energy, r.row.stretch = ev.stretch, r.row.bend = ev.bend;
    r.dq_dt = -M.response;
    return r;
}
}  // namespace

SweepOutcome run_sweep(const NetworkEnergy& e, const SweepParams& p, Solver& solver, const SweepCallbacks& cb,
                       const SweepState* resume, Solver* snap) {
    p.check("sweep");
    // The tolerance a state of this sweep was accepted at (the corrector may be the snap solver).
    const double accepted_tol = std::max(solver.options().tol, snap ? snap->options().tol : 0.0);
    SweepOutcome out;
    const double dir = p.t_max > 0 ? 1 : -1;
    SweepState s;
    Response resp;
    if (resume) {
        s = *resume;
        resp = respond(e, s.q, s.t, p.kind, accepted_tol);
        if (!resp.ok) {
            out.message = "linear response failed at the resumed state: " + resp.message;
            return out;
        }
    } else {
        const auto t0 = std::chrono::steady_clock::now();
        Equilibrium eq = relax(e, Eigen::Matrix2d::Identity(), solver);
        if (!eq.converged()) {
            out.message = "the unstrained state did not converge (" + to_string(eq.result.status) + ")";
            return out;
        }
        s.q = eq.q, s.t = 0, s.step = 0, s.next_step = p.step;
        resp = respond(e, s.q, 0, p.kind, accepted_tol);
        if (!resp.ok) {
            out.message = "linear response failed at t = 0: " + resp.message;
            return out;
        }
        resp.row.iterations = eq.result.iterations;
        resp.row.factorizations = eq.result.factorizations;
        resp.row.grad_max = eq.result.grad_max;
        resp.row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (cb.on_step) cb.on_step(resp.row, s);
    }
    while (dir * (p.t_max - s.t) > 1e-14) {
        if (cb.stop && cb.stop->load()) {
            out.interrupted = true;
            out.message = "interrupted after step " + std::to_string(s.step);
            return out;
        }
        const auto t0 = std::chrono::steady_clock::now();
        double h = std::min(s.next_step, dir * (p.t_max - s.t));
        int retries = 0, iters = 0, facts = 0;
        Equilibrium eq;
        std::string why;
        while (true) {
            const double t_new = (dir * (p.t_max - s.t) - h <= 1e-14) ? p.t_max : s.t + dir * h;
            const Eigen::Matrix2d F = deformation(p.kind, t_new);
            const Eigen::VectorXd q_pred = s.q + (t_new - s.t) * resp.dq_dt;
            eq = relax(e, F, solver, &q_pred, F);
            iters += eq.result.iterations, facts += eq.result.factorizations;
            if (snap && eq.result.status == SolveStatus::IterationLimit && 0.5 * h < p.min_step) {
                eq = relax(e, F, *snap, &q_pred, F);  // last chance: a snap-through needs a long descent
                iters += eq.result.iterations, facts += eq.result.factorizations;
            }
            // A converged corrector is accepted; one that needed many iterations is first retried with a smaller
            // step (the tangent predicts better), but at the smallest step it is a snap-through: the branch ended
            // and the solver found the next stable state, which is what a quasistatic experiment does too.
            const bool slow = eq.result.iterations > p.max_iterations && 0.5 * h >= p.min_step;
            if (eq.converged() && !slow) {
                Response r = respond(e, eq.q, t_new, p.kind, std::max(accepted_tol, eq.result.grad_max));
                if (r.ok) {
                    resp = std::move(r);
                    s.t = t_new;
                    break;
                }
                why = "linear response failed: " + r.message;
            } else {
                why = "corrector " + to_string(eq.result.status) + (slow ? " after many iterations" : "") + ": " +
                      eq.result.message;
            }
            h *= 0.5;
            ++retries;
            if (h < p.min_step) {
                out.message = "step fell below min_step at t = " + show(s.t) + " (last try: " + why + ")";
                return out;
            }
        }
        ++s.step;
        s.q = eq.q;
        s.next_step = eq.result.iterations <= p.good_iterations && retries == 0 ? std::min(p.max_step, h * p.grow) : h;
        resp.row.step = s.step;
        resp.row.iterations = iters, resp.row.factorizations = facts, resp.row.retries = retries;
        resp.row.grad_max = eq.result.grad_max;
        resp.row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (cb.on_step) cb.on_step(resp.row, s);
    }
    out.completed = true;
    return out;
}

}  // namespace fibernet
