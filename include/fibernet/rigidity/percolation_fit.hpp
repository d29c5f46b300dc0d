#pragma once
// Fits for the percolation analysis (issue 4 part 4; seed figure 3.6 and table 3.1):
//  - the spanning probability P(q) at one L as a probit curve P = Phi((q - q_half) / w), by binomial maximum
//    likelihood (Fisher scoring); q_half is the inflection point, its error from the inverse Fisher information;
//  - the finite-size scaling q_half(L) = q_c + A L^(-1/nu) by weighted least squares: a scan over 1/nu with
//    (q_c, A) linear at each value, errors from the Jacobian at the optimum, scaled by chi2/dof when that is > 1.
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
};

// Needs >= 4 sizes (3 parameters).
ScalingFit fit_finite_size_scaling(const std::vector<double>& L, const std::vector<double>& q_half,
                                   const std::vector<double>& err);

// The same with nu held at a known value (linear in q_c and A; nu_err = 0); needs >= 3 sizes. When the
// finite-size shifts are small against the error bars, a free nu is undetermined while q_c still is.
ScalingFit fit_finite_size_scaling_fixed_nu(const std::vector<double>& L, const std::vector<double>& q_half,
                                            const std::vector<double>& err, double nu);

}  // namespace fibernet
