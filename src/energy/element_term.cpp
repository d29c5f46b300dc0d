#include "fibernet/energy/element_term.hpp"

#include <Eigen/Eigenvalues>

namespace fibernet {

ElementFrame::ElementFrame(const Model& m, const std::vector<int>& dof, const Eigen::VectorXd& u,
                           const Eigen::Matrix2d& F, const Eigen::Matrix2d& dF, bool strain, bool comoving)
    : m_(m), dof_(dof), u_(u), dF_(dF), strain_(strain), comoving_(strain && comoving) {
    const Eigen::Matrix2d B0 = m.box.B0();
    FmIB0_ = (F - Eigen::Matrix2d::Identity()) * B0;
    dB_ = dF * B0;
    V_ = comoving_ ? Eigen::Matrix2d(dF * F.inverse()) : Eigen::Matrix2d::Zero();
}

void ElementFrame::edge(int i, int j, const Eigen::Vector2i& n, const Eigen::Vector2d& d0, Eigen::Vector2d& d,
                        Eigen::Vector2d& c) const {
    d = d0 + FmIB0_ * n.cast<double>() + (u_.segment<2>(2 * j) - u_.segment<2>(2 * i));
    if (!strain_) return;
    if (comoving_) {
        c = V_ * d;
        return;
    }
    c = dB_ * n.cast<double>();
    if (dof_[2 * j] < 0) c += dF_ * m_.x.segment<2>(2 * j);
    if (dof_[2 * i] < 0) c -= dF_ * m_.x.segment<2>(2 * i);
}

namespace {
template <int M>
Eigen::Matrix<double, M, M> project(const Eigen::Matrix<double, M, M>& h) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, M, M>> es(h);
    Eigen::Matrix<double, M, 1> ev = es.eigenvalues().cwiseMax(0.0);
    return es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
}
}  // namespace

Eigen::Matrix2d project_psd(const Eigen::Matrix2d& h) { return project<2>(h); }
Eigen::Matrix4d project_psd(const Eigen::Matrix4d& h) { return project<4>(h); }

}  // namespace fibernet
