#include "fibernet/rigidity/elastic_rigidity.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"

namespace fibernet {

namespace {
Eigen::MatrixXd dense_hessian(const NetworkEnergy& e, const Eigen::VectorXd& q, EnergyEval& ev, unsigned want) {
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    e.evaluate(q, Eigen::Matrix2d::Identity(), strain_direction(StrainKind::Shear), want | kHessian, ev, &H);
    Eigen::MatrixXd upper = Eigen::MatrixXd(H);
    Eigen::MatrixXd D = upper.selfadjointView<Eigen::Upper>();
    return D;
}

// Jacobi scaling S = W H W, W = diag(1 / sqrt(max(H_ii, 1))): a congruence with a positive diagonal matrix, so
// S has exactly the nullity of H (Sylvester's law of inertia), but the stiff stretching rows of very short
// segments no longer set the round-off of every eigenvalue (eps * lambda_max reached 1e-6 on networks with
// segments of 1e-4 ls, above any cut on the bending scale).
Eigen::VectorXd jacobi_weights(const Eigen::MatrixXd& H) {
    Eigen::VectorXd w(H.rows());
    for (int i = 0; i < H.rows(); ++i) w(i) = 1 / std::sqrt(std::max(H(i, i), 1.0));
    return w;
}
}  // namespace

HessianSpectrum hessian_spectrum(const Model& model, double cut) {
    HessianSpectrum out;
    out.cut = cut;
    NetworkEnergy e(model);
    if (e.num_dofs() == 0) return out;
    EnergyEval ev;
    const Eigen::MatrixXd D = dense_hessian(e, e.dofs(model.x), ev, kValue);
    const Eigen::VectorXd w = jacobi_weights(D);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(w.asDiagonal() * D * w.asDiagonal(), Eigen::EigenvaluesOnly);
    out.eigenvalues = es.eigenvalues();
    for (int i = 0; i < out.eigenvalues.size(); ++i) {
        const double l = out.eigenvalues(i);
        if (l <= cut) {
            ++out.nullity;
            out.largest_zero = std::max(out.largest_zero, std::abs(l));
        } else if (out.smallest_nonzero == 0) {
            out.smallest_nonzero = l;
        }
    }
    return out;
}

Model clamped_model(const ClampedNetwork& c, const DiscretizationParams& p) {
    Model m = discretize(c.net, p);
    for (const auto& pin : c.pins) {
        const auto& ch = m.chains[pin.fiber];
        m.fixed[pin.s == 0 ? ch.nodes.front() : ch.nodes.back()] = 1;
    }
    return m;
}

double clamped_shear_modulus(const Model& model, double cut) {
    NetworkEnergy e(model);
    EnergyEval ev;
    const Eigen::VectorXd q = e.dofs(model.x);
    if (e.num_dofs() == 0) {
        e.evaluate(q, Eigen::Matrix2d::Identity(), strain_direction(StrainKind::Shear), kStrain, ev);
        return ev.d2E_dt2 / model.box.reference_area();
    }
    const Eigen::MatrixXd D = dense_hessian(e, q, ev, kStrain);
    // In scaled coordinates x = W y: E_xt^T H^+ E_xt = c^T S^+ c with c = W E_xt (E_xt lies in the range of H
    // at a stress-free state, so the pseudo-inverse is the minimisation over the relaxed coordinates).
    const Eigen::VectorXd w = jacobi_weights(D);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(w.asDiagonal() * D * w.asDiagonal());
    const Eigen::VectorXd proj = es.eigenvectors().transpose() * w.cwiseProduct(ev.d2E_dqdt);
    double relax = 0;
    for (int i = 0; i < proj.size(); ++i)
        if (es.eigenvalues()(i) > cut) relax += proj(i) * proj(i) / es.eigenvalues()(i);
    return (ev.d2E_dt2 - relax) / model.box.reference_area();
}

}  // namespace fibernet
