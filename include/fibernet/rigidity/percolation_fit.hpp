#pragma once
// Fits for the percolation analysis (issue 4 part 4; seed figure 3.6 and table 3.1):
//  - the spanning probability P(q) at one L as a probit curve P = Phi((q - q_half) / w), by binomial maximum
//    likelihood (Fisher scoring); q_half is the inflection point, its error from the inverse Fisher information;
//  - the finite-size scaling q_half(L) = q_c + A L^(-1/nu) by weighted least squares: a scan over 1/nu with
//    (q_c, A) linear at each value, errors from the Jacobian at the optimum, scaled by chi2/dof when that is > 1;
//  - nu from the probit widths, width(L) = c L^(-1/nu) (weighted least squares of log width against log L), and
//    q_c from the q_1/2 shifts with nu held at that estimate, its uncertainty carried into q_c.
#include <limits>
#include <string>
#include <vector>

namespace fibernet {

struct ProbitFit {
    bool ok = false;               // false: too few points in the transition or no convergence
    double q_half = 0, q_half_err = 0;
    double width = 0, width_err = 0;
    int points = 0;
};

// q values, spanning counts and sample counts per q.
ProbitFit fit_spanning_probability(const std::vector<double>& q, const std::vector<int>& hits, const std::vector<int>& n);

struct ScalingFit {
    bool ok = false;
    double q_c = 0, q_c_err = 0, A = 0, A_err = 0, nu = 0, nu_err = 0;
    double chi2 = 0;
    int dof = 0;
    // Only from fit_finite_size_scaling_width_nu: q_c_err = sqrt(q_c_err_stat^2 + q_c_err_nu^2), the first from the
    // q_1/2 errors at nu held fixed, the second from the uncertainty of nu (same for A).
    double q_c_err_stat = 0, q_c_err_nu = 0, A_err_stat = 0, A_err_nu = 0;
};

// Needs >= 4 sizes (3 parameters).
ScalingFit fit_finite_size_scaling(const std::vector<double>& L, const std::vector<double>& q_half,
                                   const std::vector<double>& err);

// The same with nu held at a known value (linear in q_c and A; nu_err = 0); needs >= 3 sizes. When the
// finite-size shifts are small against the error bars, a free nu is undetermined while q_c still is.
ScalingFit fit_finite_size_scaling_fixed_nu(const std::vector<double>& L, const std::vector<double>& q_half,
                                            const std::vector<double>& err, double nu);

// Finite-size scaling of the probit widths, width(L) = c L^(-1/nu) (the transition narrows as L^(-1/nu)): weighted
// least squares of y = log(width) against log(L), y's error width_err / width; slope -1/nu. Errors from the
// inverse normal matrix, scaled by sqrt(chi2/dof) when chi2/dof > 1 (not with 2 sizes: dof = 0); nu_err from the
// delta method, inv_nu_err / inv_nu^2. Entries with L, width or width_err not finite and > 0 are skipped (a failed
// probit fit). ok = false and `reason` says why, with every value NaN, when the inputs differ in length, fewer
// than 2 sizes remain or all remaining sizes are equal; ok = false with nu, nu_err NaN (inv_nu, inv_nu_err, chi2
// filled) when the widths do not fall with L (1/nu <= 0).
struct WidthScalingFit {
    bool ok = false;
    std::string reason;  // why there is no fit; empty when ok
    double inv_nu = std::numeric_limits<double>::quiet_NaN(), inv_nu_err = std::numeric_limits<double>::quiet_NaN();
    double nu = std::numeric_limits<double>::quiet_NaN(), nu_err = std::numeric_limits<double>::quiet_NaN();
    double c = std::numeric_limits<double>::quiet_NaN(), c_err = std::numeric_limits<double>::quiet_NaN();  // width at L = 1
    double chi2 = std::numeric_limits<double>::quiet_NaN();
    int dof = 0, points = 0;  // points: sizes used
};

WidthScalingFit fit_width_scaling(const std::vector<double>& L, const std::vector<double>& width,
                                  const std::vector<double>& width_err);

// q_1/2(L) = q_c + A L^(-1/nu) with nu held at the width estimate w.nu (needs w.ok and >= 3 sizes). The
// uncertainty of nu is carried into q_c and A by refitting at 1/nu = w.inv_nu +- w.inv_nu_err (one standard error
// of the fitted quantity; both must stay > 0) and adding half the spread in quadrature to the fixed-nu error.
// nu, nu_err are w's.
ScalingFit fit_finite_size_scaling_width_nu(const std::vector<double>& L, const std::vector<double>& q_half,
                                            const std::vector<double>& err, const WidthScalingFit& w);

}  // namespace fibernet
