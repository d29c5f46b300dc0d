#include "fibernet/wet/wet_region.hpp"

#include "fibernet/energy/network_region.hpp"

#include <algorithm>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"

namespace fibernet {

namespace {
// Counting sort of (node, element) pairs into compressed rows; nodes_of(e, k) returns element e's k nodes (-1: none).
template <class NodesOf>
void build_rows(int nn, int ne, NodesOf nodes_of, std::vector<int>& start, std::vector<int>& list) {
    start.assign(nn + 1, 0);
    for (int e = 0; e < ne; ++e) {
        int k = 0;
        const int* n = nodes_of(e, k);
        for (int a = 0; a < k; ++a)
            if (n[a] >= 0 && std::find(n, n + a, n[a]) == n + a) ++start[n[a] + 1];
    }
    for (int i = 0; i < nn; ++i) start[i + 1] += start[i];
    list.resize(start[nn]);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int e = 0; e < ne; ++e) {
        int k = 0;
        const int* n = nodes_of(e, k);
        for (int a = 0; a < k; ++a)
            if (n[a] >= 0 && std::find(n, n + a, n[a]) == n + a) list[fill[n[a]]++] = e;
    }
}

}  // namespace

ElementIncidence element_incidence(const WetEnergy& W) {
    const Model& m = W.dry().model();
    const int nn = m.num_nodes();
    ElementIncidence inc;
    int buf[3];
    build_rows(nn, static_cast<int>(m.segments.size()), [&](int e, int& k) {
        buf[0] = m.segments[e].i, buf[1] = m.segments[e].j, k = 2;
        return static_cast<const int*>(buf);
    }, inc.seg_start, inc.seg);
    build_rows(nn, static_cast<int>(m.hinges.size()), [&](int e, int& k) {
        buf[0] = m.hinges[e].i, buf[1] = m.hinges[e].j, buf[2] = m.hinges[e].k, k = 3;
        return static_cast<const int*>(buf);
    }, inc.hinge_start, inc.hinge);
    update_bridge_incidence(W, inc);
    return inc;
}

void incidence_for(const WetEnergy& W, ElementIncidence& inc) {
    if (inc.seg_start.empty()) inc = element_incidence(W);
    else if (inc.bridges_of != W.id()) update_bridge_incidence(W, inc);
}

void update_bridge_incidence(const WetEnergy& W, ElementIncidence& inc) {
    const bool wet = W.params().beta != 0;
    build_rows(W.dry().model().num_nodes(), wet ? static_cast<int>(W.elements().size()) : 0, [&](int e, int& k) {
        k = 8;
        return static_cast<const int*>(W.elements()[e].node);
    }, inc.bridge_start, inc.bridge);
    inc.bridges_of = W.id();
}

std::vector<char> nodes_above(const NetworkEnergy& dry, const Eigen::VectorXd& g, double threshold) {
    const int nn = dry.model().num_nodes();
    std::vector<char> in(nn, 0);
    for (int i = 0; i < nn; ++i)
        for (int c = 0; c < 2; ++c)
            if (dry.dof(i, c) >= 0 && std::abs(g[dry.dof(i, c)]) > threshold) in[i] = 1;
    return in;
}

namespace {
// Calls f(v) for every node v sharing an element of W with node u (u itself included).
template <class F>
void for_each_neighbour(const WetEnergy& W, const ElementIncidence& inc, int u, F f) {
    const Model& m = W.dry().model();
    for (int k = inc.seg_start[u]; k < inc.seg_start[u + 1]; ++k) f(m.segments[inc.seg[k]].i), f(m.segments[inc.seg[k]].j);
    for (int k = inc.hinge_start[u]; k < inc.hinge_start[u + 1]; ++k)
        f(m.hinges[inc.hinge[k]].i), f(m.hinges[inc.hinge[k]].j), f(m.hinges[inc.hinge[k]].k);
    for (int k = inc.bridge_start[u]; k < inc.bridge_start[u + 1]; ++k)
        for (int a = 0; a < 8; ++a)
            if (W.elements()[inc.bridge[k]].node[a] >= 0) f(W.elements()[inc.bridge[k]].node[a]);
}
}  // namespace

void grow_region(const WetEnergy& W, const ElementIncidence& inc, std::vector<char>& in, int hops) {
    // Breadth first, one hop per layer: a layer's nodes are those of the elements at the last layer's nodes.
    std::vector<int> layer;
    for (int i = 0; i < static_cast<int>(in.size()); ++i)
        if (in[i]) layer.push_back(i);
    std::vector<int> next;
    for (int h = 0; h < hops && !layer.empty(); ++h) {
        next.clear();
        for (int u : layer)
            for_each_neighbour(W, inc, u, [&](int v) {
                if (!in[v]) in[v] = 1, next.push_back(v);
            });
        layer.swap(next);
    }
}

std::vector<std::vector<int>> region_parts(const WetEnergy& W, const ElementIncidence& inc, const std::vector<char>& in) {
    const Model& m = W.dry().model();
    const int nn = m.num_nodes();
    std::vector<int> part(nn, -1);
    std::vector<std::vector<int>> parts;
    std::vector<int> stack;
    for (int s = 0; s < nn; ++s) {
        if (!in[s] || part[s] >= 0 || W.dry().dof(s, 0) < 0) continue;
        const int id = static_cast<int>(parts.size());
        parts.emplace_back();
        part[s] = id, stack.assign(1, s);
        // A node without coordinates (fixed) never moves, so it joins nothing.
        auto visit = [&](int v) {
            if (v >= 0 && in[v] && part[v] < 0 && W.dry().dof(v, 0) >= 0) part[v] = id, stack.push_back(v);
        };
        while (!stack.empty()) {
            const int v = stack.back();
            stack.pop_back();
            parts[id].push_back(v);
            for_each_neighbour(W, inc, v, visit);
        }
        std::sort(parts[id].begin(), parts[id].end());
    }
    return parts;
}

RegionState::RegionState(const WetEnergy& W, const Eigen::VectorXd& q)
    : u(W.dry().displacements(q, W.F())), x(W.dry().positions(q, W.F())) {}

WetRegion::WetRegion(const WetEnergy& W, RegionState& state, const std::vector<int>& nodes, const ElementIncidence& inc)
    : W_(W), u_(state.u), x_(state.x) {
    const NetworkEnergy& dry = W.dry();
    const Model& m = dry.model();
    // Region index of each coordinate of W (only the region's nodes' entries are looked up).
    std::vector<int> order(nodes);
    std::sort(order.begin(), order.end());
    auto local = [&](int node, int c) -> int {
        const auto it = std::lower_bound(order.begin(), order.end(), node);
        if (dry.dof(node, c) < 0 || it == order.end() || *it != node) return -1;
        return 2 * static_cast<int>(it - order.begin()) + c;
    };
    // Coordinates: 2 per node in sorted order, fixed ones (no coordinate) left out below by compaction.
    std::vector<int> compact(2 * order.size(), -1);
    for (size_t k = 0; k < order.size(); ++k)
        for (int c = 0; c < 2; ++c)
            if (dry.dof(order[k], c) >= 0) {
                compact[2 * k + c] = static_cast<int>(dofs_.size());
                dofs_.push_back(dry.dof(order[k], c));
                dof_node_.push_back(2 * order[k] + c);
            }
    auto index = [&](const int* n, int k, std::vector<int>& out) {
        for (int a = 0; a < 2 * k; ++a) {
            const int l = n[a / 2] < 0 ? -1 : local(n[a / 2], a % 2);
            out.push_back(l < 0 ? -1 : compact[l]);
        }
    };
    segs_ = elements_at(inc.seg_start, inc.seg, order);
    hinges_ = elements_at(inc.hinge_start, inc.hinge, order);
    bridges_ = elements_at(inc.bridge_start, inc.bridge, order);
    for (int e : segs_) {
        const int n[2] = {m.segments[e].i, m.segments[e].j};
        index(n, 2, seg_idx_);
    }
    for (int e : hinges_) {
        const int n[3] = {m.hinges[e].i, m.hinges[e].j, m.hinges[e].k};
        index(n, 3, hinge_idx_);
    }
    for (int e : bridges_) index(W.elements()[e].node, 8, bridge_idx_);
}

// The Hessian pattern on first use: a region built for its gradient only (gradient_rows) never needs it.
const Eigen::SparseMatrix<double>& WetRegion::hessian_pattern() const {
    if (pattern_built_) return pattern_;
    // Upper-triangular pattern over the region's coordinates, then each element's value slots.
    PatternBuilder builder(size());
    builder.add_elements(seg_idx_, 4), builder.add_elements(hinge_idx_, 6), builder.add_elements(bridge_idx_, 16);
    builder.add_diagonal();  // a diagonal entry for every coordinate
    pattern_ = builder.build();
    element_slots(pattern_, seg_idx_, 4, seg_slot_);
    element_slots(pattern_, hinge_idx_, 6, hinge_slot_);
    element_slots(pattern_, bridge_idx_, 16, bridge_slot_);
    pattern_built_ = true;
    return pattern_;
}

Eigen::VectorXd WetRegion::restrict(const Eigen::VectorXd& q) const {
    Eigen::VectorXd qa(size());
    for (int i = 0; i < size(); ++i) qa[i] = q[dofs_[i]];
    return qa;
}

void WetRegion::embed(const Eigen::VectorXd& qa, Eigen::VectorXd& q) const {
    for (int i = 0; i < size(); ++i) q[dofs_[i]] = qa[i];
}

double WetRegion::eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) {
    const NetworkEnergy& dry = W_.dry();
    const Eigen::Matrix2d& F = W_.F();
    const Eigen::VectorXd& xr = dry.model().x;
    for (int i = 0; i < size(); ++i) u_[dof_node_[i]] = qa[i], x_[dof_node_[i]] = xr[dof_node_[i]] + qa[i];
    const Eigen::VectorXd& u = u_;
    if (g) g->setZero(size());
    double* hv = nullptr;
    if (H) {
        if (H->nonZeros() != hessian_pattern().nonZeros()) throw std::logic_error("Hessian lacks the region's pattern");
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
        E += dry.segment_term(segs_[k], u, F, g ? &g4 : nullptr, H ? &H4 : nullptr, psd);
        add(&seg_idx_[4 * k], H ? &seg_slot_[16 * k] : nullptr, 4, g4.data(), H4.data());
    }
    Eigen::Matrix<double, 6, 1> g6;
    Eigen::Matrix<double, 6, 6> H6;
    for (size_t k = 0; k < hinges_.size(); ++k) {
        E += dry.hinge_term(hinges_[k], u, F, g ? &g6 : nullptr, H ? &H6 : nullptr, psd);
        add(&hinge_idx_[6 * k], H ? &hinge_slot_[36 * k] : nullptr, 6, g6.data(), H6.data());
    }
    if (!bridges_.empty()) {
        const Eigen::VectorXd& x = x_;
        const Eigen::Matrix2d B = F * dry.model().box.B0();
        Vector16d g16;
        Matrix16d H16;
        for (size_t k = 0; k < bridges_.size(); ++k) {
            const BridgeElement& e = W_.elements()[bridges_[k]];
            E += bridge_element_energy(e, element_coordinates(e, x, B), W_.params().beta, W_.params().law,
                                       g ? &g16 : nullptr, H ? &H16 : nullptr, psd);
            add(&bridge_idx_[16 * k], H ? &bridge_slot_[256 * k] : nullptr, 16, g16.data(), H16.data());
        }
    }
    return E;
}

void gradient_rows(const WetEnergy& W, const ElementIncidence& inc, const Eigen::VectorXd& q,
                   const std::vector<char>& nodes, Eigen::VectorXd& g) {
    const NetworkEnergy& dry = W.dry();
    const Model& m = dry.model();
    const Eigen::Matrix2d& F = W.F();
    // The elements at the flagged nodes (as WetRegion gathers them, without its index tables: here each element's
    // entries go straight to g).
    std::vector<int> flagged;
    for (int v = 0; v < static_cast<int>(nodes.size()); ++v) {
        if (!nodes[v]) continue;
        flagged.push_back(v);
        for (int c = 0; c < 2; ++c)
            if (dry.dof(v, c) >= 0) g[dry.dof(v, c)] = 0;
    }
    const std::vector<int> segs = elements_at(inc.seg_start, inc.seg, flagged);
    const std::vector<int> hinges = elements_at(inc.hinge_start, inc.hinge, flagged);
    const std::vector<int> bridges = elements_at(inc.bridge_start, inc.bridge, flagged);
    // An element's local coordinate a adds to g where its node is flagged, in the order a = 0, 1, ... (as
    // NetworkEnergy::evaluate and WetEnergy::eval add them).
    auto add = [&](const int* n, int M, const double* ge) {
        for (int a = 0; a < M; ++a) {
            const int v = n[a / 2];
            if (v < 0 || !nodes[v]) continue;
            const int r = dry.dof(v, a % 2);
            if (r >= 0) g[r] += ge[a];
        }
    };
    const Eigen::VectorXd u = dry.displacements(q, F);
    Eigen::Vector4d g4;
    for (int e : segs) {
        dry.segment_term(e, u, F, &g4, nullptr, false);
        const int n[2] = {m.segments[e].i, m.segments[e].j};
        add(n, 4, g4.data());
    }
    Eigen::Matrix<double, 6, 1> g6;
    for (int e : hinges) {
        dry.hinge_term(e, u, F, &g6, nullptr, false);
        const int n[3] = {m.hinges[e].i, m.hinges[e].j, m.hinges[e].k};
        add(n, 6, g6.data());
    }
    if (bridges.empty()) return;
    const Eigen::VectorXd x = dry.positions(q, F);
    const Eigen::Matrix2d B = F * m.box.B0();
    Vector16d g16;
    for (int k : bridges) {
        const BridgeElement& e = W.elements()[k];
        bridge_element_energy(e, element_coordinates(e, x, B), W.params().beta, W.params().law, &g16, nullptr, false);
        add(e.node, 16, g16.data());
    }
}

void update_gradient(const WetEnergy& W, const ElementIncidence& inc, const Eigen::VectorXd& q, std::vector<char> moved,
                     const std::vector<char>& touched, Eigen::VectorXd& g) {
    grow_region(W, inc, moved, 1);
    for (size_t i = 0; i < moved.size(); ++i) moved[i] = moved[i] || touched[i];
    gradient_rows(W, inc, q, moved, g);
}

}  // namespace fibernet
