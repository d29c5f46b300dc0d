#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/network_region.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>
#include <string>

#include "fibernet/energy/bend.hpp"
#include "fibernet/energy/sparse_pattern.hpp"

namespace fibernet {

namespace {
// Local upper-triangular pairs (a <= b) of an m x m element block, in row-major order.
template <int M>
constexpr int n_upper() { return M * (M + 1) / 2; }

// Slots for an element on nodes[0..K-1] (2K local coordinates), packed upper triangle (a <= b) in row order; unlike
// fibernet::element_slots (sparse_pattern.hpp), which fills full M x M blocks for the wet energies.
template <int K>
void packed_slots(const int* nodes, const std::vector<int>& dof, const Eigen::SparseMatrix<double>& P, int* out) {
    for (int a = 0; a < K; ++a)
        for (int b = a + 1; b < K; ++b)
            if (nodes[a] == nodes[b]) throw std::logic_error("an element uses one node twice");
    int s = 0;
    for (int a = 0; a < 2 * K; ++a)
        for (int b = a; b < 2 * K; ++b) {
            const int r = dof[2 * nodes[a / 2] + a % 2], c = dof[2 * nodes[b / 2] + b % 2];
            out[s++] = (r < 0 || c < 0) ? -1 : pattern_slot(P, std::min(r, c), std::max(r, c));
        }
}

template <int M>
void scatter(const Eigen::Matrix<double, M, M>& h, const int* slots, double* values) {
    int s = 0;
    for (int a = 0; a < M; ++a)
        for (int b = a; b < M; ++b, ++s)
            if (slots[s] >= 0) values[slots[s]] += h(a, b);
}

template <int M>
Eigen::Matrix<double, M, M> project_psd(const Eigen::Matrix<double, M, M>& h) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, M, M>> es(h);
    Eigen::Matrix<double, M, 1> ev = es.eigenvalues().cwiseMax(0.0);
    return es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
}
}  // namespace

NetworkEnergy::NetworkEnergy(const Model& model, EnergyParams params) : model_(model), params_(params) {
    const int n = model.num_nodes();
    dof_.assign(2 * n, -1);
    for (int i = 0; i < n; ++i)
        if (model.fixed.empty() || !model.fixed[i]) dof_[2 * i] = ndof_++, dof_[2 * i + 1] = ndof_++;

    // Node adjacency (pairs sharing an element), then the coordinate-level upper pattern column by column.
    std::vector<std::vector<int>> adj(n);
    auto link = [&](int i, int j) {
        adj[std::max(i, j)].push_back(std::min(i, j));  // column node keeps lower-numbered neighbours
    };
    for (int i = 0; i < n; ++i) adj[i].push_back(i);
    for (const auto& s : model.segments) link(s.i, s.j);
    for (const auto& h : model.hinges) link(h.i, h.j), link(h.j, h.k), link(h.i, h.k);
    std::vector<int> outer(ndof_ + 1, 0), inner;
    for (int J = 0; J < n; ++J) {
        auto& a = adj[J];
        std::sort(a.begin(), a.end());
        a.erase(std::unique(a.begin(), a.end()), a.end());
        for (int cj = 0; cj < 2; ++cj) {
            const int col = dof_[2 * J + cj];
            if (col < 0) continue;
            for (int I : a)
                for (int ci = 0; ci < 2; ++ci) {
                    const int row = dof_[2 * I + ci];
                    if (row >= 0 && row <= col) inner.push_back(row);
                }
            outer[col + 1] = static_cast<int>(inner.size());
        }
    }
    std::vector<double> zeros(inner.size(), 0.0);
    pattern_ = Eigen::Map<const Eigen::SparseMatrix<double>>(ndof_, ndof_, static_cast<Eigen::Index>(inner.size()),
                                                            outer.data(), inner.data(), zeros.data());
    pattern_.makeCompressed();

    // Rest vectors: exact ones from the discretization, else from the reference positions.
    const Eigen::Matrix2d B0 = model.box.B0();
    auto rest = [&](const Eigen::Vector2d& given, int i, int j, const Eigen::Vector2i& n) -> Eigen::Vector2d {
        if (given.allFinite()) return given;
        return model.x.segment<2>(2 * j) - model.x.segment<2>(2 * i) + B0 * n.cast<double>();
    };
    for (const auto& s : model.segments) seg_d0_.push_back(rest(s.d0, s.i, s.j, s.shift));
    for (const auto& h : model.hinges) {
        hinge_d0_.push_back(rest(h.d10, h.i, h.j, h.shift1));
        hinge_d0_.push_back(rest(h.d20, h.j, h.k, h.shift2));
    }

    seg_slots_.resize(n_upper<4>() * model.segments.size());
    for (size_t e = 0; e < model.segments.size(); ++e) {
        const int nodes[2] = {model.segments[e].i, model.segments[e].j};
        packed_slots<2>(nodes, dof_, pattern_, &seg_slots_[n_upper<4>() * e]);
    }
    hinge_slots_.resize(n_upper<6>() * model.hinges.size());
    for (size_t e = 0; e < model.hinges.size(); ++e) {
        const int nodes[3] = {model.hinges[e].i, model.hinges[e].j, model.hinges[e].k};
        packed_slots<3>(nodes, dof_, pattern_, &hinge_slots_[n_upper<6>() * e]);
    }
}

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

double NetworkEnergy::segment_term(int e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F, Eigen::Vector4d* g,
                                   Eigen::Matrix4d* H, bool psd) const {
    const Segment& s = model_.segments[e];
    const Eigen::Matrix2d FmIB0 = (F - Eigen::Matrix2d::Identity()) * model_.box.B0();
    const Eigen::Vector2d d = seg_d0_[e] + FmIB0 * s.shift.cast<double>() + (u.segment<2>(2 * s.j) - u.segment<2>(2 * s.i));
    Eigen::Vector2d gd;
    Eigen::Matrix2d Hd;
    const double E = stretch_energy(d, s.l0, 4 * model_.aspect_ratio * model_.aspect_ratio, params_.stretch,
                                    g ? &gd : nullptr, H ? &Hd : nullptr);
    if (g) *g << -gd, gd;
    if (H) {
        const Eigen::Matrix2d h = psd ? project_psd<2>(Hd) : Hd;
        *H << h, -h, -h, h;
    }
    return E;
}

double NetworkEnergy::hinge_term(int e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F,
                                 Eigen::Matrix<double, 6, 1>* g, Eigen::Matrix<double, 6, 6>* H, bool psd) const {
    const Hinge& h = model_.hinges[e];
    const Eigen::Matrix2d FmIB0 = (F - Eigen::Matrix2d::Identity()) * model_.box.B0();
    const Eigen::Vector2d d1 = hinge_d0_[2 * e] + FmIB0 * h.shift1.cast<double>() + (u.segment<2>(2 * h.j) - u.segment<2>(2 * h.i));
    const Eigen::Vector2d d2 = hinge_d0_[2 * e + 1] + FmIB0 * h.shift2.cast<double>() + (u.segment<2>(2 * h.k) - u.segment<2>(2 * h.j));
    Eigen::Vector4d g4;
    Eigen::Matrix4d H4;
    const double E = bend_energy(d1, d2, h.lt0, g ? &g4 : nullptr, H ? &H4 : nullptr);
    // d1 = x_j - x_i, d2 = x_k - x_j (+ images).
    if (g) *g << -g4.head<2>(), g4.head<2>() - g4.tail<2>(), g4.tail<2>();
    if (H) {
        Eigen::Matrix<double, 4, 6> A = Eigen::Matrix<double, 4, 6>::Zero();
        A.block<2, 2>(0, 0) = -Eigen::Matrix2d::Identity();
        A.block<2, 2>(0, 2) = Eigen::Matrix2d::Identity();
        A.block<2, 2>(2, 2) = -Eigen::Matrix2d::Identity();
        A.block<2, 2>(2, 4) = Eigen::Matrix2d::Identity();
        const Eigen::Matrix4d hp = psd ? project_psd<4>(H4) : H4;
        *H = A.transpose() * hp * A;
    }
    return E;
}

void NetworkEnergy::evaluate(const Eigen::VectorXd& q, const Eigen::Matrix2d& F, const Eigen::Matrix2d& dF,
                             unsigned want, EnergyEval& out, Eigen::SparseMatrix<double>* H) const {
    const bool wg = want & kGradient, wh = want & kHessian, ws = want & kStrain, psd = want & kProjectPSD;
    const bool comoving = ws && (want & kComoving);
    const Eigen::Matrix2d V = comoving ? Eigen::Matrix2d(dF * F.inverse()) : Eigen::Matrix2d::Zero();
    const Eigen::VectorXd u = displacements(q, F);
    const Eigen::Matrix2d FmI = F - Eigen::Matrix2d::Identity();
    const Eigen::Matrix2d dB = dF * model_.box.B0(), FmIB0 = FmI * model_.box.B0();
    const double k4a2 = 4 * model_.aspect_ratio * model_.aspect_ratio;
    const bool any_fixed = ndof_ != static_cast<int>(dof_.size());
    out.energy = out.stretch = out.bend = 0;
    out.dE_dt = out.d2E_dt2 = out.d2E_dt2_size = 0;
    if (wg) out.gradient.setZero(ndof_);
    if (ws) out.d2E_dqdt.setZero(ndof_);
    double* hv = nullptr;
    if (wh) {
        if (!H || H->nonZeros() != pattern_.nonZeros()) throw std::logic_error("Hessian lacks the energy's pattern");
        hv = H->valuePtr();
        std::fill(hv, hv + H->nonZeros(), 0.0);
    }
    auto add_grad = [&](Eigen::VectorXd& v, int node, const Eigen::Vector2d& g) {
        const int d0 = dof_[2 * node];
        if (d0 >= 0) v[d0] += g.x(), v[d0 + 1] += g.y();
    };
    // Edge vector d = d0 + (F - I) B0 n + u_j - u_i (= x_j - x_i + F B0 n) and its strain rate
    // dd/dt = dF (B0 n + [fixed] x_ref differences), or dF F^-1 d when every node moves affinely (kComoving).
    auto edge = [&](int i, int j, const Eigen::Vector2i& n, const Eigen::Vector2d& d0, Eigen::Vector2d& d,
                    Eigen::Vector2d& c) {
        d = d0 + FmIB0 * n.cast<double>() + (u.segment<2>(2 * j) - u.segment<2>(2 * i));
        if (!ws) return;
        if (comoving) {
            c = V * d;
            return;
        }
        c = dB * n.cast<double>();
        if (any_fixed) {
            if (dof_[2 * j] < 0) c += dF * model_.x.segment<2>(2 * j);
            if (dof_[2 * i] < 0) c -= dF * model_.x.segment<2>(2 * i);
        }
    };

    Eigen::Vector2d d, c, gd;
    Eigen::Matrix2d Hd;
    for (size_t e = 0; e < model_.segments.size(); ++e) {
        const Segment& s = model_.segments[e];
        edge(s.i, s.j, s.shift, seg_d0_[e], d, c);
        const double E = stretch_energy(d, s.l0, k4a2, params_.stretch, (wg || ws) ? &gd : nullptr,
                                        (wh || ws) ? &Hd : nullptr);
        out.stretch += E;
        if (wg) add_grad(out.gradient, s.i, -gd), add_grad(out.gradient, s.j, gd);
        if (ws) {
            out.dE_dt += gd.dot(c);
            const double tt = c.dot(Hd * c);
            out.d2E_dt2 += tt;
            out.d2E_dt2_size += std::abs(tt);
            const Eigen::Vector2d hc = Hd * c;
            add_grad(out.d2E_dqdt, s.i, -hc), add_grad(out.d2E_dqdt, s.j, hc);
        }
        if (wh) {
            const Eigen::Matrix2d h = psd ? project_psd<2>(Hd) : Hd;
            Eigen::Matrix4d hl;
            hl << h, -h, -h, h;
            scatter<4>(hl, &seg_slots_[n_upper<4>() * e], hv);
        }
    }

    Eigen::Vector2d d1, d2, c1, c2;
    Eigen::Vector4d g4;
    Eigen::Matrix4d H4;
    Eigen::Matrix<double, 4, 6> A = Eigen::Matrix<double, 4, 6>::Zero();
    A.block<2, 2>(0, 0) = -Eigen::Matrix2d::Identity();
    A.block<2, 2>(0, 2) = Eigen::Matrix2d::Identity();
    A.block<2, 2>(2, 2) = -Eigen::Matrix2d::Identity();
    A.block<2, 2>(2, 4) = Eigen::Matrix2d::Identity();
    for (size_t e = 0; e < model_.hinges.size(); ++e) {
        const Hinge& h = model_.hinges[e];
        edge(h.i, h.j, h.shift1, hinge_d0_[2 * e], d1, c1);
        edge(h.j, h.k, h.shift2, hinge_d0_[2 * e + 1], d2, c2);
        const double E = bend_energy(d1, d2, h.lt0, (wg || ws) ? &g4 : nullptr, (wh || ws) ? &H4 : nullptr);
        out.bend += E;
        if (wg) {
            add_grad(out.gradient, h.i, -g4.head<2>());
            add_grad(out.gradient, h.j, g4.head<2>() - g4.tail<2>());
            add_grad(out.gradient, h.k, g4.tail<2>());
        }
        if (ws) {
            Eigen::Vector4d c4;
            c4 << c1, c2;
            out.dE_dt += g4.dot(c4);
            const double tt = c4.dot(H4 * c4);
            out.d2E_dt2 += tt;
            out.d2E_dt2_size += std::abs(tt);
            const Eigen::Vector4d hc = H4 * c4;
            add_grad(out.d2E_dqdt, h.i, -hc.head<2>());
            add_grad(out.d2E_dqdt, h.j, hc.head<2>() - hc.tail<2>());
            add_grad(out.d2E_dqdt, h.k, hc.tail<2>());
        }
        if (wh) {
            const Eigen::Matrix4d hp = psd ? project_psd<4>(H4) : H4;
            const Eigen::Matrix<double, 6, 6> hl = A.transpose() * hp * A;
            scatter<6>(hl, &hinge_slots_[n_upper<6>() * e], hv);
        }
    }
    out.energy = out.stretch + out.bend;
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
