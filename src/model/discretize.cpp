#include "fibernet/model/discretize.hpp"

#include <algorithm>
#include <cmath>

#include "fibernet/util/error.hpp"
#include "fibernet/util/union_find.hpp"

namespace fibernet {

Scheme parse_scheme(const std::string& s) {
    if (s == "seed") return Scheme::Seed;
    if (s == "even") return Scheme::Even;
    throw InputError("discretization scheme '" + s + "' is unknown (expected seed or even)");
}

std::string to_string(Scheme s) { return s == Scheme::Seed ? "seed" : "even"; }

void DiscretizationParams::check(const std::string& where) const {
    check_value(n_seg >= 1 && n_seg <= 100000, n_seg, where, "n_seg", "must be an integer in [1, 100000]");
    check_value(h > 0, h, where, "h (even-scheme segment length)", "must be > 0");
    check_value(fiber_length > 0, fiber_length, where, "fiber_length", "must be > 0");
    check_value(aspect_ratio > 0, aspect_ratio, where, "a (aspect ratio)", "must be > 0");
    if (scheme == Scheme::Even && fiber_length / h > 1e5)
        throw InputError(where + ": h = " + show(h) + " gives more than 1e5 segments per fiber");
}

namespace {
struct Pin {
    double s;      // arc position in seed units
    int crossing;
};

// Fiber fib's nodes as arc positions (seed units) with the crossing each pins (-1: none), in arc order. Seed scheme:
// regular nodes plus pins; even: ends plus pins, then subdivided to at most h. pins_f: the fiber's crosslinks in arc
// order; coincident ones (a junction of three or more fibers) count once.
std::vector<Pin> breakpoints(const Fiber& fib, const std::vector<Pin>& pins_f, const DiscretizationParams& p, double unit,
                             double tol) {
    const double len = fib.length * unit;
    std::vector<Pin> pts;
    std::vector<Pin> merged;  // pins with coincident ones removed
    for (const auto& pin : pins_f)
        if (merged.empty() || pin.s - merged.back().s > tol) merged.push_back(pin);
    if (p.scheme == Scheme::Seed) {
        const int nseg = std::max(1, static_cast<int>(std::lround(p.n_seg * fib.length)));
        for (int k = 0; k <= nseg; ++k) pts.push_back({len * k / nseg, -1});
    } else {
        pts.push_back({0, -1});
        pts.push_back({len, -1});
    }
    // A pin replaces a regular breakpoint it coincides with.
    for (const auto& pin : merged) {
        bool replaced = false;
        for (auto& q : pts)
            if (q.crossing < 0 && std::abs(q.s - pin.s) <= tol) q = {q.s, pin.crossing}, replaced = true;
        if (!replaced) pts.push_back(pin);
    }
    for (double b : fib.breakpoints) {
        bool present = false;
        for (const auto& q : pts) present = present || std::abs(q.s - b * unit) <= tol;
        if (!present) pts.push_back({b * unit, -1});
    }
    std::sort(pts.begin(), pts.end(), [](const Pin& a, const Pin& b) { return a.s < b.s; });
    if (p.scheme == Scheme::Even) {
        std::vector<Pin> fine{pts.front()};
        for (size_t k = 1; k < pts.size(); ++k) {
            const double a = pts[k - 1].s, b = pts[k].s;
            const int n = std::max(1, static_cast<int>(std::ceil((b - a) / p.h - 1e-9)));
            for (int i = 1; i < n; ++i) fine.push_back({a + (b - a) * i / n, -1});
            fine.push_back(pts[k]);
        }
        pts.swap(fine);
    }
    if (p.trim_ends) {
        auto first = std::find_if(pts.begin(), pts.end(), [](const Pin& q) { return q.crossing >= 0; });
        auto last = std::find_if(pts.rbegin(), pts.rend(), [](const Pin& q) { return q.crossing >= 0; });
        if (first == pts.end()) pts.clear();
        else pts = std::vector<Pin>(first, last.base());
    }
    return pts;
}

// Fiber f's segments and hinges from its chain's nodes (m.chains[f]), unit direction u and the image of each node
// occurrence (wraps).
void add_elements(Model& m, int f, const Eigen::Vector2d& u, const std::vector<Eigen::Vector2i>& wraps) {
    FiberChain& ch = m.chains[f];
    for (size_t k = 0; k + 1 < ch.nodes.size(); ++k) {
        Segment sg;
        sg.i = ch.nodes[k], sg.j = ch.nodes[k + 1];
        sg.shift = wraps[k + 1] - wraps[k];
        sg.l0 = ch.s[k + 1] - ch.s[k];
        sg.d0 = sg.l0 * u;  // exact rest vector: no cancellation of large wrapped coordinates
        sg.fiber = f;
        ch.segments.push_back(static_cast<int>(m.segments.size()));
        m.segments.push_back(sg);
    }
    for (size_t k = 0; k + 2 < ch.nodes.size(); ++k) {
        const Segment& a = m.segments[ch.segments[k]];
        const Segment& b = m.segments[ch.segments[k + 1]];
        Hinge hg;
        hg.i = a.i, hg.j = a.j, hg.k = b.j;
        hg.shift1 = a.shift, hg.shift2 = b.shift;
        hg.lt0 = 0.5 * (a.l0 + b.l0);
        hg.d10 = a.d0, hg.d20 = b.d0;
        hg.fiber = f;
        m.hinges.push_back(hg);
    }
}
}  // namespace

Model discretize(const Network& net, const DiscretizationParams& p) {
    p.check("discretization");
    const double lf = p.fiber_length;
    const double unit = lf;  // network lengths are in fiber lengths
    const double tol = 1e-12 * lf;
    Model m;
    m.box.L = net.L * unit;
    m.box.periodic = net.periodic;
    m.aspect_ratio = p.aspect_ratio;
    m.fiber_length = lf;
    const int nf = static_cast<int>(net.fibers.size());
    const int nc = static_cast<int>(net.crossings.size());

    // Crosslinks on each fiber, in arc order. Pins that coincide on a fiber (hand-made junctions of three
    // or more fibers) become one supernode.
    std::vector<std::vector<Pin>> pins(nf);
    for (int k = 0; k < nc; ++k) {
        const auto& c = net.crossings[k];
        if (!c.crosslink) continue;
        pins[c.f1].push_back({c.s1 * unit, k});
        pins[c.f2].push_back({c.s2 * unit, k});
    }
    UnionFind uf(nc);
    for (auto& v : pins) {
        std::sort(v.begin(), v.end(), [](const Pin& a, const Pin& b) { return a.s < b.s || (a.s == b.s && a.crossing < b.crossing); });
        for (size_t i = 1; i < v.size(); ++i)
            if (v[i].s - v[i - 1].s <= tol) uf.unite(v[i].crossing, v[i - 1].crossing);
    }

    std::vector<double> pos;  // interleaved node positions (wrapped)
    auto wrap = [&](const Eigen::Vector2d& P) -> Eigen::Vector2d {
        if (!net.periodic) return P;
        return P - m.box.L * (P / m.box.L).array().floor().matrix();
    };
    auto add_node = [&](const Eigen::Vector2d& P) {
        const Eigen::Vector2d x = wrap(P);
        pos.push_back(x.x());
        pos.push_back(x.y());
        return static_cast<int>(pos.size() / 2 - 1);
    };
    m.crossing_node.assign(nc, -1);
    std::vector<int> root_node(nc, -1);
    auto supernode_of = [&](int crossing, const Eigen::Vector2d& P) {
        const int r = uf.find(crossing);
        if (root_node[r] < 0) {
            root_node[r] = add_node(P);
            m.supernodes.push_back({root_node[r], {}});
        }
        m.crossing_node[crossing] = root_node[r];
        return root_node[r];
    };

    m.chains.resize(nf);
    for (int f = 0; f < nf; ++f) {
        const Fiber& fib = net.fibers[f];
        const std::vector<Pin> pts = breakpoints(fib, pins[f], p, unit, tol);
        FiberChain& ch = m.chains[f];
        const Eigen::Vector2d u = fib.direction();
        std::vector<Eigen::Vector2i> wraps;
        for (const auto& q : pts) {
            const Eigen::Vector2d P = unit * fib.start + q.s * u;  // unwrapped position
            int node;
            if (q.crossing >= 0) {
                const auto& c = net.crossings[q.crossing];
                // The supernode's position is taken from the crossing's first fiber.
                const Eigen::Vector2d P1 = unit * net.fibers[c.f1].point(c.s1);
                node = supernode_of(q.crossing, c.f1 == f ? P : P1);
                for (const auto& pin : pins[f])
                    if (pin.crossing != q.crossing && uf.find(pin.crossing) == uf.find(q.crossing))
                        m.crossing_node[pin.crossing] = node;
            } else {
                node = add_node(P);
            }
            ch.nodes.push_back(node);
            ch.s.push_back(q.s);
            // Image of this node occurrence: P = x + B0 w.
            const Eigen::Vector2d x(pos[2 * node], pos[2 * node + 1]);
            const Eigen::Vector2d w = (P - x) / m.box.L;
            wraps.emplace_back(static_cast<int>(std::lround(w.x())), static_cast<int>(std::lround(w.y())));
        }
        add_elements(m, f, u, wraps);
    }
    std::vector<int> supernode_of_node(pos.size() / 2, -1);
    for (size_t i = 0; i < m.supernodes.size(); ++i) supernode_of_node[m.supernodes[i].node] = static_cast<int>(i);
    for (int k = 0; k < nc; ++k)
        if (m.crossing_node[k] >= 0) m.supernodes[supernode_of_node[m.crossing_node[k]]].crossings.push_back(k);
    m.x = Eigen::Map<Eigen::VectorXd>(pos.data(), static_cast<Eigen::Index>(pos.size()));
    m.fixed.assign(m.num_nodes(), 0);
    return m;
}

}  // namespace fibernet
