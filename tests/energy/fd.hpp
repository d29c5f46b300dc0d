#pragma once
// Finite-difference helpers for derivative checks. Central differences have O(h^2) truncation error and
// O(eps/h) round-off; with h ~ 1e-6 relative both are ~1e-10 relative, so a tolerance of 1e-6 relative
// (to the largest entry) catches any wrong term (errors of O(1)) with a wide margin.
#include <Eigen/Core>
#include <functional>

namespace fdtest {

inline Eigen::VectorXd fd_gradient(const std::function<double(const Eigen::VectorXd&)>& f, Eigen::VectorXd x,
                                   double h) {
    Eigen::VectorXd g(x.size());
    for (int i = 0; i < x.size(); ++i) {
        const double xi = x[i];
        x[i] = xi + h;
        const double fp = f(x);
        x[i] = xi - h;
        const double fm = f(x);
        x[i] = xi;
        g[i] = (fp - fm) / (2 * h);
    }
    return g;
}

inline Eigen::MatrixXd fd_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, Eigen::VectorXd x,
                                   double h) {
    const Eigen::VectorXd f0 = f(x);
    Eigen::MatrixXd J(f0.size(), x.size());
    for (int i = 0; i < x.size(); ++i) {
        const double xi = x[i];
        x[i] = xi + h;
        const Eigen::VectorXd fp = f(x);
        x[i] = xi - h;
        const Eigen::VectorXd fm = f(x);
        x[i] = xi;
        J.col(i) = (fp - fm) / (2 * h);
    }
    return J;
}

// max |a - b| / max(max|b|, floor)
inline double rel_err(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor = 1e-8) {
    return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), floor);
}

}  // namespace fdtest
