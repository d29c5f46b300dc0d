#include "fibernet/energy/network_region.hpp"

#include <algorithm>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"

namespace fibernet {

namespace {
// Compressed rows: for each element (nodes given by nodes_of), an entry at each of its nodes.
template <class NodesOf>
void compress(int nn, int ne, int k, NodesOf nodes_of, std::vector<int>& start, std::vector<int>& list) {
    start.assign(nn + 1, 0);
    for (int e = 0; e < ne; ++e)
        for (int a = 0; a < k; ++a) ++start[nodes_of(e, a) + 1];
    for (int v = 0; v < nn; ++v) start[v + 1] += start[v];
    list.resize(start[nn]);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int e = 0; e < ne; ++e)
        for (int a = 0; a < k; ++a) list[fill[nodes_of(e, a)]++] = e;
}

}  // namespace

std::vector<int> elements_at(const std::vector<int>& start, const std::vector<int>& list, const std::vector<int>& nodes) {
    std::vector<int> out;
    for (int v : nodes) out.insert(out.end(), list.begin() + start[v], list.begin() + start[v + 1]);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

NodeElements node_elements(const NetworkEnergy& e) {
    const Model& m = e.model();
    NodeElements inc;
    compress(m.num_nodes(), static_cast<int>(m.segments.size()), 2,
             [&](int s, int a) { return a == 0 ? m.segments[s].i : m.segments[s].j; }, inc.seg_start, inc.seg);
    compress(m.num_nodes(), static_cast<int>(m.hinges.size()), 3,
             [&](int h, int a) { return a == 0 ? m.hinges[h].i : a == 1 ? m.hinges[h].j : m.hinges[h].k; },
             inc.hinge_start, inc.hinge);
    inc.dof_node.assign(e.num_dofs(), -1);
    for (int v = 0; v < m.num_nodes(); ++v)
        for (int c = 0; c < 2; ++c)
            if (e.dof(v, c) >= 0) inc.dof_node[e.dof(v, c)] = 2 * v + c;
    return inc;
}

NetworkRegion::NetworkRegion(const NetworkEnergy& e, const Eigen::Matrix2d& F, const NodeElements& inc,
                             const Eigen::VectorXd& q, const std::vector<int>& coords)
    : e_(e), F_(F), coords_(coords) {
    const Model& m = e.model();
    std::vector<int> nodes;
    for (int c : coords_) {
        if (c < 0 || c >= e.num_dofs()) throw std::logic_error("NetworkRegion: coordinate out of range");
        coord_u_.push_back(inc.dof_node[c]);
        nodes.push_back(inc.dof_node[c] / 2);
    }
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());  // coords sorted: a node's two are adjacent
    // Region index of coordinate c of node v, or -1 when it is held (or fixed).
    auto local = [&](int v, int c) -> int {
        const int d = e.dof(v, c);
        if (d < 0) return -1;
        const auto it = std::lower_bound(coords_.begin(), coords_.end(), d);
        return it != coords_.end() && *it == d ? static_cast<int>(it - coords_.begin()) : -1;
    };
    segs_ = elements_at(inc.seg_start, inc.seg, nodes);
    hinges_ = elements_at(inc.hinge_start, inc.hinge, nodes);
    for (int s : segs_)
        for (int v : {m.segments[s].i, m.segments[s].j})
            for (int c = 0; c < 2; ++c) seg_idx_.push_back(local(v, c));
    for (int h : hinges_)
        for (int v : {m.hinges[h].i, m.hinges[h].j, m.hinges[h].k})
            for (int c = 0; c < 2; ++c) hinge_idx_.push_back(local(v, c));
    // The displacements of the elements' nodes only: the elements read no other entry, so the rest of u_ is left
    // unwritten (its pages never touched), and a region costs its elements, not a copy of the network (at L = 80 a
    // copy of 1.4e6 entries per part and line-search trial).
    u_.resize(2 * m.num_nodes());
    for (int s : segs_)
        for (int v : {m.segments[s].i, m.segments[s].j}) e.displacement_of(v, q, F, u_);
    for (int h : hinges_)
        for (int v : {m.hinges[h].i, m.hinges[h].j, m.hinges[h].k}) e.displacement_of(v, q, F, u_);
    PatternBuilder builder(size());
    builder.add_elements(seg_idx_, 4), builder.add_elements(hinge_idx_, 6);
    builder.add_diagonal();
    pattern_ = builder.build();
    element_slots(pattern_, seg_idx_, 4, seg_slot_);
    element_slots(pattern_, hinge_idx_, 6, hinge_slot_);
}

double NetworkRegion::eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) {
    for (int i = 0; i < size(); ++i) u_[coord_u_[i]] = qa[i];
    if (g) g->setZero(size());
    double* hv = nullptr;
    if (H) {
        if (H->nonZeros() != pattern_.nonZeros()) throw std::logic_error("NetworkRegion: Hessian lacks the region's pattern");
        hv = H->valuePtr();
        std::fill(hv, hv + H->nonZeros(), 0.0);
    }
    auto add = [&](const int* idx, const int* slot, int M, const double* ge, const double* he) {
        scatter_element(idx, slot, M, ge, he, g, hv);
    };
    double E = 0;
    Eigen::Vector4d g4;
    Eigen::Matrix4d H4;
    for (size_t k = 0; k < segs_.size(); ++k) {
        E += e_.segment_term(segs_[k], u_, F_, g ? &g4 : nullptr, H ? &H4 : nullptr, psd);
        add(&seg_idx_[4 * k], &seg_slot_[16 * k], 4, g4.data(), H4.data());
    }
    Eigen::Matrix<double, 6, 1> g6;
    Eigen::Matrix<double, 6, 6> H6;
    for (size_t k = 0; k < hinges_.size(); ++k) {
        E += e_.hinge_term(hinges_[k], u_, F_, g ? &g6 : nullptr, H ? &H6 : nullptr, psd);
        add(&hinge_idx_[6 * k], &hinge_slot_[36 * k], 6, g6.data(), H6.data());
    }
    return E;
}

}  // namespace fibernet
