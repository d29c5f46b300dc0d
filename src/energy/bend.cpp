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

}  // namespace fibernet
