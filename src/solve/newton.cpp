#include "fibernet/solve/newton.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <limits>

#include "fibernet/solve/cholmod_llt.hpp"

namespace fibernet {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Mean |diagonal| of an upper-triangular CSC matrix (the diagonal is the last entry of each column).
double mean_diag(const Eigen::SparseMatrix<double>& H) {
    const int n = static_cast<int>(H.cols());
    double s = 0;
    for (int j = 0; j < n; ++j) {
        const int e = H.outerIndexPtr()[j + 1] - 1;
        if (e >= H.outerIndexPtr()[j] && H.innerIndexPtr()[e] == j) s += std::abs(H.valuePtr()[e]);
    }
    return n > 0 ? s / n : 1.0;
}

constexpr double kArmijo = 1e-4;
constexpr double kDescent = 1e-12;    // g.d < -kDescent |g| |d|
constexpr double kMuFloor = 1e-13;    // relative to mean diag: round-off scale of a null pivot
constexpr double kMuStart = 1e-8;     // relative to mean diag: first Levenberg-Marquardt shift
constexpr double kLambda0 = 1e-8;     // rung 2 start, relative to mean diag
constexpr int kLambdaSteps = 11;
constexpr double kExactGrow = 4;      // rung 0 escalation factor
constexpr double kExactCap = 0.2;     // rung 0 escalation stops above this x mean diag
constexpr int kMaxHalvings = 60;
}  // namespace

// max_i sum_j |H_ij| ulp(max(|q_j|, 1)): the gradient error of rounding every coordinate to its floating-point spacing.
double roundoff_floor(const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& q) {
    const int n = static_cast<int>(q.size());
    Eigen::VectorXd u(n), r = Eigen::VectorXd::Zero(n);
    // Coordinates are displacements (~0 near the reference) added to rest vectors of order one seed unit, so the
    // rounding is that of max(|q_j|, 1), not of q_j itself.
    for (int j = 0; j < n; ++j) {
        const double a = std::max(std::abs(q[j]), 1.0);
        u[j] = std::nextafter(a, HUGE_VAL) - a;
    }
    for (int j = 0; j < n; ++j)
        for (int k = H.outerIndexPtr()[j]; k < H.outerIndexPtr()[j + 1]; ++k) {
            const int i = H.innerIndexPtr()[k];
            const double a = std::abs(H.valuePtr()[k]);
            r[i] += a * u[j];
            if (i != j) r[j] += a * u[i];
        }
    return n > 0 ? r.maxCoeff() : 0.0;
}


CholmodLLT& NewtonSolver::factorization_for(const Eigen::SparseMatrix<double>& H, double* seconds) {
    // Symbolic analysis once per pattern (kept across calls while the pattern is the same).
    const bool same = llt_ && analyzed_.rows() == H.rows() && analyzed_.nonZeros() == H.nonZeros() &&
                      std::equal(H.outerIndexPtr(), H.outerIndexPtr() + H.cols() + 1, analyzed_.outerIndexPtr()) &&
                      std::equal(H.innerIndexPtr(), H.innerIndexPtr() + H.nonZeros(), analyzed_.innerIndexPtr());
    if (!same) {
        auto t0 = Clock::now();
        llt_ = std::make_unique<CholmodLLT>();
        analyzed_ = H;
        // With the LDL^T rung the LL^T factorization is only a fallback: analyzed on first use (CholmodLLT::factorize),
        // which on wet networks with many small regions is often never.
        if (H.rows() > 0 && !opt_.ldl) llt_->analyze(H);
        ldl_.reset();  // analyzed on first use (SolverOptions::ldl)
        if (seconds) *seconds = since(t0);
    }
    return *llt_;
}

SolveResult NewtonSolver::minimize(Objective& f, Eigen::VectorXd& q) {
    const auto t_start = Clock::now();
    SolveResult r;
    r.solver = name();
    history_.clear();
    rungs_.clear();
    shifts_.clear();
    const int n = f.size();
    if (q.size() != n) throw std::logic_error("newton: start vector has the wrong size");

    Eigen::SparseMatrix<double> H = f.hessian_pattern();
    double t_analysis = 0;
    CholmodLLT& llt = factorization_for(H, &t_analysis);
    r.timings.factorization += t_analysis;
    if (opt_.ldl && n > 0 && !ldl_) {
        const auto t0 = Clock::now();
        ldl_ = std::make_unique<CholmodLDL>();
        ldl_->analyze(H);
        r.timings.factorization += since(t0);
    }
    CholmodLDL* ldl = opt_.ldl ? ldl_.get() : nullptr;
    std::unique_ptr<NonlinearElimination> ne;
    if (opt_.eliminate && n > 0) ne = std::make_unique<NonlinearElimination>(H, opt_.elimination);

    Eigen::VectorXd g(n), gt(n), d(n), qt(n);
    int start_rung = 0;
    std::vector<double> energies;
    double mu_lm = -1;  // Levenberg-Marquardt shift, adapted from the model agreement of each step
    double dm_last = 0;  // mean diag of the last iteration's H (the shift is kept relative to it)
    bool projected = false;  // what H currently holds
    for (int it = 0;; ++it) {
        // Assemble f, g, H at q: exact unless the last iteration needed the projected rungs.
        auto t0 = Clock::now();
        projected = start_rung >= 1;
        double fq = n > 0 ? f.hessian(q, g, H, projected) : f.value(q);
        r.timings.assembly += since(t0);
        ++r.evaluations;
        r.energy = fq;
        r.iterations = it;
        if (!std::isfinite(fq) || !g.allFinite()) {
            r.status = SolveStatus::NonFinite;
            r.message = "non-finite energy or gradient at iteration " + std::to_string(it);
            r.grad_max = n > 0 ? g.lpNorm<Eigen::Infinity>() : 0.0;
            break;
        }
        double gmax = n > 0 ? g.lpNorm<Eigen::Infinity>() : 0.0;
        r.grad_max = gmax;
        history_.push_back(gmax);
        if (gmax <= opt_.tol) {
            r.status = SolveStatus::Converged;
            r.message = "max|g| <= tol";
            break;
        }
        // Round-off floor: coordinates are stored to ulp(q_j), so the gradient of the best representable state is
        // uncertain by about (|H| ulp(q))_i. With segments of 1e-4 in a box of side 100 this is ~1e-8, above the
        // default tol 1e-10 (docs/moduli.md, "Round-off floor"). The bound below is pessimistic (~10x).
        // Stop there only when progress has stopped too (max|g| not halved and the energy flat to 1e-11 over the
        // last 3 iterations), so this pessimistic bound (10-100x on Mikado networks) never cuts a converging or
        // still-descending Newton short. The bound costs a pass over H: computed only then (and for the verbose
        // line, and once for the returned state).
        const int h = static_cast<int>(history_.size());
        energies.push_back(fq);
        bool stalled = h >= 4 && gmax > 0.5 * std::min({history_[h - 2], history_[h - 3], history_[h - 4]});
        if (stalled) {
            const auto [lo, hi] = std::minmax_element(energies.end() - 4, energies.end());
            stalled = *hi - *lo <= 1e-11 * (1 + std::abs(fq));
        }
        const double floor = stalled || opt_.verbose ? roundoff_floor(H, q) : 0.0;
        if (gmax <= floor && stalled) {
            r.status = SolveStatus::Converged;
            char buf[160];
            std::snprintf(buf, sizeof buf, "max|g| = %.3e is at the round-off floor of the coordinates (bound %.3e), above tol",
                          gmax, floor);
            r.message = buf;
            break;
        }
        if (it >= opt_.max_iter) {
            r.status = SolveStatus::IterationLimit;
            r.message = "iteration limit " + std::to_string(opt_.max_iter) + " reached";
            break;
        }
        if (opt_.max_seconds > 0 && since(t_start) > opt_.max_seconds) {
            r.status = SolveStatus::IterationLimit;
            r.message = "time limit reached";
            break;
        }

        // Nonlinear elimination (nonlinear_elimination.hpp): the hot places to local equilibrium, then H and g again.
        double local_tol = 0;
        bool eliminating = false;
        if (ne && ne->select(g)) {
            local_tol = std::max(opt_.tol, opt_.elimination.local_rtol * gmax);
            ne->eliminate(f, q, local_tol);
            eliminating = true;
            auto ta = Clock::now();
            fq = f.hessian(q, g, H, projected);
            r.timings.assembly += since(ta);
            ++r.evaluations;
            r.energy = fq;
            r.grad_max = gmax = n > 0 ? g.lpNorm<Eigen::Infinity>() : 0.0;
            if (!std::isfinite(fq) || !g.allFinite()) {
                r.status = SolveStatus::NonFinite;
                r.message = "non-finite energy or gradient after the elimination of iteration " + std::to_string(it);
                break;
            }
            if (r.grad_max <= opt_.tol) {
                history_.back() = r.grad_max;
                r.status = SolveStatus::Converged;
                r.message = "max|g| <= tol";
                break;
            }
        }

        // The ladder: find a descent direction.
        const double dm = std::max(mean_diag(H), std::numeric_limits<double>::min());
        if (mu_lm < 0) mu_lm = (opt_.warm_start && shift_rel_ > 0 ? shift_rel_ : kMuStart) * dm;
        dm_last = dm;
        const double mu = std::max(kMuFloor * dm, mu_lm);
        const double gnorm = g.norm();
        auto descent = [&] { return d.allFinite() && g.dot(d) < -kDescent * gnorm * d.norm(); };
        auto try_factor = [&](double s) {
            auto tf = Clock::now();
            const bool ok = llt.factorize(H, s);
            r.timings.factorization += since(tf);
            ++r.factorizations;
            if (!ok) return false;
            auto ts = Clock::now();
            d = llt.solve(-g);
            r.timings.solve += since(ts);
            return descent();
        };
        auto make_projected = [&] {
            if (projected) return;
            auto ta = Clock::now();
            f.hessian(q, gt, H, true);
            r.timings.assembly += since(ta);
            ++r.evaluations;
            projected = true;
        };
        // Two passes: with SolverOptions::ldl the first takes the LDL^T direction; if its line search fails (a poor
        // flipped-curvature direction), the second redoes the iteration with the shifted LL^T ladder.
        int rung = -1;
        double shift = 0, alpha = 1, ft = 0;
        bool accepted = false, retry = false, retried = false, step_ldl = false;
        for (int pass = 0; pass < 2 && !accepted; ++pass) {
            if (pass == 1 && !retry) break;
            retried = pass == 1;
            bool used_ldl = false, indefinite = false;
            rung = -1, shift = 0;
            if (start_rung <= 0 && ldl && pass == 0) {
                // Rung 0 by LDL^T (SolverOptions::ldl): the exact H + mu I with its negative pivots flipped, a positive
                // definite matrix equal to H + mu I wherever H is positive definite. Negative curvature is handled where
                // it occurs: no escalated shift for the whole Hessian, which on a large wet network is set by its worst
                // spot and shortens the step of every other part.
                auto tf = Clock::now();
                const bool ok = ldl->factorize(H, mu);
                r.timings.factorization += since(tf);
                ++r.factorizations;
                if (ok) {
                    auto ts = Clock::now();
                    d = -ldl->solve_modified(g, mu);
                    r.timings.solve += since(ts);
                    if (descent()) {
                        rung = 0, shift = mu, used_ldl = true;
                        // No negative pivot: H + mu I is positive definite (Sylvester's law of inertia) and this is the
                        // LL^T direction itself, so a failed line search has nothing to retry.
                        indefinite = ldl->negative_pivots() > 0;
                    }
                }
            }
            if (start_rung <= 0 && rung < 0) {  // H holds the exact Hessian (assembled with projected = start_rung >= 1)
                // (On the retry H + mu I is known to be indefinite: the escalation starts above mu.)
                if (pass == 0 && try_factor(mu)) {
                    rung = 0, shift = mu;
                } else {
                    // Exact H + lambda I with lambda raised 4x at a time (Nocedal & Wright, Alg. 3.3) before giving up
                    // the exact Hessian: negative curvature (capillary torques, buckling) is kept in every direction but
                    // the few unstable ones, where projecting each element's block would overstate the stiffness of the
                    // whole assembly and turn Newton into a linearly converging method (docs/moduli.md, "Newton ladder").
                    double lam = std::max(kExactGrow * mu, kLambda0 * dm);
                    for (; lam <= kExactCap * dm && rung < 0; lam *= kExactGrow)
                        if (try_factor(lam)) rung = 0, shift = lam;
                }
            }
            if (rung < 0 && start_rung <= 1) {
                make_projected();
                if (try_factor(mu)) rung = 1, shift = mu;
            }
            if (rung < 0) {
                make_projected();
                double lam = std::max(mu, kLambda0 * dm);
                for (int j = 0; j < kLambdaSteps && rung < 0; ++j, lam *= 10)
                    if (try_factor(lam)) rung = 2, shift = lam;
            }
            if (rung < 0) rung = 3, d = -g / dm;

            // Armijo backtracking; +inf/NaN is a failed trial.
            auto tl = Clock::now();
            for (int attempt = 0; attempt < 2 && !accepted; ++attempt) {
                if (attempt == 1) {  // the Newton-type direction failed: one steepest-descent try (after the LDL^T retry)
                    if (rung == 3 || (used_ldl && indefinite)) break;
                    rung = 3, d = -g / dm;
                }
                const double gd = g.dot(d);
                alpha = 1;
                for (int k = 0; k < kMaxHalvings; ++k, alpha *= 0.5) {
                    qt = q + alpha * d;
                    if (eliminating) ne->eliminate(f, qt, local_tol);  // the places back in their valleys
                    ft = f.value(qt);
                    ++r.evaluations;
                    if (!std::isfinite(ft)) continue;
                    if (ft <= fq + kArmijo * alpha * gd) {
                        accepted = true;
                        break;
                    }
                    // Round-off regime: the predicted decrease is below what the energy can resolve.
                    if (k == 0 && ft - fq <= 1e-12 * (1 + std::abs(fq)) && -gd <= 1e-10 * (1 + std::abs(fq))) {
                        f.gradient(qt, gt);
                        ++r.evaluations;
                        if (gt.allFinite() && gt.lpNorm<Eigen::Infinity>() < gmax) {
                            accepted = true;
                            break;
                        }
                    }
                }
            }
            r.timings.line_search += since(tl);
            step_ldl = accepted && used_ldl;
            retry = !accepted && used_ldl && indefinite;
            if (retry) ++r.ldl_retries;
        }
        rungs_.push_back(rung);
        shifts_.push_back(rung <= 2 ? shift : 0.0);
        if (opt_.verbose)
            std::fprintf(stderr, "newton %4d  E = %.15e  max|g| = %.3e  floor %.1e  rung %d%s  shift %.2e  alpha %.3e\n", it,
                         fq, gmax, floor, rung,
                         step_ldl ? (" (LDL^T, " + std::to_string(ldl->negative_pivots()) + " negative pivots)").c_str()
                                  : retried ? " (after LDL^T)" : "",
                         shift, accepted ? alpha : 0.0);
        if (!accepted) {
            r.status = SolveStatus::LineSearchFailed;
            r.message = "no acceptable step along a descent direction at iteration " + std::to_string(it);
            break;
        }
        // Shift update (Nielsen-like): shrink after a full step the quadratic model predicted well, grow after
        // backtracking or a poor prediction. Near a minimum every step is full and predicted, so the shift
        // falls 10x per iteration and the convergence becomes quadratic.
        if (rung <= 2) {
            const Eigen::VectorXd Hd = H.selfadjointView<Eigen::Upper>() * d;
            const double pred = -(alpha * g.dot(d) + 0.5 * alpha * alpha * d.dot(Hd));
            const double actual = fq - ft;
            const double rho = pred > 1e-12 * (1 + std::abs(fq)) ? actual / pred : 1.0;
            if (alpha == 1 && rho > 0.5) mu_lm = std::max(kMuFloor * dm, shift / 10);
            else if (alpha < 1 || rho < 0.25) mu_lm = std::max(4 * shift, kMuFloor * dm);
            else mu_lm = shift;
            // After a retry the ladder's escalated shift damps the whole Hessian; the next LDL^T iteration grows from
            // its own shift instead, as after a backtracked step.
            if (retried) mu_lm = std::max(4 * mu, kMuFloor * dm);
        }
        q = qt;
        start_rung = std::max(0, std::min(rung, 2) - 1);
    }
    // The floor at the returned state: H was assembled there (every exit follows an assembly at q; a failed line
    // search leaves q where H was assembled, possibly as the projected Hessian of the ladder's lower rungs).
    if (n > 0 && r.status != SolveStatus::NonFinite) r.grad_floor = roundoff_floor(H, q);
    if (ne) {
        const EliminationCounts& c = ne->counts();
        r.local_solves = c.local_solves, r.local_iterations = c.local_iterations;
        r.local_factorizations = c.local_factorizations;
    }
    r.timings.total = since(t_start);
    if (mu_lm > 0 && dm_last > 0) shift_rel_ = mu_lm / dm_last;
    if (opt_.verbose)
        std::fprintf(stderr, "newton: %s after %d iterations, %d factorizations (%d local solves, %d local iterations), "
                     "max|g| = %.3e, %.3f s\n", to_string(r.status).c_str(), r.iterations, r.factorizations,
                     r.local_solves, r.local_iterations, r.grad_max, r.timings.total);
    return r;
}

}  // namespace fibernet
