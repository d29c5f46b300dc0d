#include "fibernet/wet/pores.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>

#include "fibernet/util/union_find.hpp"
#include "fibernet/wet/active_set.hpp"

namespace fibernet {

namespace {
double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Crossing number of point q against the closed polygon poly.
bool inside(const std::vector<Eigen::Vector2d>& poly, const Eigen::Vector2d& q) {
    bool in = false;
    for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const Eigen::Vector2d &a = poly[i], &b = poly[j];
        if ((a.y() > q.y()) != (b.y() > q.y()) && q.x() < a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y()))
            in = !in;
    }
    return in;
}
}  // namespace

PoreStats pores(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    PoreStats out;
    out.box_area = std::abs(B.determinant());
    const int nn = m.num_nodes();
    const Eigen::Matrix2d Bi = B.inverse();
    // Every vertex has one position (wrapped into the box if periodic); edges are differences of these plus whole
    // box vectors, so a face closes exactly when its box vectors sum to zero.
    std::vector<Eigen::Vector2d> pos;
    auto wrap = [&](const Eigen::Vector2d& p) -> Eigen::Vector2d {
        if (!m.box.periodic) return p;
        const Eigen::Vector2d u = Bi * p;
        return B * (u.array() - u.array().floor()).matrix();
    };
    // Vertices: model nodes, merged where two sit at one place (a fiber that closes on itself through the box),
    // then one vertex per crossing of two segments.
    std::vector<int> vert(nn);
    std::map<std::pair<long long, long long>, int> at;
    int nv = 0;
    const double snap = 1e-9;
    // Wrapped (u = 1 is u = 0) in a periodic box only: in an open one, nodes at 0 and at 1 are different points.
    const long long period = m.box.periodic ? std::llround(1 / snap) : 0;
    auto cell = [&](double c) { return period ? std::llround(c / snap) % period : std::llround(c / snap); };
    for (int i = 0; i < nn; ++i) {
        Eigen::Vector2d u = Bi * x.segment<2>(2 * i);
        if (m.box.periodic) u = u.array() - u.array().floor();
        const auto k = std::make_pair(cell(u.x()), cell(u.y()));
        auto it = at.find(k);
        if (it != at.end()) {
            vert[i] = it->second;
        } else {
            vert[i] = at[k] = nv++;
            pos.push_back(wrap(x.segment<2>(2 * i)));
        }
    }
    // Points along each segment: (t, vertex). Crossings come from the segment-pair search of the active set.
    const int ns = static_cast<int>(m.segments.size());
    std::vector<std::vector<std::pair<double, int>>> pts(ns);
    std::vector<Eigen::Vector2d> P(ns), D(ns);
    for (int e = 0; e < ns; ++e) {
        const Segment& s = m.segments[e];
        P[e] = x.segment<2>(2 * s.i);
        D[e] = x.segment<2>(2 * s.j) - P[e] + B * s.shift.cast<double>();
        pts[e] = {{0.0, vert[s.i]}, {1.0, vert[s.j]}};
    }
    auto along = [](const Eigen::Vector2d& p, const Eigen::Vector2d& P0, const Eigen::Vector2d& d) {
        return std::min(1.0, std::max(0.0, (p - P0).dot(d) / d.squaredNorm()));
    };
    for (const Bridge& c : segment_crossings(m, x, B)) {
        const int a = m.chains[c.f1].segments[c.k1], b = m.chains[c.f2].segments[c.k2];
        // Segment b's start in a's frame: the bridge frame puts fiber 2's home start node at x + B image.
        const Eigen::Vector2d& Pa = P[a];
        const Eigen::Vector2d Pb = P[b] + B * c.image.cast<double>();
        // One point per crossing, placed on both segments from it. Solving for t and u separately put the two ends
        // of a crossing of (anti)parallel zipped fibers up to 2e-3 apart, and faces through it did not close.
        const double den = cross2(D[a], D[b]);
        Eigen::Vector2d X;
        if (std::abs(den) > 1e-8 * D[a].norm() * D[b].norm()) {
            X = Pa + std::min(1.0, std::max(0.0, cross2(Pb - Pa, D[b]) / den)) * D[a];
        } else {  // parallel to round-off: the crossing may be anywhere on the overlap; take its middle
            const double s0 = along(Pb, Pa, D[a]), s1 = along(Pb + D[b], Pa, D[a]);
            X = Pa + 0.5 * (s0 + s1) * D[a];
        }
        pts[a].push_back({along(X, Pa, D[a]), nv}), pts[b].push_back({along(X, Pb, D[b]), nv});
        pos.push_back(wrap(X));
        ++nv;
    }
    // Pieces between consecutive points of each segment. A piece shorter than tol is contracted (its ends become
    // one vertex): the crossings of one fiber with two fibers zipped on top of each other are round-off apart, and
    // their order along it says nothing. Contraction keeps the graph planar; dropping the piece cut the fiber.
    const double tol = 1e-9 * m.box.L;
    UnionFind rep(nv);
    struct Piece {
        int from, to;
        Eigen::Vector2d d;  // along the segment (unwrapped)
    };
    std::vector<Piece> pieces;
    for (int e = 0; e < ns; ++e) {
        auto& p = pts[e];
        std::sort(p.begin(), p.end());
        for (size_t k = 0; k + 1 < p.size(); ++k) {
            if (p[k].second == p[k + 1].second) continue;
            const Eigen::Vector2d d = (p[k + 1].first - p[k].first) * D[e];
            if (d.norm() < tol) rep.unite(p[k].second, p[k + 1].second);
            else pieces.push_back({p[k].second, p[k + 1].second, d});
        }
    }
    // Half-edges (twin of h is h ^ 1) between merged vertices, with their box-vector counts.
    struct Half {
        int from, to;
        Eigen::Vector2d d;
        Eigen::Vector2i shift;
        double angle;
    };
    std::vector<Half> half;
    for (const Piece& p : pieces) {
        const int f = rep.find(p.from), t = rep.find(p.to);
        Eigen::Vector2i s(0, 0);
        if (m.box.periodic) {
            const Eigen::Vector2d w = Bi * (p.d - (pos[t] - pos[f]));
            s = Eigen::Vector2i(static_cast<int>(std::lround(w.x())), static_cast<int>(std::lround(w.y())));
        }
        if (f == t && s == Eigen::Vector2i(0, 0)) continue;  // both ends contracted into one vertex
        const Eigen::Vector2d d = pos[t] - pos[f] + B * s.cast<double>();
        half.push_back({f, t, d, s, std::atan2(d.y(), d.x())});
        half.push_back({t, f, -d, Eigen::Vector2i(-s), std::atan2(-d.y(), -d.x())});
    }
    std::vector<char> live(nv, 0);
    for (const Half& h : half) live[h.from] = 1;
    out.vertices = static_cast<int>(std::count(live.begin(), live.end(), 1));
    out.edges = static_cast<int>(half.size() / 2);
    // Outgoing half-edges around each vertex in counter-clockwise order. Edges between the same two vertices have
    // bit-identical vectors (two zipped fibers): the tie is broken by an edge key whose sign flips with direction,
    // so the order reverses at the other end, as two infinitesimally separated curves would have it.
    std::vector<std::vector<int>> around(nv);
    for (int h = 0; h < static_cast<int>(half.size()); ++h) around[half[h].from].push_back(h);
    auto key = [](int h) { return (h & 1) ? -(h / 2) - 1 : h / 2 + 1; };
    std::vector<int> rank(half.size());
    for (auto& v : around) {
        std::sort(v.begin(), v.end(), [&](int a, int b) {
            return half[a].angle != half[b].angle ? half[a].angle < half[b].angle : key(a) < key(b);
        });
        for (size_t i = 0; i < v.size(); ++i) rank[v[i]] = static_cast<int>(i);
    }
    auto next = [&](int h) {  // face on the left: the outgoing edge just clockwise of the twin
        const auto& v = around[half[h].to];
        const int r = rank[h ^ 1];
        return v[(r + v.size() - 1) % v.size()];
    };
    // Connected components, for the islands below.
    UnionFind comp(nv);
    for (size_t h = 0; h < half.size(); h += 2) comp.unite(half[h].from, half[h].to);
    struct Face {
        int h0, n;
        double area;
        bool hole = false;  // encloses an island: not a disk
        std::vector<Eigen::Vector2d> poly;  // unwrapped, from its first vertex's position
        Eigen::Vector2d lo, hi;             // bounds of poly in box coordinates
    };
    std::vector<Face> faces;        // closed, positive area
    std::vector<int> island_point;  // a vertex of each island's outer boundary
    std::vector<char> used(half.size(), 0), seen(nv, 0);
    for (int h0 = 0; h0 < static_cast<int>(half.size()); ++h0) {
        if (used[h0]) continue;
        Eigen::Vector2d p(0, 0);
        Eigen::Vector2i wind(0, 0);
        double area2 = 0;
        std::vector<Eigen::Vector2d> poly;
        for (int h = h0; !used[h]; h = next(h)) {
            used[h] = 1;
            poly.push_back(pos[half[h0].from] + p);
            area2 += cross2(p, p + half[h].d);
            p += half[h].d;
            wind += half[h].shift;
        }
        // open_cycles: the boundary winds around the torus (a band below percolation, or a fiber closing on
        // itself): exact, from whole box vectors.
        if (wind != Eigen::Vector2i(0, 0)) {
            ++out.open_cycles;
            continue;
        }
        if (area2 < -1e-12 * out.box_area) {
            // Clockwise: the outer boundary of a component that does not wind around the torus and encloses area.
            // Inside a pore it is an island, and the pore around it is not a disk (below). A tree (a fiber crossing
            // nothing) encloses none and is left where it lies: the pore keeps its area.
            const int c = comp.find(half[h0].from);
            if (!seen[c]) seen[c] = 1, island_point.push_back(half[h0].from);
            continue;
        }
        if (area2 <= 1e-12 * out.box_area) continue;  // flat: a tree, or a sliver between fibers zipped together
        Face f;
        f.h0 = h0, f.n = static_cast<int>(poly.size()), f.area = 0.5 * area2;
        f.lo = f.hi = Bi * poly[0];
        for (const auto& q : poly) f.lo = f.lo.cwiseMin(Bi * q), f.hi = f.hi.cwiseMax(Bi * q);
        f.poly = std::move(poly);
        faces.push_back(std::move(f));
    }
    // Each island belongs to the smallest pore of another component that contains one of its vertices (tested at
    // the periodic images that fall in the pore's bounds); its area is not that pore's, and the pore, not a disk,
    // goes to the remainder.
    for (int v : island_point) {
        const int c = comp.find(v);
        const Eigen::Vector2d u = Bi * pos[v];
        Face* best = nullptr;
        for (Face& f : faces) {
            if (comp.find(half[f.h0].from) == c || (best && f.area >= best->area)) continue;
            bool in = !m.box.periodic && (u.array() >= f.lo.array()).all() && (u.array() <= f.hi.array()).all() &&
                      inside(f.poly, pos[v]);
            if (m.box.periodic)
                for (int ny = static_cast<int>(std::ceil(f.lo.y() - u.y())); !in && ny <= f.hi.y() - u.y(); ++ny)
                    for (int nx = static_cast<int>(std::ceil(f.lo.x() - u.x())); !in && nx <= f.hi.x() - u.x(); ++nx)
                        in = inside(f.poly, pos[v] + B * Eigen::Vector2d(nx, ny));
            if (in) best = &f;
        }
        if (best) best->hole = true, ++out.islands;
    }
    double covered = 0;
    for (const Face& f : faces) {
        if (f.hole) continue;
        Pore pore;
        pore.area = f.area, pore.diameter = std::sqrt(4 * pore.area / M_PI), pore.edges = f.n;
        covered += pore.area;
        out.pores.push_back(pore);
    }
    out.remainder = out.box_area - covered;
    return out;
}

}  // namespace fibernet
