#include "fibernet/energy/stretch.hpp"

#include <cmath>
#include <limits>

namespace fibernet {

void StretchLaw::eval(double eps, double& f, double& df, double& d2f) const {
    f = eps * eps, df = 2 * eps, d2f = 2;
    if (eps >= eps_star) return;
    const double u = 1 + eps, us = 1 + eps_star;
    if (u <= 0) {
        f = df = d2f = std::numeric_limits<double>::infinity();
        return;
    }
    const double k = us * us * us;
    const double du = u - us;
    f += k * (1 / u - 1 / us + du / (us * us) - du * du / (us * us * us));
    df += k * (-1 / (u * u) + 1 / (us * us) - 2 * du / (us * us * us));
    d2f += k * (2 / (u * u * u) - 2 / (us * us * us));
}

double stretch_energy(const Eigen::Vector2d& d, double l0, double k, const StretchLaw& law, Eigen::Vector2d* grad,
                      Eigen::Matrix2d* hess) {
    const double l = d.norm();
    const double eps = l / l0 - 1;
    double f, df, d2f;
    law.eval(eps, f, df, d2f);
    const double E = k * l0 * f;
    if (!grad && !hess) return E;
    // dE/dl = k f'(eps), d2E/dl2 = k f''(eps) / l0; dl/dd = n, d2l/dd2 = (I - n n^T) / l.
    const double El = k * df, Ell = k * d2f / l0;
    if (l == 0) {  // a collapsed segment: the softcore made E infinite; no direction is defined
        if (grad) grad->setConstant(std::numeric_limits<double>::quiet_NaN());
        if (hess) hess->setConstant(std::numeric_limits<double>::quiet_NaN());
        return E;
    }
    const Eigen::Vector2d n = d / l;
    if (grad) *grad = El * n;
    if (hess) *hess = Ell * n * n.transpose() + (El / l) * (Eigen::Matrix2d::Identity() - n * n.transpose());
    return E;
}

}  // namespace fibernet
