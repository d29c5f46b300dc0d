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

StretchTerm::StretchTerm(const Model& m, StretchLaw law)
    : m_(m), law_(law), k_(4 * m.aspect_ratio * m.aspect_ratio) {
    d0_.reserve(m.segments.size());
    for (const Segment& s : m.segments) d0_.push_back(rest_vector(m, s.d0, s.i, s.j, s.shift));
}

void StretchTerm::nodes(std::size_t e, int* out) const { out[0] = m_.segments[e].i, out[1] = m_.segments[e].j; }

void StretchTerm::evaluate(std::size_t e, const ElementFrame& frame, const ElementWant& want,
                           ElementResult& out) const {
    const Segment& s = m_.segments[e];
    Eigen::Vector2d d, c, gd;
    Eigen::Matrix2d Hd;
    frame.edge(s.i, s.j, s.shift, d0_[e], d, c);
    const bool g = want.gradient || want.strain, h = want.hessian || want.strain;
    out.energy = stretch_energy(d, s.l0, k_, law_, g ? &gd : nullptr, h ? &Hd : nullptr);
    if (want.gradient) out.gradient.head<4>() << -gd, gd;
    if (want.strain) {  // d(d)/dt = c: dE/dt = g.c, d2E/dt2 = c.H c, d2E/dx dt = +-H c
        out.dE_dt = gd.dot(c);
        out.d2E_dt2 = c.dot(Hd * c);
        const Eigen::Vector2d hc = Hd * c;
        out.d2E_dqdt.head<4>() << -hc, hc;
    }
    if (want.hessian) {
        const Eigen::Matrix2d hp = want.psd ? project_psd(Hd) : Hd;
        Eigen::Matrix4d hl;
        hl << hp, -hp, -hp, hp;
        out.hessian.topLeftCorner<4, 4>() = hl;
    }
}

}  // namespace fibernet
