#include "fibernet/mechanics/moduli.hpp"

#include <chrono>
#include <cmath>
#include <algorithm>
#include <stdexcept>

#include <Eigen/LU>
#include <limits>

#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/newton.hpp"  // roundoff_floor
#include "fibernet/util/stopwatch.hpp"

namespace fibernet {

namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

StrainMode shear_mode(const Eigen::Matrix2d& F, double area) {
    Eigen::Matrix2d D = Eigen::Matrix2d::Zero();
    D(0, 1) = 1;
    return {"G", D * F, area > 0 ? 1.0 / area : 0.0};
}

StrainMode bulk_mode(const Eigen::Matrix2d& F, double area) {
    return {"K", F, area > 0 ? 0.25 / area : 0.0};
}

StrainMode path_mode(StrainKind k, double area) {
    return {"path", strain_direction(k), area > 0 ? 1.0 / area : 0.0};
}

namespace {
// The relaxed moduli at q (Hessian, strain derivatives, relaxed_moduli), after the equilibrium check; out[m].affine
// is left 0. grad: the gradient at q, for the state check.
// False (every modulus refused, the message says why) if q is not an equilibrium.
bool relaxed_at(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                const std::vector<StrainMode>& modes, const ModuliOptions& opt, ModuliInfo& inf, LinearSolver& llt,
                Eigen::VectorXd& grad, std::vector<Modulus>& out) {
    const auto t_start = Clock::now();
    inf = ModuliInfo{};
    const int n = e.num_dofs();
    out.assign(modes.size(), Modulus{});
    std::vector<Eigen::VectorXd> b(modes.size());

    // Hessian (once) and the strain derivatives along every mode.
    auto t0 = Clock::now();
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    EnergyEval ev;
    double gmax = 0;
    std::vector<double> E_tt_size(modes.size());
    for (size_t m = 0; m < modes.size(); ++m) {
        const bool first = m == 0;
        // Comoving strain derivatives from the elements' own edge vectors (kComoving): E_tt + 2 v.b + v.H v formed
        // from H v loses (|v| |H| |v|) eps to H's stiff entries, 5e-5 of c on the seed scheme at L = 40.
        e.evaluate(q, F, modes[m].dF, kStrain | kComoving | (first ? kHessian | kGradient : 0u), ev, first ? &H : nullptr);
        if (first) grad = ev.gradient;
        if (first && n > 0) gmax = ev.gradient.cwiseAbs().maxCoeff();
        out[m].name = modes[m].name;
        out[m].E_tt = ev.d2E_dt2;
        E_tt_size[m] = ev.d2E_dt2_size;
        b[m] = ev.d2E_dqdt;
    }
    const double seconds_assembly = seconds_since(t0);
    // The formula holds at an equilibrium only (E_xt in range(H)); elsewhere it returns a plausible number with a
    // bound that says nothing (Newton stopped 4 iterations early on problems/default.toml at gamma = 0.01 gave G 1.4 %
    // off with a bound of 3e-10). Accepted: max|g| within equilibrium_tol or the coordinates' round-off floor, where
    // Newton itself stops.
    const double floor = n > 0 ? roundoff_floor(H, q) : 0.0;
    const bool equilibrium = !(gmax > std::max(opt.equilibrium_tol, floor));  // NaN: not an equilibrium either
    if (!equilibrium) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "not an equilibrium: max|g| = %.3g above max(equilibrium_tol %.3g, round-off floor %.3g); linear "
                      "moduli hold at an equilibrium only",
                      gmax, opt.equilibrium_tol, floor);
        for (auto& M : out)
            M.value = M.error = M.affine = std::numeric_limits<double>::quiet_NaN(), M.ok = false;
        inf.message = buf;
        inf.grad_max = gmax, inf.grad_floor = floor;
        inf.seconds_assembly = seconds_assembly;
        inf.seconds_total = seconds_since(t_start);
        return false;
    }
    // The relaxed part, in comoving coordinates (relaxed_moduli).
    const Eigen::VectorXd x = e.positions(q, F);  // absolute positions: the affine velocity is dF F^-1 x
    std::vector<StrainTerms> terms(modes.size());
    for (size_t m = 0; m < modes.size(); ++m)
        terms[m] = {out[m].E_tt, std::move(b[m]), affine_velocity(e, x, modes[m].dF * F.inverse()), true, E_tt_size[m]};
    std::vector<Modulus> relaxed = relaxed_moduli(H, terms, modes, opt, &inf, &llt);
    for (size_t m = 0; m < modes.size(); ++m) relaxed[m].name = out[m].name;
    out = std::move(relaxed);
    inf.seconds_assembly += seconds_assembly;
    inf.grad_max = gmax, inf.grad_floor = floor;
    inf.seconds_total = seconds_since(t_start);
    return true;
}

// Affine predictions: d2E/dt2 along the affine path x(t) = F(t) x_ref with no relaxation: the comoving d2E/dt2
// (kComoving) at the affinely deformed reference q_a. This is not the fixed-q E_tt, which (q fixed = positions fixed)
// holds only the terms of box-crossing segments. At the affine state itself (the straight reference at F = I is one)
// the comoving E_tt of `relaxed` already is the prediction.
void affine_predictions(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                        const std::vector<StrainMode>& modes, std::vector<Modulus>& relaxed) {
    const int n = e.num_dofs();
    const Eigen::VectorXd qa = n > 0 ? affine_start(e, F) : Eigen::VectorXd();
    if (n == 0 || (qa - q).lpNorm<Eigen::Infinity>() <= 1e-10) {  // all fixed, or q is the affine state (to
        for (size_t m = 0; m < modes.size(); ++m) relaxed[m].affine = modes[m].scale * relaxed[m].E_tt;  // round-off)
        return;
    }
    EnergyEval ev;
    for (size_t m = 0; m < modes.size(); ++m) {
        e.evaluate(qa, F, modes[m].dF, kStrain | kComoving, ev);
        relaxed[m].affine = modes[m].scale * ev.d2E_dt2;
    }
}

// The state's share of the error: q is an equilibrium only to the solver's tolerance or its round-off floor, and the
// moduli move with it (a seed-scheme G of -1.8e-8 at one Newton equilibrium, -4.3e-7 at another equally converged
// one). One Newton step from q, q' = q - (H + delta D)^{-1} g with the factorization the moduli used, is as good an
// equilibrium (quadratically closer, or as close at the floor); the moduli there differ from those at q by what the
// state leaves, and that difference joins each error (one more assembly, factorization and CG).
void state_error(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                 const std::vector<StrainMode>& modes, const ModuliOptions& opt, const Eigen::VectorXd& g,
                 LinearSolver& llt, std::vector<Modulus>& out, ModuliInfo& inf) {
    const Eigen::VectorXd step = llt.solve(g);
    ModuliOptions o2 = opt;
    o2.state_error = false;
    ModuliInfo i2;
    Eigen::VectorXd g2;
    std::vector<Modulus> again;
    const bool equilibrium = relaxed_at(e, q - step, F, modes, o2, i2, llt, g2, again);
    inf.state_step = step.lpNorm<Eigen::Infinity>();
    inf.factorizations += i2.factorizations;
    inf.seconds_state = i2.seconds_total;
    if (!equilibrium) return;  // the step left the equilibrium (a saddle nearby): the errors stay the solve's own
    inf.state_checked = true;
    for (size_t m = 0; m < out.size(); ++m) {
        if (!again[m].ok) continue;
        out[m].state_error = std::abs(again[m].value - out[m].value);
        out[m].error = std::max(out[m].error, out[m].state_error);
    }
}
}  // namespace

std::vector<Modulus> linear_moduli(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                                   const std::vector<StrainMode>& modes, const ModuliOptions& opt, ModuliInfo* info,
                                   LinearSolver* shared_llt) {
    const auto t_start = Clock::now();
    ModuliInfo local;
    ModuliInfo& inf = info ? *info : local;
    CholmodLLT own;
    LinearSolver& llt = shared_llt && shared_llt->definite() ? *shared_llt : own;  // a modulus needs the exact inverse
    Eigen::VectorXd g;
    std::vector<Modulus> out;
    if (!relaxed_at(e, q, F, modes, opt, inf, llt, g, out)) return out;
    auto t0 = Clock::now();
    affine_predictions(e, q, F, modes, out);
    inf.seconds_affine = seconds_since(t0);
    bool all_ok = true;
    for (const auto& M : out) all_ok = all_ok && M.ok;
    if (opt.state_error && all_ok && e.num_dofs() > 0) state_error(e, q, F, modes, opt, g, llt, out, inf);
    inf.seconds_total = seconds_since(t_start);
    return out;
}

Eigen::VectorXd affine_velocity(const NetworkEnergy& e, const Eigen::VectorXd& x, const Eigen::Matrix2d& V) {
    Eigen::VectorXd v(e.num_dofs());
    for (int i = 0; i < e.model().num_nodes(); ++i)
        if (e.dof(i, 0) >= 0) v.segment<2>(e.dof(i, 0)) = V * x.segment<2>(2 * i);
    return v;
}

namespace {
// One mode's conjugate gradients (pcg_modes): c = b.u, the last two increments of c, and how it stopped.
struct ModeCG {
    double c = 0, inc = std::numeric_limits<double>::infinity(), prev_inc = std::numeric_limits<double>::infinity();
    double abs_sum = 0;  // sum_i |b_i u_i|: the size of the terms that the dot product c cancels
    int steps = 0;
    bool conv = false, noise = false, broke = false;
};
// Per mode: the scale of the cancellation E_tt - c, b.M b at the start (M = (H + delta D)^-1), and the unknowns.
struct CgScales {
    const std::vector<double>& scale_ref;
    const std::vector<double>& rz0;
    const std::vector<double>& comoving_size;  // sum of |terms| of the comoving E_tt (its round-off's scale)
    int n;
};

// Preconditioned conjugate gradients on H U = B from U = 0 with the preconditioner M = (H + delta D)^{-1}, one
// independent CG per mode, all modes' preconditioner solves in one multi-column CHOLMOD call. The preconditioned
// spectrum is lambda / (lambda + delta): 1 for every stiff mode, so CG only has to resolve the few modes with
// lambda ~ delta (plain refinement u += (H + delta D)^{-1} (b - H u) crawls on those: measured 0.55 per step at
// L = 20). The iterates stay in range(H) when b does, and c_k = b.u_k rises monotonically to b.H^+ b. (Restarting
// from the true residual B - H U was tried: on the seed scheme it chases the round-off of H U and moves c further.)
template <class HView>
std::vector<ModeCG> pcg_modes(const HView& Hs, const LinearSolver& llt, const Eigen::MatrixXd& B, const Eigen::MatrixXd& Z0,
                              Eigen::MatrixXd& U, const CgScales& sc, const ModuliOptions& opt) {
    const int M = static_cast<int>(B.cols());
    std::vector<ModeCG> st(M);
    U.setZero(B.rows(), M);
    Eigen::MatrixXd R = B, Z = Z0, P = Z;  // Z0 = M B, the first preconditioner solve
    std::vector<double> rz(M);
    for (int m = 0; m < M; ++m) {
        rz[m] = sc.rz0[m];
        st[m].conv = rz[m] == 0;  // b = 0
        if (st[m].conv) st[m].inc = st[m].prev_inc = 0;
    }
    auto active = [&](int m) {
        const ModeCG& r = st[m];
        return !r.conv && !r.noise && !r.broke && r.steps < opt.max_refinements;
    };
    for (;;) {
        std::vector<int> act;
        for (int m = 0; m < M; ++m)
            if (active(m)) act.push_back(m);
        if (act.empty()) break;
        for (int m : act) {
            ModeCG& r = st[m];
            const Eigen::VectorXd Ap = Hs * P.col(m);
            const double pAp = P.col(m).dot(Ap);
            if (!(pAp > 0)) {
                // After the first steps p is round-off (its null-space part amplified by M): stop there. At the
                // start it means negative curvature along M b: a saddle, not a minimum.
                if (rz[m] <= 1e-16 * sc.rz0[m]) r.conv = true;  // the residual is round-off: converged
                else if (r.steps >= 1) r.noise = true;           // round-off direction; `error` says how far we got
                else r.broke = true;
                continue;
            }
            const double alpha = rz[m] / pAp;
            U.col(m) += alpha * P.col(m);
            R.col(m) -= alpha * Ap;
            const double c_new = B.col(m).dot(U.col(m));
            r.prev_inc = r.inc;
            r.inc = std::abs(c_new - r.c);
            r.c = c_new;
            ++r.steps;
            r.conv = r.inc <= opt.refine_tol * sc.scale_ref[m];
            r.noise = r.steps >= 3 && r.inc <= 1e-11 * sc.scale_ref[m] && r.inc > 0.5 * r.prev_inc;  // round-off
        }
        act.clear();
        for (int m = 0; m < M; ++m)  // the preconditioner solve for the modes still running only
            if (active(m)) act.push_back(m);
        if (act.empty()) break;
        Eigen::MatrixXd Rn(B.rows(), static_cast<Eigen::Index>(act.size()));
        for (size_t a = 0; a < act.size(); ++a) Rn.col(a) = R.col(act[a]);
        const Eigen::MatrixXd Zn = llt.solve_many(Rn);
        for (size_t a = 0; a < act.size(); ++a) Z.col(act[a]) = Zn.col(a);
        for (int m : act) {
            const double rz_new = R.col(m).dot(Z.col(m));
            if (rz_new <= 1e-28 * sc.rz0[m]) st[m].conv = true;  // residual at round-off
            P.col(m) = Z.col(m) + (rz_new / rz[m]) * P.col(m);
            rz[m] = rz_new;
        }
    }
    for (int m = 0; m < M; ++m) st[m].abs_sum = B.col(m).cwiseProduct(U.col(m)).cwiseAbs().sum();
    return st;
}

// Geometric tail of the CG's increments: what is left <= inc rho / (1 - rho), rho = inc / prev_inc; at the round-off
// level (noise) the last increment itself; infinite for a saddle or a CG that did not contract.
double cg_tail(const ModeCG& r) {
    if (r.broke) return std::numeric_limits<double>::infinity();
    if (r.inc == 0) return 0;
    if (r.noise) return r.inc;
    // One step gives no rate: a CG stopped there (by its step limit) has an unknown tail, unless it converged.
    if (!(std::isfinite(r.prev_inc) && r.prev_inc > 0)) return r.conv ? 0.0 : std::numeric_limits<double>::infinity();
    const double rho = r.inc / r.prev_inc;
    return rho < 1 ? r.inc * rho / (1 - rho) : std::numeric_limits<double>::infinity();
}

// The CG's own error in c: its tail, floored at the round-off of E_tt - c. Sums of n terms: n eps scale_ref (the
// classical bound; 1e-15 scale_ref let a floppy network's G = -1.7e-11 stand 200 errors below zero), and for the
// sums whose terms are far larger than their result (the comoving E_tt, c = sum b_i u_i) sqrt(n) eps times the size
// of their terms, the random-walk estimate of their rounding (n eps would put the default scene's G error at 4e-5
// relative, where other CPUs agree to 1e-9; without it a floppy network's G = -9.1e-11 stood 3 errors below zero,
// --L 4.25 --q 4.9 --pl 0.35 --seed 549912 --gamma 0.03).
double cg_error(const ModeCG& r, const CgScales& sc, int m) {
    const double eps = std::numeric_limits<double>::epsilon();
    const double floor = std::max(std::max(1e-15, sc.n * eps) * sc.scale_ref[m],
                                  std::sqrt(static_cast<double>(sc.n)) * eps * std::max(r.abs_sum, sc.comoving_size[m]));
    return std::max(cg_tail(r), floor);
}

// The error of c = b.u that the true residual r = B - H U shows: c* - c = u.r + r.H^+ r for c* = b.H^+ b (b, H u in
// range(H)); r.M r stands in for r.H^+ r (equal on H's stiff modes, a lower bound on the soft ones). Plus what
// rounding leaves unknown in the products with H: fl(H w) is H w only to gamma_k |H| |w| componentwise (k nonzeros
// per row; Higham, Accuracy and Stability, eq. 3.11), for w = u (the residual) and w = v (the comoving B = b + H v and
// E_tt + v.H v), so the modulus is uncertain by (|u| + |v|).|H|.(|u| + |v|) times the rounding of a k-term sum,
// taken as sqrt(k) eps as for the other sums. On the seed scheme a 1e-5 segment (stiffness 1e5 a^2) puts that 1e9
// times above u.H u; this term covers a floppy network's G of -1.1e-5 at rest (docs/moduli.md "Error estimates").
struct ResidualError {
    double drift = 0;     // u.r + r.M r
    double roundoff = 0;  // sqrt(k) eps (|u| + |v|).|H|.(|u| + |v|)
};
template <class HView>
std::vector<ResidualError> true_residual_error(const HView& Hs, const Eigen::SparseMatrix<double>& H,
                                               const LinearSolver& llt, const Eigen::MatrixXd& B, const Eigen::MatrixXd& U,
                                               const Eigen::MatrixXd& V) {
    const Eigen::MatrixXd R = B - Hs * U, Z = llt.solve_many(R);
    const Eigen::SparseMatrix<double> Habs = H.cwiseAbs();
    const Eigen::MatrixXd W = U.cwiseAbs() + V.cwiseAbs(), HW = Habs.selfadjointView<Eigen::Upper>() * W;
    const double per_row = H.rows() > 0 ? (2.0 * H.nonZeros() - H.rows()) / H.rows() : 1.0;  // of the full symmetric H
    const double rounding = std::sqrt(std::max(per_row, 1.0)) * std::numeric_limits<double>::epsilon();
    std::vector<ResidualError> d(B.cols());
    for (int m = 0; m < B.cols(); ++m) {
        d[m].drift = U.col(m).dot(R.col(m)) + R.col(m).dot(Z.col(m));
        d[m].roundoff = rounding * W.col(m).dot(HW.col(m));
    }
    return d;
}

// Names every modulus that failed, by cause (a saddle, or a CG that did not converge), e.g. "... for G, K".
std::string failure_message(const std::vector<Modulus>& out, const std::vector<char>& broke) {
    std::string saddle, unconverged;
    for (size_t m = 0; m < out.size(); ++m) {
        if (out[m].ok) continue;
        std::string& list = broke[m] ? saddle : unconverged;
        list += (list.empty() ? "" : ", ") + out[m].name;
    }
    std::string msg;
    if (!saddle.empty()) msg = "H is not positive semidefinite at this state (a saddle): no modulus for " + saddle;
    if (!unconverged.empty())
        msg += (msg.empty() ? "" : "; ") + std::string("conjugate gradients for H^+ E_xt did not converge for ") + unconverged;
    return msg;
}
// The comoving right-hand sides B and E_tt (written into out[m].E_tt) of relaxed_moduli. With v = dF F^{-1} x the
// affine velocity of the free nodes,
//   E_tt - b.H^+ b = (E_tt + 2 v.b + v.H v) - (b + H v).H^+ (b + H v)     (b in range(H)),
// whose two terms are the affine and non-affine parts: O(G A) instead of O(L^2 k) with absolute coordinates, where
// box-crossing segments make E_tt ~ 1e8 and the cancellation costs 6 digits. Terms already comoving (formed per
// element, StrainTerms::comoving) are taken as they are.
struct ComovingRhs {
    Eigen::MatrixXd B, V;
    Eigen::MatrixXd Vround;     // v where B and E_tt were formed through H v (their rounding), else 0
    std::vector<double> size;   // sum of |terms| of the comoving E_tt (its round-off's scale)
};
ComovingRhs comoving_rhs(const Eigen::SparseMatrix<double>& H, const std::vector<StrainTerms>& terms,
                         std::vector<Modulus>& out) {
    const auto Hs = H.selfadjointView<Eigen::Upper>();
    const int n = static_cast<int>(H.rows()), M = static_cast<int>(terms.size());
    ComovingRhs r{Eigen::MatrixXd(n, M), Eigen::MatrixXd(n, M), Eigen::MatrixXd::Zero(n, M), std::vector<double>(M)};
    for (int m = 0; m < M; ++m) {
        const Eigen::VectorXd& v = terms[m].v;
        r.V.col(m) = v;
        if (terms[m].comoving) {
            r.size[m] = std::max(terms[m].E_tt_size, std::abs(out[m].E_tt));
            r.B.col(m) = terms[m].b;
            continue;
        }
        const Eigen::VectorXd Hv = Hs * v;
        r.size[m] = std::abs(out[m].E_tt) + 2 * v.cwiseProduct(terms[m].b).cwiseAbs().sum() +
                    v.cwiseProduct(Hv).cwiseAbs().sum();
        out[m].E_tt += 2 * v.dot(terms[m].b) + v.dot(Hv);
        r.B.col(m) = terms[m].b + Hv;
        r.Vround.col(m) = v;
    }
    return r;
}
// D = |diag H| floored at 1e-12 of its median, so that a coordinate without stiffness still gets a shift
// (relaxed_moduli's Jacobi-scaled shift H + delta D).
std::vector<double> shift_scales(const Eigen::SparseMatrix<double>& H) {
    const int n = static_cast<int>(H.rows());
    std::vector<double> diag(n);
    for (int j = 0; j < n; ++j) diag[j] = std::abs(H.coeff(j, j));
    std::vector<double> sorted = diag;
    std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
    const double d_floor = std::max(1e-12 * sorted[n / 2], std::numeric_limits<double>::min());
    for (double& d : diag) d = std::max(d, d_floor);
    return diag;
}

// One factorization of Hd = H + delta D into llt, delta from rel grown 100x at a time (up to 8 tries) while round-off
// makes the (PSD, singular) H fail to factor. False if none factored.
bool factor_shifted(LinearSolver& llt, const Eigen::SparseMatrix<double>& H, const std::vector<double>& diag, double rel,
                    Eigen::SparseMatrix<double>& Hd, ModuliInfo& inf) {
    auto t0 = Clock::now();
    if (!llt.analyzed()) llt.analyze(H);  // a shared wrapper of another pattern is re-analyzed by factorize()
    inf.seconds_factorization += seconds_since(t0);
    bool factored = false;
    double delta = rel;
    const int n = static_cast<int>(H.rows());
    for (int k = 0; k < 8 && !factored; ++k, delta *= 100) {
        t0 = Clock::now();
        for (int j = 0; j < n; ++j) Hd.coeffRef(j, j) = H.coeff(j, j) + delta * diag[j];
        factored = llt.factorize(Hd, 0.0);
        inf.seconds_one_factorization = seconds_since(t0);
        inf.seconds_factorization += inf.seconds_one_factorization;
        ++inf.factorizations;
        if (factored) inf.delta = delta;
        inf.shift_grown = inf.shift_grown || (factored && k > 0);  // in either attempt
    }
    return factored;
}
}  // namespace

std::vector<Modulus> relaxed_moduli(const Eigen::SparseMatrix<double>& H, const std::vector<StrainTerms>& terms,
                                    const std::vector<StrainMode>& modes, const ModuliOptions& opt, ModuliInfo* info,
                                    LinearSolver* shared_llt) {
    const auto t_start = Clock::now();
    ModuliInfo local;
    ModuliInfo& inf = info ? *info : local;
    inf = ModuliInfo{};
    const int n = static_cast<int>(H.rows());
    if (terms.size() != modes.size()) throw std::logic_error("relaxed_moduli: one StrainTerms per mode");
    std::vector<Modulus> out(modes.size());
    for (size_t m = 0; m < modes.size(); ++m) {
        out[m].name = modes[m].name;
        out[m].E_tt = terms[m].E_tt;
        if (terms[m].b.size() != n || terms[m].v.size() != n) throw std::logic_error("relaxed_moduli: wrong sizes");
    }
    if (n == 0) {  // nothing can relax: the modulus is the fixed-coordinate term
        for (size_t m = 0; m < modes.size(); ++m) out[m].value = modes[m].scale * out[m].E_tt, out[m].ok = true;
        inf.seconds_total = seconds_since(t_start);
        return out;
    }
    // The shift is relative to each coordinate's own stiffness, H + delta D with D = |diag H| (a Jacobi-scaled
    // shift): Cholesky's rounding is relative to the diagonal (Demmel 1989: it succeeds once the scaled matrix's
    // smallest eigenvalue is above ~n eps), so delta D factors at delta = 1e-12 where a uniform shift of 1e-12 the
    // median |diagonal| failed on the seed scheme's 1e-5 segments (stiffness 1e5 the median) and had to grow to 1e-4,
    // which left the CG hundreds of soft modes (L = 40: modulus_failed; now 136 steps, docs/moduli.md). D is floored
    // at 1e-12 of the median so that a coordinate without stiffness still gets a shift.
    const std::vector<double> diag = shift_scales(H);
    // The right-hand sides in comoving coordinates, the same for both shift scales below.
    auto t0 = Clock::now();
    const auto Hs = H.selfadjointView<Eigen::Upper>();
    const int M = static_cast<int>(modes.size());
    const ComovingRhs rhs = comoving_rhs(H, terms, out);
    const Eigen::MatrixXd &B = rhs.B, &V = rhs.V, &Vround = rhs.Vround;
    const std::vector<double>& comoving_size = rhs.size;
    const double seconds_setup = seconds_since(t0);
    const std::vector<Modulus> base = out;
    CholmodLLT own;
    LinearSolver& llt = shared_llt && shared_llt->definite() ? *shared_llt : own;  // a modulus needs the exact inverse
    Eigen::SparseMatrix<double> Hd = H;  // H + delta D
    auto attempt = [&](double rel) -> bool {
        out = base;
        if (!factor_shifted(llt, H, diag, rel, Hd, inf)) {
            inf.message = "H + delta |diag H| is not positive definite up to delta = 1e2: not a stable equilibrium";
            return false;
        }

        // Preconditioned CG towards H^+ b, all modes at once, and the error its true residual shows (pcg_modes,
        // true_residual_correction).
        t0 = Clock::now();
        Eigen::MatrixXd U = Eigen::MatrixXd::Zero(n, M);
        const Eigen::MatrixXd Z0 = llt.solve_many(B);
        std::vector<double> scale_ref(M), rz0(M);
        for (int m = 0; m < M; ++m) {
            rz0[m] = B.col(m).dot(Z0.col(m));
            scale_ref[m] = std::max({std::abs(out[m].E_tt), rz0[m], std::numeric_limits<double>::min()});
        }
        const CgScales sc{scale_ref, rz0, comoving_size, n};
        const std::vector<ModeCG> cg = pcg_modes(Hs, llt, B, Z0, U, sc, opt);
        const std::vector<ResidualError> drift = true_residual_error(Hs, H, llt, B, U, Vround);
        std::vector<char> broke(M);
        for (int m = 0; m < M; ++m) {
            const ModeCG& r = cg[m];
            Modulus& Mo = out[m];
            broke[m] = r.broke;
            Mo.refinements = r.steps;
            Mo.stalled = r.noise && !r.conv;
            Mo.response = U.col(m) - V.col(m);  // H (u - v) = (b + H v) - H v = E_xt
            Mo.correction = r.c;
            Mo.value = modes[m].scale * (Mo.E_tt - r.c);
            // What the CG says is left (its tail, floored at the cancellation's round-off), and at least what the true
            // residual says, within the rounding of that residual: the CG's own residual drifts from B - H U by
            // round-off in H's stiff modes, and then its tail is no bound (a seed-scheme G of -1.13e-6 reported
            // +- 4e-10 on AVX2 kernels, +- 3.7e-8 and -4.3e-7 on AVX-512 ones at the same state; docs/moduli.md
            // "Error estimates").
            Mo.error = modes[m].scale * std::max(cg_error(r, sc, m), std::abs(drift[m].drift) + drift[m].roundoff);
            // Accepted when converged, or stopped by round-off with the tail below 1e-7 of the cancellation scale
            // (the seed scheme's 1e-4 segments at L = 20 end there; the error is reported).
            Mo.ok = std::isfinite(Mo.value) && !r.broke && (r.conv || cg_tail(r) <= 1e-7 * scale_ref[m]);
        }
        inf.message = failure_message(out, broke);
        inf.seconds_solve += seconds_since(t0);
        for (const auto& m : out)
            if (!m.ok) return false;
        return true;
    };
    // The retry also when round-off stopped a CG before convergence (accepted with a small tail above, but a CG
    // stalled in the null space of a floppy part can understate its error: measured a G 4.6e-5 off with a bound of
    // 4e-7, tests/mechanics/moduli_test.cpp "[prune]"): the larger shift leaves fewer modes for the CG.
    inf.seconds_solve += seconds_setup;
    const bool first = attempt(opt.delta_rel);
    bool stalled = false;
    for (const auto& m : out) stalled = stalled || m.stalled;
    if (!first || stalled) {
        const std::vector<Modulus> kept = out;
        const std::string kept_message = inf.message;
        inf.message.clear();
        if (!attempt(100 * opt.delta_rel) && first) {
            out = kept, inf.message = kept_message;
        } else if (first) {
            // Both attempts stopped somewhere: their difference is a measured lower bound on the error (a stalled
            // CG's own bound can be 100x too small, docs/moduli.md "Error estimates").
            for (size_t m = 0; m < out.size(); ++m) out[m].error = std::max(out[m].error, std::abs(out[m].value - kept[m].value));
        }
    }
    // A failed modulus has no value: NaN, so that a caller who forgets `ok` does not carry a plausible number on.
    for (auto& M : out)
        if (!M.ok) M.value = M.error = std::numeric_limits<double>::quiet_NaN();
    inf.seconds_total = seconds_since(t_start);
    return out;
}

}  // namespace fibernet
