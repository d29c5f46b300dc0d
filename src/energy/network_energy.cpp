#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/network_region.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "fibernet/energy/bend.hpp"

namespace fibernet {

NetworkEnergy::NetworkEnergy(const Model& model, EnergyParams params) : model_(model), params_(params) {
    const int n = model.num_nodes();
    dof_.assign(2 * n, -1);
    for (int i = 0; i < n; ++i)
        if (model.fixed.empty() || !model.fixed[i]) dof_[2 * i] = ndof_++, dof_[2 * i + 1] = ndof_++;
    stretch_ = std::make_unique<StretchTerm>(model, params.stretch);
    bend_ = std::make_unique<BendTerm>(model);
    assembly_ = std::make_unique<ElementAssembly>(std::vector<const ElementTerm*>{stretch_.get(), bend_.get()}, dof_,
                                                  ndof_);
}

std::vector<std::string> NetworkEnergy::term_names() const { return {stretch_->name(), bend_->name()}; }

Eigen::VectorXd NetworkEnergy::dofs(const Eigen::VectorXd& x) const {
    Eigen::VectorXd q(ndof_);
    for (size_t k = 0; k < dof_.size(); ++k)
        if (dof_[k] >= 0) q[dof_[k]] = x[k] - model_.x[k];
    return q;
}

Eigen::VectorXd NetworkEnergy::dofs_of_displacements(const Eigen::VectorXd& u) const {
    if (u.size() != static_cast<Eigen::Index>(dof_.size()))
        throw std::invalid_argument("NetworkEnergy::dofs_of_displacements: u has " + std::to_string(u.size()) +
                                    " entries, the model " + std::to_string(dof_.size()) + " node coordinates");
    Eigen::VectorXd q(ndof_);
    for (size_t k = 0; k < dof_.size(); ++k)
        if (dof_[k] >= 0) q[dof_[k]] = u[k];
    return q;
}

namespace {
// Eigen checks no sizes with NDEBUG: a q of another model would read past its end.
void check_size(const Eigen::VectorXd& q, int ndof, const char* where) {
    if (q.size() != ndof)
        throw std::invalid_argument(std::string(where) + ": q has " + std::to_string(q.size()) +
                                    " coordinates, the model " + std::to_string(ndof) + " free ones");
}
}  // namespace

Eigen::VectorXd NetworkEnergy::positions(const Eigen::VectorXd& q, const Eigen::Matrix2d& F) const {
    check_size(q, ndof_, "NetworkEnergy::positions");
    Eigen::VectorXd x(dof_.size());
    for (int i = 0; i < model_.num_nodes(); ++i) {
        if (dof_[2 * i] >= 0) {
            x[2 * i] = model_.x[2 * i] + q[dof_[2 * i]], x[2 * i + 1] = model_.x[2 * i + 1] + q[dof_[2 * i + 1]];
        } else {
            x.segment<2>(2 * i) = F * model_.x.segment<2>(2 * i);
        }
    }
    return x;
}

Eigen::VectorXd NetworkEnergy::affine_map(const Eigen::VectorXd& q, const Eigen::Matrix2d& F_old,
                                          const Eigen::Matrix2d& F_new) const {
    const Eigen::Matrix2d M = F_new * F_old.inverse();
    Eigen::VectorXd x = positions(q, F_old);
    for (int i = 0; i < model_.num_nodes(); ++i) x.segment<2>(2 * i) = M * x.segment<2>(2 * i).eval();
    return dofs(x);
}

Eigen::VectorXd NetworkEnergy::displacements(const Eigen::VectorXd& q, const Eigen::Matrix2d& F) const {
    // u = x - x_ref: q for free nodes, (F - I) x_ref for fixed ones.
    check_size(q, ndof_, "NetworkEnergy::displacements");
    Eigen::VectorXd u(dof_.size());
    const Eigen::Matrix2d FmI = F - Eigen::Matrix2d::Identity();
    for (int i = 0; i < model_.num_nodes(); ++i) {
        if (dof_[2 * i] >= 0) u[2 * i] = q[dof_[2 * i]], u[2 * i + 1] = q[dof_[2 * i + 1]];
        else u.segment<2>(2 * i) = FmI * model_.x.segment<2>(2 * i);
    }
    return u;
}

void NetworkEnergy::displacement_of(int i, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                                    Eigen::VectorXd& u) const {
    if (dof_[2 * i] >= 0) u[2 * i] = q[dof_[2 * i]], u[2 * i + 1] = q[dof_[2 * i + 1]];
    else u.segment<2>(2 * i) = (F - Eigen::Matrix2d::Identity()) * model_.x.segment<2>(2 * i);
}

namespace {
// One element of term t at displacements u (no strain), its gradient and Hessian on the M local coordinates.
template <int M>
double one_element(const ElementTerm& t, int e, const ElementFrame& frame, Eigen::Matrix<double, M, 1>* g,
                   Eigen::Matrix<double, M, M>* H, bool psd) {
    ElementWant want;
    want.gradient = g, want.hessian = H, want.psd = psd;
    ElementResult r;
    t.evaluate(e, frame, want, r);
    if (g) *g = r.gradient.head<M>();
    if (H) *H = r.hessian.topLeftCorner<M, M>();
    return r.energy;
}
}  // namespace

double NetworkEnergy::segment_term(int e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F, Eigen::Vector4d* g,
                                   Eigen::Matrix4d* H, bool psd) const {
    return one_element<4>(*stretch_, e, ElementFrame(model_, dof_, u, F, Eigen::Matrix2d::Zero(), false, false), g, H,
                          psd);
}

double NetworkEnergy::hinge_term(int e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F,
                                 Eigen::Matrix<double, 6, 1>* g, Eigen::Matrix<double, 6, 6>* H, bool psd) const {
    return one_element<6>(*bend_, e, ElementFrame(model_, dof_, u, F, Eigen::Matrix2d::Zero(), false, false), g, H,
                          psd);
}

void NetworkEnergy::evaluate(const Eigen::VectorXd& q, const Eigen::Matrix2d& F, const Eigen::Matrix2d& dF,
                             unsigned want, EnergyEval& out, Eigen::SparseMatrix<double>* H) const {
    ElementWant w;
    w.gradient = want & kGradient, w.hessian = want & kHessian, w.strain = want & kStrain, w.psd = want & kProjectPSD;
    double* hv = nullptr;
    if (w.hessian) {
        if (!H || H->nonZeros() != hessian_pattern().nonZeros())
            throw std::logic_error("Hessian lacks the energy's pattern");
        hv = H->valuePtr();
    }
    const Eigen::VectorXd u = displacements(q, F);
    const ElementFrame frame(model_, dof_, u, F, dF, w.strain, want & kComoving);
    ElementAssembly::Sums sums;
    assembly_->assemble(frame, w, sums, w.gradient ? &out.gradient : nullptr, w.strain ? &out.d2E_dqdt : nullptr, hv);
    out.terms = sums.energy;
    out.stretch = sums.energy[0], out.bend = sums.energy[1];
    out.energy = out.stretch + out.bend;
    out.dE_dt = sums.dE_dt, out.d2E_dt2 = sums.d2E_dt2, out.d2E_dt2_size = sums.d2E_dt2_size;
}

std::unique_ptr<Objective> StrainedEnergy::restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) {
    if (!incidence_) incidence_ = std::make_shared<const NodeElements>(node_elements(e_));
    return std::make_unique<NetworkRegion>(e_, F_, *incidence_, q, coords);
}

double StrainedEnergy::value(const Eigen::VectorXd& q) {
    e_.evaluate(q, F_, Eigen::Matrix2d::Zero(), kValue, eval_);
    return eval_.energy;
}

double StrainedEnergy::gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) {
    e_.evaluate(q, F_, Eigen::Matrix2d::Zero(), kGradient, eval_);
    g.swap(eval_.gradient);
    return eval_.energy;
}

double StrainedEnergy::hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                               bool project) {
    e_.evaluate(q, F_, Eigen::Matrix2d::Zero(), kGradient | kHessian | (project ? kProjectPSD : 0u), eval_, &H);
    g.swap(eval_.gradient);
    return eval_.energy;
}

}  // namespace fibernet
