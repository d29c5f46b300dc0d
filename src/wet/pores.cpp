#include "fibernet/wet/pores.hpp"

#include <CGAL/Arr_extended_dcel.h>
#include <CGAL/Arr_segment_traits_2.h>
#include <CGAL/Arrangement_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace fibernet {

double PoreStats::cover() const {
    double a = wall_area + island_area + open_area;
    for (const Pore& p : pores) a += p.area;
    return box_area > 0 ? a / box_area : 0;
}

double default_wall_width(const Model& m) { return 2 / m.aspect_ratio; }

namespace {

using Kernel = CGAL::Exact_predicates_exact_constructions_kernel;
using FT = Kernel::FT;
using Traits = CGAL::Arr_segment_traits_2<Kernel>;
using Point = Traits::Point_2;
using Curve = Traits::Curve_2;
struct VertexData {
    int point = -1;  // the torus point (a vertex on the cut has a twin on the opposite side)
    int sides = 0;   // bits of the cut lines it lies on
};
using Dcel = CGAL::Arr_extended_dcel<Traits, VertexData, char, int>;
using Arrangement = CGAL::Arrangement_2<Traits, Dcel>;
using Halfedge = Arrangement::Halfedge_handle;
using Vertex = Arrangement::Vertex_handle;
using Face = Arrangement::Face_handle;

enum Side { Left = 1, Right = 2, Bottom = 4, Top = 8 };

// The cut cell [c, c + 1]^2 in lattice coordinates u = B^-1 x (a periodic box), or none (an open box).
struct Cut {
    bool periodic = false;
    double cx = 0, cy = 0;
};

// A cut line off every node (lattice coordinate not within 1e-12 of c + integer), so that no fiber lies along it.
double cut_off_nodes(const std::vector<double>& u) {
    for (double c : {0.0, 0.3819660112501051, 0.2360679774997897, 0.1458980337503155, 0.0901699437494742}) {
        bool clear = true;
        for (double v : u) clear = clear && std::abs((v - c) - std::round(v - c)) > 1e-12;
        if (clear) return c;
    }
    throw std::runtime_error("pores: no cut line of the periodic box avoids the nodes");
}

FT floor_exact(const FT& v) {
    double f = std::floor(CGAL::to_double(v));
    while (FT(f) > v) f -= 1;
    while (FT(f + 1) <= v) f += 1;
    return FT(f);
}

// Segment p-q (unwrapped, lattice coordinates) cut at the lattice lines of the cut and each piece moved into the
// cut cell by whole lattice vectors (exactly: a point on x = c + 1 lands on x = c with the same y).
void clip_into_cell(const Point& p, const Point& q, const Cut& cut, std::vector<Curve>& out) {
    // Most segments lie inside one cell, clear of its lines by more than the round-off of p and q in double: only
    // moved, by whole lattice vectors.
    auto cell_of = [](double a, double b, double c) {
        const double lo = std::floor(std::min(a, b) - c - 1e-9), hi = std::floor(std::max(a, b) - c + 1e-9);
        return lo == hi ? lo : std::nan("");
    };
    const double kx = cell_of(CGAL::to_double(p.x()), CGAL::to_double(q.x()), cut.cx),
                 ky = cell_of(CGAL::to_double(p.y()), CGAL::to_double(q.y()), cut.cy);
    if (std::isfinite(kx) && std::isfinite(ky)) {
        if (kx == 0 && ky == 0) out.emplace_back(p, q);
        else out.emplace_back(Point(p.x() - kx, p.y() - ky), Point(q.x() - kx, q.y() - ky));
        return;
    }
    std::vector<FT> ts = {FT(0), FT(1)};
    auto add_lines = [&](const FT& a, const FT& b, double c) {
        if (a == b) return;
        const double lo = std::min(CGAL::to_double(a), CGAL::to_double(b)) - c,
                     hi = std::max(CGAL::to_double(a), CGAL::to_double(b)) - c;
        for (double k = std::floor(lo) - 1; k <= std::ceil(hi) + 1; ++k) {
            const FT t = (FT(c) + FT(k) - a) / (b - a);
            if (t > 0 && t < 1) ts.push_back(t);
        }
    };
    add_lines(p.x(), q.x(), cut.cx);
    add_lines(p.y(), q.y(), cut.cy);
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
    const FT dx = q.x() - p.x(), dy = q.y() - p.y();
    for (size_t k = 0; k + 1 < ts.size(); ++k) {
        const FT mx = p.x() + (ts[k] + ts[k + 1]) / 2 * dx, my = p.y() + (ts[k] + ts[k + 1]) / 2 * dy;
        const FT sx = floor_exact(mx - FT(cut.cx)), sy = floor_exact(my - FT(cut.cy));
        const Point a(p.x() + ts[k] * dx - sx, p.y() + ts[k] * dy - sy);
        const Point b(p.x() + ts[k + 1] * dx - sx, p.y() + ts[k + 1] * dy - sy);
        out.emplace_back(a, b);
    }
}

// Node positions in lattice coordinates: nodes within 1e-9 of each other (wrapped, if periodic) share one position,
// each at its own lattice image. The two ends of a fiber that closes on itself through the box are a round-off apart,
// and exactly they would leave it open (two dangling ends).
struct LatticeNode {
    Eigen::Vector2d at;     // the shared position
    Eigen::Vector2i image;  // whole lattice vectors to add (exactly, to the exact position)
    // Exact leaves where the image is zero (most nodes): cheaper to build and to compare than sums.
    Point point(const Eigen::Vector2i& shift = Eigen::Vector2i::Zero()) const {
        const Eigen::Vector2i k = image + shift;
        if (k.isZero()) return Point(at.x(), at.y());
        return Point(FT{at.x()} + k.x(), FT{at.y()} + k.y());
    }
};

std::vector<LatticeNode> lattice_nodes(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    const Eigen::Matrix2d Bi = B.inverse();
    const double snap = 1e-9;
    const long long period = m.box.periodic ? std::llround(1 / snap) : 0;
    auto cell = [&](double c) {
        const long long k = std::llround(c / snap);
        return period ? ((k % period) + period) % period : k;
    };
    std::map<std::pair<long long, long long>, Eigen::Vector2d> at;
    std::vector<LatticeNode> u(m.num_nodes());
    for (int i = 0; i < m.num_nodes(); ++i) {
        const Eigen::Vector2d v = Bi * x.segment<2>(2 * i);
        const auto it = at.emplace(std::make_pair(cell(v.x()), cell(v.y())), v).first;
        const Eigen::Vector2d image = (v - it->second).array().round().matrix();
        u[i] = {it->second, image.cast<int>()};
    }
    return u;
}

// Every segment as an exact curve in lattice coordinates (clipped into the cut cell if periodic), plus the cell's
// four sides.
std::vector<Curve> lattice_curves(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, Cut& cut) {
    const std::vector<LatticeNode> u = lattice_nodes(m, x, B);
    std::vector<double> ux, uy;
    for (const LatticeNode& n : u) ux.push_back(n.at.x()), uy.push_back(n.at.y());
    cut.periodic = m.box.periodic;
    std::vector<Curve> curves;
    if (cut.periodic) {
        cut.cx = cut_off_nodes(ux), cut.cy = cut_off_nodes(uy);
        const Point c00(cut.cx, cut.cy), c10(FT(cut.cx) + 1, FT(cut.cy)), c11(FT(cut.cx) + 1, FT(cut.cy) + 1),
            c01(FT(cut.cx), FT(cut.cy) + 1);
        curves = {Curve(c00, c10), Curve(c10, c11), Curve(c11, c01), Curve(c01, c00)};
    }
    for (const Segment& s : m.segments) {
        const Point p = u[s.i].point(), q = u[s.j].point(s.shift);
        if (p == q) continue;
        if (cut.periodic) clip_into_cell(p, q, cut, curves);
        else curves.emplace_back(p, q);
    }
    return curves;
}

int sides_of(const Point& p, const Cut& cut) {
    if (!cut.periodic) return 0;
    const FT cx(cut.cx), cy(cut.cy);
    return (p.x() == cx ? Left : 0) | (p.x() == cx + 1 ? Right : 0) | (p.y() == cy ? Bottom : 0) |
           (p.y() == cy + 1 ? Top : 0);
}

// A side of the cut cell (both ends on one cut line: no fiber lies along one).
bool on_cut(Halfedge h) { return (h->source()->data().sides & h->target()->data().sides) != 0; }

// Torus points: one per interior vertex, one per pair of cut vertices facing each other, one for the four corners;
// with their fiber degree (edges that are not cut sides).
struct TorusPoints {
    std::vector<std::vector<Vertex>> members;
    std::vector<int> degree;
};

TorusPoints torus_points(Arrangement& arr) {
    TorusPoints t;
    std::map<FT, int> on_x, on_y;  // cut vertices on the left/right sides by y, on the bottom/top by x
    int corner = -1;
    for (auto v = arr.vertices_begin(); v != arr.vertices_end(); ++v) {
        const int s = v->data().sides;
        int id;
        if (s == 0) {
            id = static_cast<int>(t.members.size());
        } else if ((s & (Left | Right)) && (s & (Bottom | Top))) {
            if (corner < 0) corner = static_cast<int>(t.members.size());
            id = corner;
        } else {
            auto& map = (s & (Left | Right)) ? on_x : on_y;
            const FT key = (s & (Left | Right)) ? v->point().y() : v->point().x();
            auto it = map.find(key);
            id = it != map.end() ? it->second : (map[key] = static_cast<int>(t.members.size()));
        }
        if (id == static_cast<int>(t.members.size())) t.members.emplace_back(), t.degree.push_back(0);
        v->data().point = id;
        t.members[id].push_back(v);
        if (v->is_isolated()) continue;
        auto h = v->incident_halfedges(), first = h;
        do t.degree[id] += on_cut(h) ? 0 : 1;
        while (++h != first);
    }
    return t;
}

// Removes fiber trees: repeatedly the one fiber edge at a torus point of degree 1 (a dangling end, or what is left of
// a free fiber). They bound no area; pruned, every island left encloses some.
void prune_trees(Arrangement& arr, TorusPoints& t) {
    std::vector<int> queue;
    for (size_t p = 0; p < t.degree.size(); ++p)
        if (t.degree[p] == 1) queue.push_back(static_cast<int>(p));
    while (!queue.empty()) {
        const int p = queue.back();
        queue.pop_back();
        if (t.degree[p] != 1) continue;
        Halfedge edge;
        bool found = false;
        for (Vertex v : t.members[p]) {
            if (v->is_isolated()) continue;
            auto h = v->incident_halfedges(), first = h;
            do
                if (!on_cut(h)) edge = h, found = true;
            while (!found && ++h != first);
            if (found) break;
        }
        if (!found) throw std::logic_error("pores: a torus point of degree 1 has no fiber edge");
        const int other = edge->source()->data().point;
        arr.remove_edge(edge, false, false);
        --t.degree[p];
        if (--t.degree[other] == 1) queue.push_back(other);
    }
}

// One face of the arrangement (a cell face if periodic), in lattice units; perimeter and edges count fiber edges only.
struct CellFace {
    double area = 0, perimeter = 0;
    int holes = 0, edges = 0;
};

CellFace measure(Face f, const Eigen::Matrix2d& B) {
    CellFace c;
    auto ccb = [&](Arrangement::Ccb_halfedge_circulator first) {
        const Eigen::Vector2d o(CGAL::to_double(first->source()->point().x()), CGAL::to_double(first->source()->point().y()));
        auto h = first;
        do {
            const Eigen::Vector2d a = Eigen::Vector2d(CGAL::to_double(h->source()->point().x()),
                                                      CGAL::to_double(h->source()->point().y())) - o;
            const Eigen::Vector2d b = Eigen::Vector2d(CGAL::to_double(h->target()->point().x()),
                                                      CGAL::to_double(h->target()->point().y())) - o;
            c.area += 0.5 * (a.x() * b.y() - a.y() * b.x());
            if (!on_cut(h)) c.perimeter += (B * (b - a)).norm(), ++c.edges;
        } while (++h != first);
    };
    if (!f->is_unbounded()) ccb(f->outer_ccb());
    for (auto i = f->inner_ccbs_begin(); i != f->inner_ccbs_end(); ++i) ccb(*i), ++c.holes;
    return c;
}

// Union-find over cell faces with lattice offsets: lift(b) - lift(a) = d for glued neighbours. An offset that does
// not close marks the face as winding around the torus.
struct OffsetUnion {
    std::vector<int> parent;
    std::vector<Eigen::Vector2i> offset;  // lift(f) - lift(parent(f))
    std::vector<char> winds;
    explicit OffsetUnion(int n) : parent(n), offset(n, Eigen::Vector2i::Zero()), winds(n, 0) {
        for (int i = 0; i < n; ++i) parent[i] = i;
    }
    int find(int f) {
        if (parent[f] == f) return f;
        const int r = find(parent[f]);
        offset[f] += offset[parent[f]];
        parent[f] = r;
        return r;
    }
    void unite(int a, int b, const Eigen::Vector2i& d) {
        const int ra = find(a), rb = find(b);
        if (ra == rb) {
            if (offset[b] - offset[a] != d) winds[ra] = 1;
            return;
        }
        parent[rb] = ra;
        offset[rb] = offset[a] + d - offset[b];
        winds[ra] = winds[ra] || winds[rb];
    }
};

// Glues the cell faces across the cut: a face at x = c continues in the face at x = c + 1 of the cell to the left
// (lift offset (-1, 0)), likewise in y. Returns the number of glued cut sides per cell face's root, after unite.
std::vector<int> glue(Arrangement& arr, OffsetUnion& u) {
    struct CutSide {
        FT at;
        int face;
    };
    std::vector<CutSide> by_side[4];
    for (auto h = arr.halfedges_begin(); h != arr.halfedges_end(); ++h) {
        if (h->face()->is_unbounded() || !on_cut(h)) continue;
        const int s = h->source()->data().sides & h->target()->data().sides;
        const int k = s & Left ? 0 : s & Right ? 1 : s & Bottom ? 2 : 3;
        const Point &a = h->source()->point(), &b = h->target()->point();
        const FT at = k < 2 ? (a.y() < b.y() ? a.y() : b.y()) : (a.x() < b.x() ? a.x() : b.x());
        by_side[k].push_back({at, h->face()->data()});
    }
    for (auto& v : by_side) std::sort(v.begin(), v.end(), [](const CutSide& a, const CutSide& b) { return a.at < b.at; });
    std::vector<std::pair<int, int>> glued;
    for (int k : {0, 2}) {
        const auto &lo = by_side[k], &hi = by_side[k + 1];
        if (lo.size() != hi.size()) throw std::logic_error("pores: the cut's opposite sides are split differently");
        const Eigen::Vector2i d = k == 0 ? Eigen::Vector2i(-1, 0) : Eigen::Vector2i(0, -1);
        for (size_t i = 0; i < lo.size(); ++i) {
            if (lo[i].at != hi[i].at) throw std::logic_error("pores: the cut's opposite sides do not match");
            u.unite(lo[i].face, hi[i].face, d);
            glued.push_back({lo[i].face, hi[i].face});
        }
    }
    std::vector<int> count(u.parent.size(), 0);
    for (const auto& g : glued) ++count[u.find(g.first)];
    return count;
}

// Cut points left with no fiber through them (after pruning): each is a 0-cell of the face it lies in.
std::vector<int> free_cut_points(const TorusPoints& t, OffsetUnion& u) {
    std::vector<int> count(u.parent.size(), 0);
    for (size_t p = 0; p < t.members.size(); ++p) {
        const Vertex v = t.members[p].front();
        if (v->data().sides == 0 || t.degree[p] != 0) continue;
        auto h = v->incident_halfedges(), first = h;
        while (h->face()->is_unbounded() && ++h != first) {}
        ++count[u.find(h->face()->data())];
    }
    return count;
}

}  // namespace

PoreStats pores(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double wall_width) {
    PoreStats out;
    out.box_area = std::abs(B.determinant());
    out.wall_width = wall_width > 0 ? wall_width : default_wall_width(m);
    Cut cut;
    const std::vector<Curve> curves = lattice_curves(m, x, B, cut);
    Arrangement arr;
    CGAL::insert(arr, curves.begin(), curves.end());
    for (auto v = arr.vertices_begin(); v != arr.vertices_end(); ++v) v->data().sides = sides_of(v->point(), cut);
    TorusPoints t = torus_points(arr);
    prune_trees(arr, t);
    int nf = 0;
    std::vector<CellFace> cells;
    for (auto f = arr.faces_begin(); f != arr.faces_end(); ++f) {
        if (f->is_unbounded()) continue;
        f->data() = nf++;
        cells.push_back(measure(f, B));
    }
    OffsetUnion u(nf);
    const std::vector<int> glued = cut.periodic ? glue(arr, u) : std::vector<int>(nf, 0);
    const std::vector<int> points = cut.periodic ? free_cut_points(t, u) : std::vector<int>(nf, 0);
    // A glued face: its cells' areas, perimeters and holes; its compactly supported Euler characteristic
    // chi = cells - holes - glued cut sides + free cut points (1 for a disk, 1 - islands for a planar face).
    struct Glued {
        double area = 0, perimeter = 0;
        int chi = 0, edges = 0;
    };
    std::vector<Glued> faces(nf);
    for (int f = 0; f < nf; ++f) {
        Glued& g = faces[u.find(f)];
        g.area += cells[f].area * out.box_area, g.perimeter += cells[f].perimeter;
        g.chi += 1 - cells[f].holes, g.edges += cells[f].edges;
    }
    double bounded = 0;
    for (int f = 0; f < nf; ++f) {
        if (u.find(f) != f) continue;
        Glued& g = faces[f];
        g.chi += points[f] - glued[f];
        bounded += g.area;
        if (u.winds[f]) {
            ++out.open_faces, out.open_area += g.area;
        } else if (g.chi < 1) {
            ++out.island_faces, out.island_area += g.area, out.islands += 1 - g.chi;
        } else if (g.chi > 1) {
            throw std::logic_error("pores: a face with Euler characteristic above 1");
        } else if (2 * g.area < out.wall_width * g.perimeter) {
            ++out.walls, out.wall_area += g.area;
        } else {
            out.pores.push_back({g.area, std::sqrt(4 * g.area / M_PI), g.edges});
        }
    }
    double covered = 0;
    for (const Pore& p : out.pores) covered += p.area;
    out.remainder = out.box_area - covered;
    if (!cut.periodic) out.outside_area = out.box_area - bounded;
    return out;
}

}  // namespace fibernet
