#include "fibernet/wet/free_box.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "box_search.hpp"
#include "fibernet/util/stopwatch.hpp"
#include "fibernet/wet/wet_energy.hpp"

namespace fibernet {

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

namespace box_search {

Eigen::Matrix2d stretch_of(const Eigen::VectorXd& u) {
    Eigen::Matrix2d U;
    if (u.size() == 1) return (1 + u[0]) * Eigen::Matrix2d::Identity();
    U << 1 + u[0], u[2], u[2], 1 + u[1];
    return U;
}

namespace {
Eigen::Vector3d components(const Stress& s) {
    return {s.sigma(0, 0), s.sigma(1, 1), 0.5 * (s.sigma(0, 1) + s.sigma(1, 0))};
}
}  // namespace

BoxSearch::BoxSearch(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, double beta, const FreeBoxOptions& opt,
                     FreeBoxResult& R)
    : dry_(dry), F0_(F0), opt_(opt), R_(R), n_(opt.isotropic ? 1 : 3), t0_(wall_seconds()) {
    sc_ = free_box_stress_scale(dry.model(), F0, beta);
    // dE*/du_j = P : (dU_j F0) = A sigma : (dU_j U^-1) at an equilibrium (E* the relaxed energy).
    dU_.assign(n_, Eigen::Matrix2d::Zero());
    if (n_ == 1) dU_[0].setIdentity();
    else dU_[0](0, 0) = 1, dU_[1](1, 1) = 1, dU_[2](0, 1) = dU_[2](1, 0) = 1;
}

double BoxSearch::elapsed() const { return wall_seconds() - t0_; }

Eigen::VectorXd BoxSearch::controlled(const Stress& s) const {
    const Eigen::Vector3d c = components(s) / sc_;
    if (n_ == 1) return Eigen::VectorXd::Constant(1, 0.5 * (c[0] + c[1]));
    return c;
}

FreeBoxIteration BoxSearch::record(const BoxState& S, int iter, double step, FreeBoxIteration it) const {
    it.iteration = iter, it.F = S.F, it.sigma = components(S.stress) / sc_, it.residual = S.residual();
    it.step = step, it.energy = S.E, it.seconds = elapsed();
    return it;
}

void BoxSearch::progress(const FreeBoxIteration& it, const char* what, const std::string& extra) const {
    if (!opt_.progress) return;
    const Eigen::Matrix2d& F = it.F;
    std::fprintf(stderr,
                 "free box %s %2d: F = [%.6f %.6f; %.6f %.6f], sigma/sigma_c = (%.3e, %.3e, %.3e), residual%s "
                 "%.3e, E %.10g, step %.4g, %d trial(s), %d round(s), %d solver iterations, %.1f s%s\n",
                 what, it.iteration, F(0, 0), F(0, 1), F(1, 0), F(1, 1), it.sigma[0], it.sigma[1], it.sigma[2],
                 n_ == 1 ? " (mean normal)" : "", it.residual, it.energy, it.step, it.trials, it.relax_rounds,
                 it.solver_iterations, it.seconds, extra.c_str());
}

void BoxSearch::report_unstable(const FreeBoxIteration& it, const Eigen::Matrix2d& Ft, const std::string& why) const {
    if (!opt_.progress) return;
    std::fprintf(stderr, "free box trial %2d: F = [%.6f %.6f; %.6f %.6f] not stable (%s)\n", it.iteration, Ft(0, 0),
                 Ft(0, 1), Ft(1, 0), Ft(1, 1), why.c_str());
}

void BoxSearch::add_events(const WetEvents& e) {
    R_.events.moves += e.moves, R_.events.ruptures += e.ruptures, R_.events.formed += e.formed;
    R_.events.merged += e.merged, R_.events.locked += e.locked;
    R_.events.capped = e.capped;  // the last relaxation's state count
}

namespace {
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

void search_free_box(BoxSearch& S, const Eigen::VectorXd& q0, const std::vector<Bridge>& bridges0, FreeBoxResult& R) {
    R.attempted = true;
    R.stress_scale = S.sc();
    if (R.stress_scale == 0) {
        // No fiber length (an empty network): no stress at any box, so the given box is the free one, exactly.
        // (The search would divide by the zero stress scale and walk the box out to twice its side.)
        const BoxState A = S.make(Eigen::VectorXd::Zero(S.n()), q0, bridges0);
        R.converged = true;
        R.message = "no fibers: the network carries no stress at any box, so the free box is the given one";
        R.q = A.q, R.bridges = A.bridges;
        R.stress0 = R.stress = A.stress;
        R.energy = S.split(A);
        R.seconds = S.elapsed();
        return;
    }
    BoxState A = S.make(Eigen::VectorXd::Zero(S.n()), q0, bridges0);
    R.stress0 = A.stress;
    R.residual0 = A.residual();
    R.history.push_back(S.record(A, 0, 0, {}));
    S.progress(R.history.back(), "start");
    R.converged = S.n() == 1 ? bracket_box(S, A, S.options(), R) : newton_box(S, A, S.options(), R);
    // Stability of the box found: the relaxed stiffness there, per unit box area.
    if (R.converged && S.options().stability) {
        const std::string msg = R.message;
        A.has_response = false;
        if (S.response(A, R.iterations + 1)) {
            const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A.K);
            R.stiffness_eigenvalues = es.eigenvalues() / std::abs((A.F * S.dry().model().box.B0()).determinant());
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
    const double ratio = A.F.determinant() / R.F0.determinant();
    R.areal_shrinkage = 1 - ratio;
    R.s = S.n() == 1 ? 1 + A.u[0] : std::sqrt(ratio);
    R.energy = S.split(A);
    R.seconds = S.elapsed();
}

}  // namespace box_search

namespace {
using box_search::BoxState;
using box_search::stretch_of;

// The event model's relaxations: each trial an active-set relaxation (relax_wet) from the accepted state's bridges;
// the relaxed response by central differences of relaxations with the bridge set frozen.
class EventBoxSearch : public box_search::BoxSearch {
public:
    EventBoxSearch(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const WetParams& params, Solver& solver,
                   const ActiveSetOptions& active_set, const FreeBoxOptions& opt, FreeBoxResult& R)
        : BoxSearch(dry, F0, params.beta, opt, R), params_(params), solver_(solver), as_(active_set) {}

    BoxState make(const Eigen::VectorXd& u, const Eigen::VectorXd& q, std::vector<Bridge> bridges) const override {
        BoxState S;
        S.u = u, S.F = stretch_of(u) * F0_, S.q = q, S.bridges = std::move(bridges);
        S.stress = wet_stress(dry_, S.q, S.F, S.bridges, params_);
        S.r = controlled(S.stress);
        S.E = WetEnergy(dry_, S.F, S.bridges, params_).value(S.q);
        return S;
    }

    WetSplit split(const BoxState& S) const override { return WetEnergy(dry_, S.F, S.bridges, params_).split(S.q); }

    // Central differences of relaxations at u +- h e_j with the bridge set frozen (2 n short solves).
    bool response(BoxState& S, int iter) override {
        if (S.has_response) return true;
        S.J.resize(n_, n_), S.K.resize(n_, n_), S.dQ.resize(S.q.size(), n_);
        for (int j = 0; j < n_; ++j) {
            Eigen::VectorXd rr[2], gg[2], qq[2];
            for (int k = 0; k < 2; ++k) {
                Eigen::VectorXd uj = S.u;
                uj[j] += (k == 0 ? 1 : -1) * opt_.fd_strain;
                const Eigen::Matrix2d Fj = stretch_of(uj) * F0_;
                qq[k] = dry_.affine_map(S.q, S.F, Fj);
                if (!frozen_solve(S, Fj, qq[k], iter)) return false;
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

    bool trial(const BoxState& S, const Eigen::VectorXd& u, BoxState& out, FreeBoxIteration& it,
               std::string& why) override {
        const Eigen::Matrix2d Ft = stretch_of(u) * F0_;
        WetEnergy W(dry_, Ft, S.bridges, params_);
        Eigen::VectorXd q = trial_start(S, u, [&](const Eigen::VectorXd& x) { return W.value(x); });
        const ActiveSetResult a = relax_wet(dry_, Ft, params_, S.bridges, solver_, q, as_);
        ++R_.relaxations, ++it.trials;
        R_.solver_iterations += a.solver_iterations;
        it.relax_rounds += a.rounds, it.solver_iterations += a.solver_iterations;
        if (!(a.stable && a.last.converged())) {
            why = a.message;
            report_unstable(it, Ft, why);
            return false;
        }
        out = make(u, q, a.bridges);
        out.events = a.events;
        return true;
    }

private:
    // The relaxation at Fj from q with S's bridge set frozen; false (R.message says why) if it did not converge.
    bool frozen_solve(const BoxState& S, const Eigen::Matrix2d& Fj, Eigen::VectorXd& q, int iter) {
        const Eigen::VectorXd q0 = q;
        WetEnergy W(dry_, Fj, S.bridges, params_);
        SolveResult sr = solver_.minimize(W, q);
        ++R_.stiffness_solves, R_.solver_iterations += sr.iterations;
        SolverOptions& so = solver_.options();
        if (sr.status == SolveStatus::LineSearchFailed && !so.ldl && as_.newton_ldl && params_.beta > 0) {
            // Retried from the same start with Newton's LDL^T rung (as the relaxations use): on one free-box
            // seed of docs/wet.md the shifted ladder's line search failed here and the retry converged.
            struct Restore {
                SolverOptions& so;
                ~Restore() { so.ldl = false; }
            } restore{so};
            q = q0;
            so.ldl = true;
            sr = solver_.minimize(W, q);
            ++R_.stiffness_retries, R_.solver_iterations += sr.iterations;
        }
        if (sr.converged()) return true;
        R_.message = "iteration " + std::to_string(iter) + ": a stiffness relaxation failed (" + to_string(sr.status) +
                     ")";
        return false;
    }

    const WetParams& params_;
    Solver& solver_;
    const ActiveSetOptions& as_;
};
}  // namespace

FreeBoxResult free_box(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const WetParams& params,
                       const Eigen::VectorXd& q0, const std::vector<Bridge>& bridges0, Solver& solver,
                       const ActiveSetOptions& active_set, const FreeBoxOptions& opt) {
    FreeBoxResult R;
    R.F0 = R.F = F0;
    EventBoxSearch S(dry, F0, params, solver, active_set, opt, R);
    box_search::search_free_box(S, q0, bridges0, R);
    return R;
}

}  // namespace fibernet
