#include "fibernet/network/network.hpp"

#include <algorithm>

#include "fibernet/util/union_find.hpp"

namespace fibernet {

int Network::num_crosslinks() const {
    int n = 0;
    for (const auto& c : crossings) n += c.crosslink ? 1 : 0;
    return n;
}

bool intersect(const Eigen::Vector2d& a0, const Eigen::Vector2d& ua, double la, const Eigen::Vector2d& b0,
               const Eigen::Vector2d& ub, double lb, double& sa, double& sb) {
    const double denom = ua.x() * ub.y() - ua.y() * ub.x();
    if (std::abs(denom) < 1e-14) return false;  // parallel fibers never cross (measure zero)
    const Eigen::Vector2d r = b0 - a0;
    sa = (r.x() * ub.y() - r.y() * ub.x()) / denom;
    sb = (r.x() * ua.y() - r.y() * ua.x()) / denom;
    return sa >= 0 && sa <= la && sb >= 0 && sb <= lb;
}

bool intersect(const Fiber& a, const Fiber& b, const Eigen::Vector2d& shift, double& sa, double& sb) {
    return intersect(a.start, a.direction(), a.length, b.start + shift, b.direction(), b.length, sa, sb);
}

std::vector<int> crosslink_components(const Network& net) {
    const int n = static_cast<int>(net.fibers.size());
    UnionFind uf(n);
    for (const auto& c : net.crossings)
        if (c.crosslink) uf.unite(c.f1, c.f2);
    std::vector<int> label(n, -1), root_label(n, -1);
    int k = 0;
    for (int i = 0; i < n; ++i) {
        int r = uf.find(i);
        if (root_label[r] < 0) root_label[r] = k++;
        label[i] = root_label[r];
    }
    return label;
}

NetworkStats statistics(const Network& net) {
    NetworkStats s;
    s.fibers = static_cast<int>(net.fibers.size());
    s.crossings = static_cast<int>(net.crossings.size());
    s.crosslinks = net.num_crosslinks();
    if (s.fibers > 0) {
        s.crossings_per_fiber = 2.0 * s.crossings / s.fibers;  // each crossing touches two fibers
        s.crosslinks_per_fiber = 2.0 * s.crosslinks / s.fibers;
    }
    auto label = crosslink_components(net);
    std::vector<int> size;
    for (int l : label) {
        if (l >= static_cast<int>(size.size())) size.resize(l + 1, 0);
        ++size[l];
    }
    s.components = static_cast<int>(size.size());
    s.largest_component = size.empty() ? 0 : *std::max_element(size.begin(), size.end());
    return s;
}

}  // namespace fibernet
