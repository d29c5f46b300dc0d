#include "fibernet/rigidity/percolation_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace fibernet {

ProbitFit fit_spanning_probability(const std::vector<double>& q, const std::vector<int>& hits, const std::vector<int>& n) {
    ProbitFit f;
    const int m = static_cast<int>(q.size());
    f.points = m;
    int inside = 0;  // points strictly between 0 and 1
    long total = 0, total_hits = 0;
    for (int i = 0; i < m; ++i) inside += hits[i] > 0 && hits[i] < n[i], total += n[i], total_hits += hits[i];
    if (m < 3 || total_hits == 0 || total_hits == total) return f;
    const double qmin = *std::min_element(q.begin(), q.end()), qmax = *std::max_element(q.begin(), q.end());
    // Start at the empirical crossing of P = 1/2 with a width of a tenth of the range: a start far from the
    // transition sees almost no information and Newton steps from there run away.
    std::vector<int> order(m);
    for (int i = 0; i < m; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int x, int y) { return q[x] < q[y]; });
    double mid = 0.5 * (qmin + qmax);
    for (int k = 1; k < m; ++k) {
        const int i = order[k - 1], j = order[k];
        const double pi = double(hits[i]) / n[i], pj = double(hits[j]) / n[j];
        if (pi < 0.5 && pj >= 0.5) {
            mid = q[i] + (0.5 - pi) / (pj - pi) * (q[j] - q[i]);
            break;
        }
    }
    double b = 10 / std::max(qmax - qmin, 1e-9), a = -b * mid;
    auto loglik = [&](double a_, double b_) {
        double l = 0;
        for (int i = 0; i < m; ++i) {
            const double eta = a_ + b_ * q[i];
            const double p = std::clamp(0.5 * std::erfc(-eta / std::sqrt(2.0)), 1e-300, 1 - 1e-16);
            l += hits[i] * std::log(p) + (n[i] - hits[i]) * std::log1p(-p);
        }
        return l;
    };
    Eigen::Matrix2d info;
    bool converged = false;
    for (int it = 0; it < 200 && !converged; ++it) {
        Eigen::Vector2d score = Eigen::Vector2d::Zero();
        info.setZero();
        for (int i = 0; i < m; ++i) {
            const double eta = a + b * q[i];
            const double p = std::clamp(0.5 * std::erfc(-eta / std::sqrt(2.0)), 1e-300, 1 - 1e-16);
            const double phi = std::exp(-0.5 * eta * eta) / std::sqrt(2 * M_PI);
            const double y = hits[i], N = n[i];
            const double g = phi * (y / p - (N - y) / (1 - p));  // d loglik / d eta
            const double w = N * phi * phi / (p * (1 - p));       // Fisher information in eta
            const Eigen::Vector2d x(1, q[i]);
            score += g * x;
            info += w * x * x.transpose();
        }
        Eigen::Vector2d step = info.ldlt().solve(score);
        if (!step.allFinite()) return f;
        // Fisher scoring with step halving until the likelihood does not decrease.
        const double l0 = loglik(a, b);
        double t = 1;
        while (t > 1e-6 && !(loglik(a + t * step(0), b + t * step(1)) >= l0 - 1e-12)) t *= 0.5;
        a += t * step(0), b += t * step(1);
        converged = t * std::abs(step(1)) < 1e-9 * std::max(1.0, std::abs(b)) &&
                    t * std::abs(step(0)) < 1e-9 * std::max(1.0, std::abs(a));
    }
    if (!converged || b <= 0 || inside < 1) return f;
    const Eigen::Matrix2d cov = info.inverse();
    const Eigen::Vector2d g(-1 / b, a / (b * b));  // gradient of q_half = -a / b
    f.q_half = -a / b;
    f.q_half_err = std::sqrt(std::max(0.0, g.dot(cov * g)));
    f.width = 1 / b;
    f.width_err = std::sqrt(std::max(0.0, cov(1, 1))) / (b * b);
    // An inflection point outside the sampled densities is an extrapolation, not a measurement; an error bar
    // wider than the spacing of the densities means the transition fell between two of them (too coarse a grid).
    double spacing = qmax - qmin;
    for (int k = 1; k < m; ++k)
        if (q[order[k]] > q[order[k - 1]]) spacing = std::min(spacing, q[order[k]] - q[order[k - 1]]);
    f.ok = std::isfinite(f.q_half) && std::isfinite(f.q_half_err) && f.q_half >= qmin && f.q_half <= qmax &&
           f.q_half_err < std::max(spacing, 0.1 * (qmax - qmin));
    return f;
}

ScalingFit fit_finite_size_scaling(const std::vector<double>& L, const std::vector<double>& y,
                                   const std::vector<double>& err) {
    ScalingFit f;
    const int m = static_cast<int>(L.size());
    if (m < 4) return f;
    auto linear = [&](double x, double& qc, double& A) {  // weighted least squares of y = qc + A L^-x
        Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
        Eigen::Vector2d r = Eigen::Vector2d::Zero();
        for (int i = 0; i < m; ++i) {
            const double w = 1 / (err[i] * err[i]);
            const Eigen::Vector2d b(1, std::pow(L[i], -x));
            M += w * b * b.transpose();
            r += w * y[i] * b;
        }
        const Eigen::Vector2d s = M.ldlt().solve(r);
        qc = s(0), A = s(1);
        double chi2 = 0;
        for (int i = 0; i < m; ++i) chi2 += std::pow((y[i] - qc - A * std::pow(L[i], -x)) / err[i], 2);
        return chi2;
    };
    double best = 1e300, bx = 0, bqc = 0, bA = 0;
    for (double x = 0.05; x <= 3.0 + 1e-12; x += 0.0005) {  // 1/nu from 0.05 to 3
        double qc, A;
        const double c = linear(x, qc, A);
        if (c < best) best = c, bx = x, bqc = qc, bA = A;
    }
    // Covariance from the Jacobian of (qc, A, x) at the optimum.
    Eigen::Matrix3d JWJ = Eigen::Matrix3d::Zero();
    for (int i = 0; i < m; ++i) {
        const double t = std::pow(L[i], -bx);
        const Eigen::Vector3d j(1, t, -bA * std::log(L[i]) * t);
        JWJ += j * j.transpose() / (err[i] * err[i]);
    }
    f.dof = m - 3;
    f.chi2 = best;
    const double scale = std::max(1.0, best / f.dof);
    const Eigen::Matrix3d cov = JWJ.inverse() * scale;
    f.q_c = bqc, f.A = bA, f.nu = 1 / bx;
    f.q_c_err = std::sqrt(std::max(0.0, cov(0, 0)));
    f.A_err = std::sqrt(std::max(0.0, cov(1, 1)));
    f.nu_err = std::sqrt(std::max(0.0, cov(2, 2))) / (bx * bx);
    f.ok = cov.allFinite() && bx > 0.05 && bx < 3.0;  // an optimum on the scan's edge is no fit
    return f;
}

ScalingFit fit_finite_size_scaling_fixed_nu(const std::vector<double>& L, const std::vector<double>& y,
                                            const std::vector<double>& err, double nu) {
    ScalingFit f;
    const int m = static_cast<int>(L.size());
    if (m < 3 || !(nu > 0)) return f;
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
    Eigen::Vector2d r = Eigen::Vector2d::Zero();
    for (int i = 0; i < m; ++i) {
        const double w = 1 / (err[i] * err[i]);
        const Eigen::Vector2d b(1, std::pow(L[i], -1 / nu));
        M += w * b * b.transpose();
        r += w * y[i] * b;
    }
    const Eigen::Vector2d s = M.ldlt().solve(r);
    f.q_c = s(0), f.A = s(1), f.nu = nu;
    for (int i = 0; i < m; ++i) f.chi2 += std::pow((y[i] - f.q_c - f.A * std::pow(L[i], -1 / nu)) / err[i], 2);
    f.dof = m - 2;
    const Eigen::Matrix2d cov = M.inverse() * std::max(1.0, f.chi2 / f.dof);
    f.q_c_err = std::sqrt(std::max(0.0, cov(0, 0)));
    f.A_err = std::sqrt(std::max(0.0, cov(1, 1)));
    f.ok = cov.allFinite();
    return f;
}

WidthScalingFit fit_width_scaling(const std::vector<double>& L, const std::vector<double>& width,
                                  const std::vector<double>& width_err) {
    WidthScalingFit f;
    if (L.size() != width.size() || L.size() != width_err.size()) {
        f.reason = "L, width and width_err differ in length";
        return f;
    }
    auto good = [](double v) { return std::isfinite(v) && v > 0; };
    std::vector<double> x, y, s;  // log L, log width, its standard error
    for (size_t i = 0; i < L.size(); ++i)
        if (good(L[i]) && good(width[i]) && good(width_err[i]))
            x.push_back(std::log(L[i])), y.push_back(std::log(width[i])), s.push_back(width_err[i] / width[i]);
    const int m = static_cast<int>(x.size());
    f.points = m;
    if (m < 2) {
        f.reason = "fewer than 2 sizes with a valid width (" + std::to_string(m) + ")";
        return f;
    }
    if (*std::max_element(x.begin(), x.end()) - *std::min_element(x.begin(), x.end()) < 1e-12) {
        f.reason = "all sizes equal";
        return f;
    }
    // y = b0 - b1 x: columns (1, -x).
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
    Eigen::Vector2d r = Eigen::Vector2d::Zero();
    for (int i = 0; i < m; ++i) {
        const double w = 1 / (s[i] * s[i]);
        const Eigen::Vector2d b(1, -x[i]);
        M += w * b * b.transpose();
        r += w * y[i] * b;
    }
    const Eigen::Vector2d sol = M.ldlt().solve(r);
    double chi2 = 0;
    for (int i = 0; i < m; ++i) chi2 += std::pow((y[i] - sol(0) + sol(1) * x[i]) / s[i], 2);
    f.dof = m - 2;
    f.chi2 = chi2;
    const Eigen::Matrix2d cov = M.inverse() * (f.dof > 0 ? std::max(1.0, chi2 / f.dof) : 1.0);
    if (!sol.allFinite() || !cov.allFinite()) {
        f.reason = "singular normal equations";
        return f;
    }
    f.inv_nu = sol(1);
    f.inv_nu_err = std::sqrt(std::max(0.0, cov(1, 1)));
    if (!(f.inv_nu > 0)) {
        f.reason = "the widths do not fall with L (1/nu = " + std::to_string(f.inv_nu) + ")";
        return f;
    }
    f.nu = 1 / f.inv_nu;
    f.nu_err = f.inv_nu_err / (f.inv_nu * f.inv_nu);
    f.c = std::exp(sol(0));
    f.c_err = f.c * std::sqrt(std::max(0.0, cov(0, 0)));
    f.ok = true;
    return f;
}

ScalingFit fit_finite_size_scaling_width_nu(const std::vector<double>& L, const std::vector<double>& q_half,
                                            const std::vector<double>& err, const WidthScalingFit& w) {
    if (!w.ok || !(w.inv_nu > 0) || !std::isfinite(w.inv_nu_err)) return {};
    const double lo = w.inv_nu - w.inv_nu_err, hi = w.inv_nu + w.inv_nu_err;
    if (!(lo > 0)) return {};  // one standard error reaches 1/nu = 0: the shifts do not define q_c
    ScalingFit f = fit_finite_size_scaling_fixed_nu(L, q_half, err, w.nu);
    const ScalingFit a = fit_finite_size_scaling_fixed_nu(L, q_half, err, 1 / hi),
                     b = fit_finite_size_scaling_fixed_nu(L, q_half, err, 1 / lo);
    if (!f.ok || !a.ok || !b.ok) return {};
    f.nu_err = w.nu_err;
    f.q_c_err_stat = f.q_c_err, f.A_err_stat = f.A_err;
    f.q_c_err_nu = 0.5 * std::abs(a.q_c - b.q_c), f.A_err_nu = 0.5 * std::abs(a.A - b.A);
    f.q_c_err = std::hypot(f.q_c_err_stat, f.q_c_err_nu);
    f.A_err = std::hypot(f.A_err_stat, f.A_err_nu);
    return f;
}

}  // namespace fibernet
