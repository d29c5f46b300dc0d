#include "fibernet/wet/pores.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "fibernet/wet/active_set.hpp"

namespace fibernet {

namespace {
double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
}  // namespace

PoreStats pores(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    PoreStats out;
    out.box_area = std::abs(B.determinant());
    const int nn = m.num_nodes();
    const Eigen::Matrix2d Bi = B.inverse();
    // Vertices: model nodes, merged where two sit at one place (a fiber that closes on itself through the box),
    // then one vertex per crossing of two segments.
    std::vector<int> vert(nn);
    std::map<std::pair<long long, long long>, int> at;
    int nv = 0;
    const double snap = 1e-9;
    for (int i = 0; i < nn; ++i) {
        Eigen::Vector2d u = Bi * x.segment<2>(2 * i);
        if (m.box.periodic) u = u.array() - u.array().floor();
        const auto k = std::make_pair(std::llround(u.x() / snap) % std::llround(1 / snap),
                                      std::llround(u.y() / snap) % std::llround(1 / snap));
        auto it = at.find(k);
        vert[i] = it != at.end() ? it->second : (at[k] = nv++);
    }
    // Points along each segment: (t, vertex). Crossings come from the segment-pair search of the active set.
    const int ns = static_cast<int>(m.segments.size());
    std::vector<std::vector<std::pair<double, int>>> pts(ns);
    std::vector<Eigen::Vector2d> D(ns);
    for (int e = 0; e < ns; ++e) {
        const Segment& s = m.segments[e];
        D[e] = x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i) + B * s.shift.cast<double>();
        pts[e] = {{0.0, vert[s.i]}, {1.0, vert[s.j]}};
    }
    for (const Bridge& c : segment_crossings(m, x, B)) {
        const int a = m.chains[c.f1].segments[c.k1], b = m.chains[c.f2].segments[c.k2];
        // Segment b's start in a's frame: the bridge frame puts fiber 2's home start node at x + B image.
        const Eigen::Vector2d Pa = x.segment<2>(2 * m.segments[a].i);
        const Eigen::Vector2d Pb = x.segment<2>(2 * m.segments[b].i) + B * c.image.cast<double>();
        const double den = cross2(D[a], D[b]);
        const double t = cross2(Pb - Pa, D[b]) / den, u = cross2(Pb - Pa, D[a]) / den;
        pts[a].push_back({t, nv}), pts[b].push_back({u, nv});
        ++nv;
    }
    // Half-edges between consecutive points of each segment, with their unwrapped vectors.
    struct Half {
        int from, to;
        Eigen::Vector2d d;
        double angle;
    };
    std::vector<Half> half;
    for (int e = 0; e < ns; ++e) {
        auto& p = pts[e];
        std::sort(p.begin(), p.end());
        for (size_t k = 0; k + 1 < p.size(); ++k) {
            const Eigen::Vector2d d = (p[k + 1].first - p[k].first) * D[e];
            if (d.norm() < 1e-12 * m.box.L || p[k].second == p[k + 1].second) continue;
            half.push_back({p[k].second, p[k + 1].second, d, std::atan2(d.y(), d.x())});
            half.push_back({p[k + 1].second, p[k].second, -d, std::atan2(-d.y(), -d.x())});
        }
    }
    out.vertices = nv;
    out.edges = static_cast<int>(half.size() / 2);
    // Outgoing half-edges around each vertex in counter-clockwise order; twin of h is h ^ 1.
    std::vector<std::vector<int>> around(nv);
    for (int h = 0; h < static_cast<int>(half.size()); ++h) around[half[h].from].push_back(h);
    std::vector<int> rank(half.size());
    for (auto& v : around) {
        std::sort(v.begin(), v.end(), [&](int a, int b) { return half[a].angle < half[b].angle; });
        for (size_t i = 0; i < v.size(); ++i) rank[v[i]] = static_cast<int>(i);
    }
    auto next = [&](int h) {  // face on the left: the outgoing edge just clockwise of the twin
        const auto& v = around[half[h].to];
        const int r = rank[h ^ 1];
        return v[(r + v.size() - 1) % v.size()];
    };
    std::vector<char> used(half.size(), 0);
    double covered = 0;
    for (int h0 = 0; h0 < static_cast<int>(half.size()); ++h0) {
        if (used[h0]) continue;
        Eigen::Vector2d p(0, 0);
        double area2 = 0;
        int n = 0;
        for (int h = h0; !used[h]; h = next(h)) {
            used[h] = 1;
            area2 += cross2(p, p + half[h].d);
            p += half[h].d;
            ++n;
        }
        const bool closed = p.norm() < 1e-9 * m.box.L;
        if (!closed) {
            ++out.open_cycles;
            continue;
        }
        if (area2 <= 1e-12 * out.box_area) continue;
        Pore pore;
        pore.area = 0.5 * area2, pore.diameter = std::sqrt(4 * pore.area / M_PI), pore.edges = n;
        covered += pore.area;
        out.pores.push_back(pore);
    }
    out.remainder = out.box_area - covered;
    return out;
}

}  // namespace fibernet
