#include "fibernet/wet/wetting.hpp"

#include <algorithm>
#include <cmath>

#include "fibernet/util/error.hpp"
#include "fibernet/util/random.hpp"

namespace fibernet {

WetWhich parse_wet_which(const std::string& s) {
    if (s == "all") return WetWhich::All;
    if (s == "free") return WetWhich::Free;
    if (s == "fraction") return WetWhich::Fraction;
    throw InputError("wet crossings '" + s + "' is unknown (expected all, free or fraction)");
}

std::string to_string(WetWhich w) { return w == WetWhich::All ? "all" : w == WetWhich::Free ? "free" : "fraction"; }

Bridge make_bridge(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, int f1, int k1, int f2, int k2,
                   int crossing) {
    if (f1 > f2) std::swap(f1, f2), std::swap(k1, k2);
    Bridge b;
    b.f1 = f1, b.f2 = f2, b.k1 = k1, b.k2 = k2, b.crossing = crossing;
    const int n = m.chains[f1].nodes[k1], j = m.chains[f2].nodes[k2];
    if (m.box.periodic) {
        // Nearest image: unambiguous while the box is wider than a few segment lengths.
        const Eigen::Vector2d w = B.inverse() * (x.segment<2>(2 * n) - x.segment<2>(2 * j));
        b.image = Eigen::Vector2i(static_cast<int>(std::lround(w.x())), static_cast<int>(std::lround(w.y())));
    }
    return b;
}

namespace {
// Index in the chain of the segment containing arc position s (seed units); a node at s starts its segment.
int home_segment(const FiberChain& ch, double s) {
    const int nseg = static_cast<int>(ch.segments.size());
    const int k = static_cast<int>(std::upper_bound(ch.s.begin(), ch.s.end(), s) - ch.s.begin()) - 1;
    return std::min(std::max(k, 0), nseg - 1);
}
}  // namespace

std::vector<char> wet_choice(const Network& net, const WettingRule& rule) {
    std::vector<char> wet(net.crossings.size(), 1);
    Rng rng(derive_seed(rule.seed, 0x77e7));
    for (size_t k = 0; k < net.crossings.size(); ++k) {
        const double u = rng.uniform();  // drawn for every crossing so the choice of one does not shift the others
        if (rule.which == WetWhich::Free && net.crossings[k].crosslink) wet[k] = 0;
        if (rule.which == WetWhich::Fraction && !(u < rule.fraction)) wet[k] = 0;
    }
    return wet;
}

FiberPairs dry_pairs(const Network& net, const WettingRule& rule) {
    FiberPairs out;
    const std::vector<char> wet = wet_choice(net, rule);
    for (size_t k = 0; k < net.crossings.size(); ++k)
        if (!wet[k]) out.insert({std::min(net.crossings[k].f1, net.crossings[k].f2), std::max(net.crossings[k].f1, net.crossings[k].f2)});
    return out;
}

std::vector<Bridge> wet_crossings(const Network& net, const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                  const WettingRule& rule) {
    std::vector<Bridge> out;
    const std::vector<char> wet = wet_choice(net, rule);
    const double unit = m.fiber_length;  // network lengths are in fiber lengths
    for (size_t k = 0; k < net.crossings.size(); ++k) {
        const Crossing& c = net.crossings[k];
        if (!wet[k]) continue;
        const FiberChain &c1 = m.chains[c.f1], &c2 = m.chains[c.f2];
        int k1 = home_segment(c1, c.s1 * unit), k2 = home_segment(c2, c.s2 * unit);
        const int node = k < m.crossing_node.size() ? m.crossing_node[k] : -1;
        if (node >= 0) {  // a crosslink: the home pair starts at the supernode (the node's own arc position)
            for (size_t i = 0; i < c1.nodes.size(); ++i)
                if (c1.nodes[i] == node) k1 = std::min<int>(static_cast<int>(i), static_cast<int>(c1.segments.size()) - 1);
            for (size_t i = 0; i < c2.nodes.size(); ++i)
                if (c2.nodes[i] == node) k2 = std::min<int>(static_cast<int>(i), static_cast<int>(c2.segments.size()) - 1);
        }
        out.push_back(make_bridge(m, x, B, c.f1, k1, c.f2, k2, static_cast<int>(k)));
    }
    return out;
}

}  // namespace fibernet
