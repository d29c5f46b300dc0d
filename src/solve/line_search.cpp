#include "fibernet/solve/line_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fibernet/util/error.hpp"

namespace fibernet {

void LineSearchParams::check(const std::string& where) const {
    const std::string w = where;
    check_value(c1 > 0 && c1 < 0.5, c1, w, "line_search.c1", "must lie in (0, 0.5)");
    check_value(c2 > c1 && c2 < 1, c2, w, "line_search.c2", "must lie in (c1, 1)");
    check_value(max_evals >= 2, max_evals, w, "line_search.max_evals", "must be >= 2");
    check_value(min_step > 0 && min_step < 1, min_step, w, "line_search.min_step", "must lie in (0, 1)");
    check_value(max_step > 1, max_step, w, "line_search.max_step", "must be > 1");
    check_value(extrapolate > 1, extrapolate, w, "line_search.extrapolate", "must be > 1");
    check_value(roundoff >= 0 && roundoff < 1e-3, roundoff, w, "line_search.roundoff", "must lie in [0, 1e-3)");
}

std::string to_string(LineSearchOutcome o) {
    switch (o) {
        case LineSearchOutcome::Ok: return "ok";
        case LineSearchOutcome::Decrease: return "decrease";
        case LineSearchOutcome::NotDescent: return "not_descent";
        case LineSearchOutcome::Failed: return "failed";
        case LineSearchOutcome::NonFinite: return "non_finite";
    }
    return "?";
}

StrongWolfeLineSearch::StrongWolfeLineSearch(const LineSearchParams& p) : p_(p) { p_.check("line search"); }

namespace {
// Minimizer of the cubic through (a, fa, da), (b, fb, db), or NaN if it has none.
double cubic_min(double a, double fa, double da, double b, double fb, double db) {
    const double d1 = da + db - 3 * (fa - fb) / (a - b);
    const double disc = d1 * d1 - da * db;
    if (!(disc >= 0)) return std::numeric_limits<double>::quiet_NaN();
    const double d2 = (b > a ? 1.0 : -1.0) * std::sqrt(disc);
    const double den = db - da + 2 * d2;
    if (den == 0) return std::numeric_limits<double>::quiet_NaN();
    return b - (b - a) * (db + d2 - d1) / den;
}
}  // namespace

LineSearchResult StrongWolfeLineSearch::search(Objective& f, const Eigen::VectorXd& x0, double f0,
                                               const Eigen::VectorXd& g0, const Eigen::VectorXd& d,
                                               double alpha_init, Eigen::VectorXd& x, Eigen::VectorXd& g, double f_scale) const {
    LineSearchResult r;
    const double dphi0 = g0.dot(d);
    x = x0, g = g0;
    if (!(dphi0 < 0)) {
        r.outcome = LineSearchOutcome::NotDescent;
        return r;
    }
    const double eps_f = p_.roundoff * std::max(std::abs(f0), std::abs(f_scale));
    const double a_min = p_.min_step * alpha_init;
    // Sufficient decrease: Armijo, or (round-off regime) approximate Wolfe.
    auto decrease = [&](double a, double fa, double dphi) {
        if (fa <= f0 + p_.c1 * a * dphi0) return true;
        return p_.roundoff > 0 && fa <= f0 + eps_f && dphi <= (2 * p_.c1 - 1) * dphi0;
    };
    auto curvature = [&](double dphi) { return std::abs(dphi) <= -p_.c2 * dphi0; };

    Eigen::VectorXd xt(x0.size()), gt(x0.size());
    // Best point with sufficient decrease so far (the fallback when the budget runs out).
    double best_a = 0, best_f = f0;
    Eigen::VectorXd best_x, best_g;
    auto eval = [&](double a, double& fa, double& dphi) {
        xt = x0 + a * d;
        fa = f.gradient(xt, gt);
        ++r.evals;
        const bool finite = std::isfinite(fa) && gt.allFinite();
        dphi = finite ? gt.dot(d) : std::numeric_limits<double>::quiet_NaN();
        if (!finite) fa = std::numeric_limits<double>::infinity();
        if (finite && decrease(a, fa, dphi) && fa < best_f) best_a = a, best_f = fa, best_x = xt, best_g = gt;
        return finite;
    };
    auto accept = [&](double a, double fa, LineSearchOutcome o) {
        r.outcome = o, r.alpha = a, r.f = fa;
        x = xt, g = gt;
        return r;
    };
    auto fallback = [&](LineSearchOutcome if_none) {
        if (best_a > 0) {
            r.outcome = LineSearchOutcome::Decrease, r.alpha = best_a, r.f = best_f;
            x = best_x, g = best_g;
        } else {
            r.outcome = if_none;
            x = x0, g = g0;
        }
        return r;
    };

    // lo: a step with sufficient decrease and f below the other end (starts at 0); hi: the other end.
    double lo = 0, f_lo = f0, d_lo = dphi0;
    double hi = 0, f_hi = 0, d_hi = 0;
    bool hi_finite = false, any_finite = false;
    double a = std::min(std::max(alpha_init, 0.0), p_.max_step);
    if (!(a > 0)) a = 1;

    // Phase 1: bracket.
    bool bracketed = false;
    while (!bracketed) {
        if (r.evals >= p_.max_evals) return fallback(LineSearchOutcome::Failed);
        double fa, da;
        const bool fin = eval(a, fa, da);
        any_finite |= fin;
        if (!fin) {  // too far: bracket [lo, a] with an unusable upper end
            hi = a, hi_finite = false, bracketed = true;
            break;
        }
        if (!decrease(a, fa, da) || (r.evals > 1 && fa >= f_lo)) {
            hi = a, f_hi = fa, d_hi = da, hi_finite = true, bracketed = true;
            break;
        }
        if (curvature(da)) return accept(a, fa, LineSearchOutcome::Ok);
        if (da >= 0) {  // passed the minimum: bracket [a, lo]
            hi = lo, f_hi = f_lo, d_hi = d_lo, hi_finite = true;
            lo = a, f_lo = fa, d_lo = da;
            bracketed = true;
            break;
        }
        // Still descending with decrease: extrapolate.
        lo = a, f_lo = fa, d_lo = da;
        if (a >= p_.max_step) return accept(a, fa, LineSearchOutcome::Decrease);
        a = std::min(a * p_.extrapolate, p_.max_step);
    }

    // Phase 2: zoom inside [lo, hi] (hi may lie on either side of lo).
    while (true) {
        if (r.evals >= p_.max_evals) return fallback(any_finite ? LineSearchOutcome::Failed : LineSearchOutcome::NonFinite);
        const double width = std::abs(hi - lo);
        if (width <= a_min || width <= 1e-16 * std::max(std::abs(lo), std::abs(hi)))
            return fallback(any_finite ? LineSearchOutcome::Failed : LineSearchOutcome::NonFinite);
        double t = std::numeric_limits<double>::quiet_NaN();
        if (hi_finite) t = cubic_min(lo, f_lo, d_lo, hi, f_hi, d_hi);
        const double left = std::min(lo, hi), right = std::max(lo, hi);
        const double margin = 0.1 * width;
        if (!std::isfinite(t) || t < left + margin || t > right - margin) t = 0.5 * (lo + hi);
        // A non-finite far end means a step far outside the domain (e.g. a Hessian-scaled step along a floppy
        // mode): shrink by 10 rather than 2 towards the good end.
        if (!hi_finite) t = lo + 0.1 * (hi - lo);
        double ft, dt;
        const bool fin = eval(t, ft, dt);
        any_finite |= fin;
        if (!fin) {
            hi = t, hi_finite = false;
            continue;
        }
        if (!decrease(t, ft, dt) || ft >= f_lo) {
            hi = t, f_hi = ft, d_hi = dt, hi_finite = true;
            continue;
        }
        if (curvature(dt)) return accept(t, ft, LineSearchOutcome::Ok);
        if (dt * (hi - lo) >= 0) hi = lo, f_hi = f_lo, d_hi = d_lo, hi_finite = true;
        lo = t, f_lo = ft, d_lo = dt;
    }
}

}  // namespace fibernet
