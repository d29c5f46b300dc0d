#include "fibernet/solve/newton.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <limits>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/newton_ladder.hpp"
#include "fibernet/solve/solver_loop.hpp"
#include "fibernet/util/stopwatch.hpp"

namespace fibernet {

namespace {
using Clock = std::chrono::steady_clock;

// |diagonal| of an upper-triangular CSC matrix (the diagonal is the last entry of each column; a column without one
// contributes nothing), in column order, into d (kept by the caller across iterations).
void abs_diagonal(const Eigen::SparseMatrix<double>& H, std::vector<double>& d) {
    d.clear();
    for (int j = 0; j < H.cols(); ++j) {
        const int e = H.outerIndexPtr()[j + 1] - 1;
        if (e >= H.outerIndexPtr()[j] && H.innerIndexPtr()[e] == j) d.push_back(std::abs(H.valuePtr()[e]));
    }
}

// Their mean over all n columns: the Hessian's scale, to which the first shift and the escalations are relative.
double mean_of(const std::vector<double>& d, int n) {
    double s = 0;
    for (double x : d) s += x;
    return n > 0 ? s / n : 1.0;
}

// Their median (reorders d): the scale of the shift's floor with SolverOptions::median_floor. The floppy modes that
// need the smallest shift live on the soft coordinates, which the median represents; the mean is set by the stiffest
// columns (very short segments: diagonals up to 1e6 x the median on the seed scheme), and a floor at 1e-13 of it held
// those modes to a linear rate (docs/solvers.md, "Newton's shift floor"). The same reason moved the moduli's shift to
// the median (docs/moduli.md).
double median_of(std::vector<double>& d) {
    if (d.empty()) return 1.0;
    std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
    return d[d.size() / 2];
}

constexpr double kArmijo = 1e-4;
constexpr double kMuFloor = 1e-13;    // relative to the median (SolverOptions::median_floor) or mean diag: round-off
                                      // scale of a null pivot
constexpr double kMuStart = 1e-8;     // relative to mean diag: first Levenberg-Marquardt shift
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


CholmodLLT& NewtonSolver::analyzed_for(const Eigen::SparseMatrix<double>& H, double* seconds) {
    // Symbolic analysis once per pattern (kept across calls while the pattern is the same).
    if (!llt_ || !same_pattern(H, analyzed_)) {
        auto t0 = Clock::now();
        llt_ = std::make_unique<CholmodLLT>();
        analyzed_ = H;
        // With the LDL^T rung the LL^T factorization is only a fallback: analyzed on first use (CholmodLLT::factorize),
        // which on wet networks with many small regions is often never.
        if (H.rows() > 0 && !opt_.ldl) llt_->analyze(H);
        ldl_.reset();  // analyzed on first use (SolverOptions::ldl)
        if (seconds) *seconds = seconds_since(t0);
    }
    return *llt_;
}

namespace {
// Newton's iteration (newton.hpp) as a method of the solver loop (solver_loop.hpp): assemble, eliminate the hot
// places, descend the ladder, line search, adapt the shift.
class Newton : public IterativeMethod {
public:
    Newton(const SolverOptions& opt, NewtonLadder& ladder, ModifiedLdlRung* ldl, double warm_shift_rel,
           NewtonTrace& trace, std::vector<LinearSolver*> factorizations)
        : opt_(opt), ladder_(ladder), ldl_(ldl), warm_shift_rel_(warm_shift_rel), trace_(trace),
          factorizations_(std::move(factorizations)) {}

    Step start(SolverRun& run, Eigen::VectorXd& q) override {
        Objective& f = run.objective();
        const int n = f.size();
        H_ = f.hessian_pattern();
        version_ = f.pattern_version();
        g_.resize(n), gt_.resize(n), d_.resize(n), qt_.resize(n);
        if (opt_.eliminate && n > 0) ne_ = std::make_unique<NonlinearElimination>(H_, opt_.elimination, opt_.median_floor, opt_.max_step);
        if (opt_.projected) start_rung_ = 1;
        return assemble(run, q, 0);
    }

    Step iterate(SolverRun& run, Eigen::VectorXd& q, int it) override {
        Step s = eliminate(run, q, it);
        if (s.done) return s;
        if (!descend_and_search(run, q, it))
            return Step::stop(SolveStatus::LineSearchFailed,
                              "no acceptable step along a descent direction at iteration " + std::to_string(it));
        q = qt_;
        return assemble(run, q, it + 1);
    }

    double energy() const override { return fq_; }
    double grad_max() const override { return gmax_; }
    bool reports_every_iteration() const override { return opt_.verbose; }

    void complete(SolveResult& r, const Step& last, const Eigen::VectorXd& q) override {
        // The floor at the returned state: H was assembled there (every exit follows an assembly at q; a failed line
        // search leaves q where H was assembled, possibly as the projected Hessian of the ladder's lower rungs).
        if (q.size() > 0 && last.status != SolveStatus::NonFinite) r.grad_floor = roundoff_floor(H_, q);
        if (ne_) {
            const EliminationCounts& c = ne_->counts();
            r.local_solves = c.local_solves, r.local_iterations = c.local_iterations;
            r.local_factorizations = c.local_factorizations, r.eliminating_iterations = c.selections;
        }
        if (mu_lm_ > 0 && dm_last_ > 0) trace_.shift_rel = mu_lm_ / dm_last_;
    }

private:
    // A Hessian in a new pattern (Objective::pattern_version): the factorizations analyze it at their next use, and
    // elimination's coupling graph is rebuilt from it.
    void follow_pattern(const Objective& f) {
        const long v = f.pattern_version();
        if (v == version_) return;
        version_ = v;
        for (LinearSolver* lin : factorizations_) lin->forget();
        if (ne_) ne_->set_pattern(H_);
    }

    // f, g, H at q (exact unless the last iteration needed the projected rungs), and the stop tests that need H.
    Step assemble(SolverRun& run, const Eigen::VectorXd& q, int it) {
        SolveResult& r = run.result();
        const auto t0 = Clock::now();
        projected_ = start_rung_ >= 1;
        fq_ = q.size() > 0 ? run.objective().hessian(q, g_, H_, projected_) : run.objective().value(q);
        r.timings.assembly += seconds_since(t0);
        follow_pattern(run.objective());
        gmax_ = q.size() > 0 ? g_.lpNorm<Eigen::Infinity>() : 0.0;
        if (!std::isfinite(fq_) || !g_.allFinite())
            return Step::stop(SolveStatus::NonFinite, "non-finite energy or gradient at iteration " + std::to_string(it),
                              it > 0);
        trace_.history.push_back(gmax_);
        energies_.push_back(fq_);
        floor_ = 0;
        if (gmax_ <= opt_.tol) return Step::moved();
        return roundoff_stop(q, it);
    }

    // Round-off floor: coordinates are stored to ulp(q_j), so the gradient of the best representable state is
    // uncertain by about (|H| ulp(q))_i. With segments of 1e-4 in a box of side 100 this is ~1e-8, above the default
    // tol 1e-10 (docs/moduli.md, "Round-off floor"). The bound is pessimistic (~10x). Stop there only when progress
    // has stopped too (max|g| not halved and the energy flat to 1e-11 over the last 3 iterations), so this bound
    // (10-100x on Mikado networks) never cuts a converging or still-descending Newton short. It costs a pass over H:
    // computed only then (and for the verbose line).
    Step roundoff_stop(const Eigen::VectorXd& q, int it) {
        const std::vector<double>& h = trace_.history;
        const size_t m = h.size();
        bool stalled = m >= 4 && gmax_ > 0.5 * std::min({h[m - 2], h[m - 3], h[m - 4]});
        if (stalled) {
            const auto [lo, hi] = std::minmax_element(energies_.end() - 4, energies_.end());
            stalled = *hi - *lo <= 1e-11 * (1 + std::abs(fq_));
        }
        floor_ = stalled || opt_.verbose ? roundoff_floor(H_, q) : 0.0;
        if (!(gmax_ <= floor_ && stalled)) return Step::moved();
        char buf[160];
        std::snprintf(buf, sizeof buf, "max|g| = %.3e is at the round-off floor of the coordinates (bound %.3e), above tol",
                      gmax_, floor_);
        return Step::stop(SolveStatus::Converged, buf, it > 0);
    }

    // What is left of the time budget for the local solves (0: no budget; a spent one leaves a tiny positive rest,
    // so that no part is solved and the loop's stop test ends the solve).
    double time_left(const SolverRun& run) const {
        if (opt_.max_seconds <= 0) return 0;
        return std::max(opt_.max_seconds - run.seconds(), 1e-9);
    }

    // Nonlinear elimination (nonlinear_elimination.hpp): the hot places to local equilibrium, then H and g again.
    Step eliminate(SolverRun& run, Eigen::VectorXd& q, int it) {
        eliminating_ = false;
        if (!ne_ || !ne_->select(g_)) return Step::again();
        local_tol_ = std::max(opt_.tol, opt_.elimination.local_rtol * gmax_);
        const auto ts = Clock::now();
        ne_->eliminate(run.objective(), q, local_tol_, time_left(run), [&](const Eigen::VectorXd& qs, int done, int total) {
            if (opt_.observe_within) opt_.observe_within(qs, [&] { return run.objective().value(qs); });
            run.tick_within(it, done, total, seconds_since(ts));
        });
        eliminating_ = ne_->at_trial_points();
        const auto ta = Clock::now();
        fq_ = run.objective().hessian(q, g_, H_, projected_);
        run.result().timings.assembly += seconds_since(ta);
        follow_pattern(run.objective());
        gmax_ = q.size() > 0 ? g_.lpNorm<Eigen::Infinity>() : 0.0;
        if (!std::isfinite(fq_) || !g_.allFinite())
            return Step::stop(SolveStatus::NonFinite,
                              "non-finite energy or gradient after the elimination of iteration " + std::to_string(it));
        if (gmax_ <= opt_.tol) {
            trace_.history.back() = gmax_;
            return Step::stop(SolveStatus::Converged, "max|g| <= tol");
        }
        return Step::again();
    }

    // The ladder's direction and the line search along it, in up to two passes: with SolverOptions::ldl the first
    // takes the modified LDL^T direction; if its line search fails (a poor flipped-curvature direction), the second
    // redoes the iteration with the shifted LL^T rungs. Then the shift update. False: no step was accepted.
    bool descend_and_search(SolverRun& run, Eigen::VectorXd& q, int it) {
        SolveResult& r = run.result();
        abs_diagonal(H_, diag_);
        const double dm = std::max(mean_of(diag_, static_cast<int>(H_.cols())), std::numeric_limits<double>::min());
        if (mu_lm_ < 0) mu_lm_ = (opt_.warm_start && warm_shift_rel_ > 0 ? warm_shift_rel_ : kMuStart) * dm;
        dm_last_ = dm;
        mu_floor_ = kMuFloor * (opt_.median_floor ? median_of(diag_) : dm);
        const double mu = std::max(mu_floor_, mu_lm_);
        LadderState ls{run.objective(), q, g_, H_, projected_, mu, dm, 0, r};
        int level = -1;
        double shift = 0, alpha = 1, ft = 0;
        bool accepted = false, retried = false, step_ldl = false;
        for (int pass = 0; pass < 2 && !accepted; ++pass) {
            retried = pass == 1;
            ls.pass = pass;
            NewtonRung& rung = ladder_.descend(ls, start_rung_, d_, shift);
            level = rung.level();
            const bool used_ldl = &rung == ldl_, modified = rung.modified();
            const auto tl = Clock::now();
            accepted = line_search(run, q, dm, level, alpha, ft, used_ldl && modified);
            r.timings.line_search += seconds_since(tl);
            step_ldl = accepted && used_ldl;
            if (accepted || !(used_ldl && modified)) break;
            ++r.ldl_retries;
        }
        trace_.rungs.push_back(level);
        trace_.shifts.push_back(level <= 2 ? shift : 0.0);
        if (opt_.verbose)
            std::fprintf(stderr, "newton %4d  E = %.15e  max|g| = %.3e  floor %.1e  rung %d%s  shift %.2e  alpha %.3e\n", it,
                         fq_, gmax_, floor_, level,
                         step_ldl ? (" (LDL^T, " + std::to_string(ldl_->negative_pivots()) + " negative pivots)").c_str()
                                  : retried ? " (after LDL^T)" : "",
                         shift, accepted ? alpha : 0.0);
        if (!accepted) return false;
        update_shift(level, shift, alpha, ft, mu, retried);
        start_rung_ = next_start(level, alpha);
        return true;
    }

    // Where the next iteration's ladder starts: one level above this step's. Projected Newton (SolverOptions::projected)
    // stays on the projected Hessian (assembled alone, without the exact one first) until a step was accepted in full,
    // then tries the exact Hessian, which a full step suggests is near positive definite: element-wise projection
    // overstates the stiffness, and near a minimum only the exact Hessian converges quadratically.
    int next_start(int level, double alpha) const {
        if (!opt_.projected) return std::max(0, std::min(level, 2) - 1);
        if (alpha == 1 && level <= 1) return 0;
        return std::max(1, std::min(level, 2) - 1);
    }

    // Armijo backtracking from alpha = 1 along d (then, unless d came from the steepest rung or from a modified
    // factorization that will be retried, once along -g / dm); +inf/NaN is a failed trial. With elimination, the hot
    // places are put back in their valleys at every trial point.
    bool line_search(SolverRun& run, const Eigen::VectorXd& q, double dm, int& level, double& alpha, double& ft,
                     bool retry_follows) {
        Objective& f = run.objective();
        for (int attempt = 0; attempt < 2; ++attempt) {
            if (attempt == 1) {  // the Newton-type direction failed: one steepest-descent try
                if (level == 3 || retry_follows) return false;
                level = 3, d_ = -g_ / dm;
            }
            const double gd = g_.dot(d_);
            const double dmax = d_.size() ? d_.lpNorm<Eigen::Infinity>() : 0.0;
            alpha = opt_.max_step > 0 && dmax > opt_.max_step ? opt_.max_step / dmax : 1.0;
            for (int k = 0; k < kMaxHalvings; ++k, alpha *= 0.5) {
                qt_ = q + alpha * d_;
                if (eliminating_) ne_->eliminate(f, qt_, local_tol_, time_left(run));
                ft = f.value(qt_);
                if (!std::isfinite(ft)) continue;
                if (ft <= fq_ + kArmijo * alpha * gd) return true;
                // Round-off regime: the predicted decrease is below what the energy can resolve; a full step is then
                // accepted when the energy did not rise beyond round-off and max|g| fell.
                if (k == 0 && ft - fq_ <= 1e-12 * (1 + std::abs(fq_)) && -gd <= 1e-10 * (1 + std::abs(fq_))) {
                    f.gradient(qt_, gt_);
                    if (gt_.allFinite() && gt_.lpNorm<Eigen::Infinity>() < gmax_) return true;
                }
            }
        }
        return false;
    }

    // Shift update (Nielsen-like): shrink after a full step the quadratic model predicted well, grow after
    // backtracking or a poor prediction. Near a minimum every step is full and predicted, so the shift falls 10x per
    // iteration and the convergence becomes quadratic.
    void update_shift(int level, double shift, double alpha, double ft, double mu, bool retried) {
        if (level > 2) return;
        const Eigen::VectorXd Hd = H_.selfadjointView<Eigen::Upper>() * d_;
        const double pred = -(alpha * g_.dot(d_) + 0.5 * alpha * alpha * d_.dot(Hd));
        const double actual = fq_ - ft;
        const double rho = pred > 1e-12 * (1 + std::abs(fq_)) ? actual / pred : 1.0;
        if (alpha == 1 && rho > 0.5) mu_lm_ = std::max(mu_floor_, shift / 10);
        else if (alpha < 1 || rho < 0.25) mu_lm_ = std::max(4 * shift, mu_floor_);
        else mu_lm_ = shift;
        // After a retry the ladder's escalated shift damps the whole Hessian; the next LDL^T iteration grows from
        // its own shift instead, as after a backtracked step.
        if (retried) mu_lm_ = std::max(4 * mu, mu_floor_);
    }

    const SolverOptions& opt_;
    NewtonLadder& ladder_;
    ModifiedLdlRung* ldl_;
    const double warm_shift_rel_;
    NewtonTrace& trace_;
    const std::vector<LinearSolver*> factorizations_;  // the ladder's, analyzed for H_'s pattern
    long version_ = 0;                                  // the objective's pattern_version() that H_ has
    std::unique_ptr<NonlinearElimination> ne_;
    Eigen::SparseMatrix<double> H_;
    Eigen::VectorXd g_, gt_, d_, qt_;
    std::vector<double> energies_, diag_;
    double fq_ = 0, gmax_ = 0, floor_ = 0, local_tol_ = 0;
    double mu_floor_ = 0; // the shift's floor, kMuFloor x median diag of this iteration's H
    double mu_lm_ = -1;   // Levenberg-Marquardt shift, adapted from the model agreement of each step
    double dm_last_ = 0;  // mean diag of the last iteration's H (the shift is kept relative to it)
    int start_rung_ = 0;
    bool projected_ = false, eliminating_ = false;
};
}  // namespace

SolverCapabilities NewtonSolver::capabilities() const {
    SolverCapabilities c;
    c.hessian = c.ldl = c.projected = c.eliminate = c.warm_start = c.newton_steps = c.shares_factorization = true;
    c.follows_pattern = true;
    return c;
}

LinearSolver* NewtonSolver::factorization_for(const Eigen::SparseMatrix<double>& pattern) {
    return &analyzed_for(pattern);
}

SolveResult NewtonSolver::minimize(Objective& f, Eigen::VectorXd& q) {
    SolverRun run(name(), opt_, f, q);
    trace_.history.clear(), trace_.rungs.clear(), trace_.shifts.clear();
    const int n = f.size();
    double t_analysis = 0;
    CholmodLLT& llt = analyzed_for(f.hessian_pattern(), &t_analysis);
    run.result().timings.factorization += t_analysis;
    if (opt_.ldl && n > 0 && !ldl_) {
        const auto t0 = Clock::now();
        ldl_ = std::make_unique<CholmodLDL>();
        ldl_->analyze(f.hessian_pattern());
        run.result().timings.factorization += seconds_since(t0);
    }
    NewtonLadder ladder(llt, opt_.ldl ? ldl_.get() : nullptr, !opt_.projected);
    std::vector<LinearSolver*> lins{&llt};
    if (opt_.ldl && ldl_) lins.push_back(ldl_.get());
    Newton method(opt_, ladder, ladder.modified_ldl(), trace_.shift_rel, trace_, lins);
    const long version = f.pattern_version();
    SolveResult r = run_iterations(run, method, q);
    // The pattern changed during the solve: the factorizations were analyzed anew for patterns analyzed_ does not
    // name, so the next solve or factorization_for() analyzes afresh.
    if (f.pattern_version() != version) llt_.reset(), ldl_.reset(), analyzed_ = Eigen::SparseMatrix<double>();
    return r;
}

}  // namespace fibernet
