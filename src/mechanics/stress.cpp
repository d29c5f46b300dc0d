#include "fibernet/mechanics/stress.hpp"

#include <Eigen/LU>  // Box::area() uses determinant()

namespace fibernet {

Stress stress(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F) {
    Stress s;
    Box box = e.model().box;
    box.F = F;
    s.area = box.area();
    EnergyEval ev;
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            Eigen::Matrix2d dF = Eigen::Matrix2d::Zero();
            dF(a, b) = 1;
            e.evaluate(q, F, dF, kStrain, ev);
            s.P(a, b) = ev.dE_dt;
        }
    if (s.area > 0) s.sigma = s.P * F.transpose() / s.area;
    return s;
}

}  // namespace fibernet
