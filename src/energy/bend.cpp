#include "fibernet/energy/bend.hpp"

namespace fibernet {

double bend_energy(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double lt0, Eigen::Vector4d* grad,
                   Eigen::Matrix4d* hess) {
    const double la = a.norm(), lb = b.norm();
    const double c = a.dot(b) / (la * lb);
    const double k = 2 / lt0;
    // 1 - cos phi without cancellation for small angles: (|a||b| - a.b) = (a x b)^2 / (|a||b| + a.b) when a.b > 0.
    // Exact to round-off (the direct form loses all digits below phi ~ 1e-8 and can turn negative), which the
    // line searches need near an equilibrium where energy differences are tiny.
    const double ab = la * lb, dot = a.dot(b), cross = a.x() * b.y() - a.y() * b.x();
    const double one_minus_c = dot > 0 ? cross * cross / (ab * (ab + dot)) : 1 - c;
    const double E = k * one_minus_c;
    if (!grad && !hess) return E;
    // dc/da = b/(la lb) - c a/la^2 ; dc/db = a/(la lb) - c b/lb^2.
    const Eigen::Vector2d ca = b / (la * lb) - c * a / (la * la);
    const Eigen::Vector2d cb = a / (la * lb) - c * b / (lb * lb);
    if (grad) *grad << -k * ca, -k * cb;
    if (hess) {
        const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
        // d2c/da2 = -(a b^T + b a^T)/(la^3 lb) + 3 c a a^T/la^4 - c I/la^2 (and a <-> b);
        // d2c/da db = I/(la lb) - b b^T/(la lb^3) - a a^T/(la^3 lb) + c a b^T/(la^2 lb^2).
        const Eigen::Matrix2d abT = a * b.transpose();
        const Eigen::Matrix2d Haa = -(abT + abT.transpose()) / (la * la * la * lb) +
                                    3 * c * a * a.transpose() / (la * la * la * la) - c * I / (la * la);
        const Eigen::Matrix2d Hbb = -(abT + abT.transpose()) / (lb * lb * lb * la) +
                                    3 * c * b * b.transpose() / (lb * lb * lb * lb) - c * I / (lb * lb);
        const Eigen::Matrix2d Hab = I / (la * lb) - b * b.transpose() / (la * lb * lb * lb) -
                                    a * a.transpose() / (la * la * la * lb) + c * abT / (la * la * lb * lb);
        hess->block<2, 2>(0, 0) = -k * Haa;
        hess->block<2, 2>(2, 2) = -k * Hbb;
        hess->block<2, 2>(0, 2) = -k * Hab;
        hess->block<2, 2>(2, 0) = -k * Hab.transpose();
    }
    return E;
}

BendTerm::BendTerm(const Model& m) : m_(m) {
    d0_.reserve(2 * m.hinges.size());
    for (const Hinge& h : m.hinges) {
        d0_.push_back(rest_vector(m, h.d10, h.i, h.j, h.shift1));
        d0_.push_back(rest_vector(m, h.d20, h.j, h.k, h.shift2));
    }
}

void BendTerm::nodes(std::size_t e, int* out) const {
    const Hinge& h = m_.hinges[e];
    out[0] = h.i, out[1] = h.j, out[2] = h.k;
}

void BendTerm::evaluate(std::size_t e, const ElementFrame& frame, const ElementWant& want, ElementResult& out) const {
    const Hinge& h = m_.hinges[e];
    Eigen::Vector2d d1, d2, c1, c2;
    frame.edge(h.i, h.j, h.shift1, d0_[2 * e], d1, c1);
    frame.edge(h.j, h.k, h.shift2, d0_[2 * e + 1], d2, c2);
    Eigen::Vector4d g4;
    Eigen::Matrix4d H4;
    const bool g = want.gradient || want.strain, hh = want.hessian || want.strain;
    out.energy = bend_energy(d1, d2, h.lt0, g ? &g4 : nullptr, hh ? &H4 : nullptr);
    // (d1, d2) = A (x_i, x_j, x_k): the node gradient is A^T g4, the node Hessian A^T H4 A.
    if (want.gradient) out.gradient.head<6>() << -g4.head<2>(), g4.head<2>() - g4.tail<2>(), g4.tail<2>();
    if (want.strain) {
        Eigen::Vector4d c4;
        c4 << c1, c2;
        out.dE_dt = g4.dot(c4);
        out.d2E_dt2 = c4.dot(H4 * c4);
        const Eigen::Vector4d hc = H4 * c4;
        out.d2E_dqdt.head<6>() << -hc.head<2>(), hc.head<2>() - hc.tail<2>(), hc.tail<2>();
    }
    if (want.hessian) {
        Eigen::Matrix<double, 4, 6> A = Eigen::Matrix<double, 4, 6>::Zero();
        A.block<2, 2>(0, 0) = -Eigen::Matrix2d::Identity();
        A.block<2, 2>(0, 2) = Eigen::Matrix2d::Identity();
        A.block<2, 2>(2, 2) = -Eigen::Matrix2d::Identity();
        A.block<2, 2>(2, 4) = Eigen::Matrix2d::Identity();
        const Eigen::Matrix4d hp = want.psd ? project_psd(H4) : H4;
        const Eigen::Matrix<double, 6, 6> hl = A.transpose() * hp * A;
        out.hessian.topLeftCorner<6, 6>() = hl;
    }
}

}  // namespace fibernet
