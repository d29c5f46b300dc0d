#include "fibernet/wet/neighbour_list.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "fibernet/util/parallel.hpp"
#include "fibernet/wet/capillary_pair.hpp"

namespace fibernet {

// A named namespace, not an anonymous one: NeighbourList::Cache (external linkage) holds these types, which GCC flags
// (-Wsubobject-linkage) when this file is compiled inside a unity batch.
namespace neighbour_cells {

// A segment's ends moved next to its wrapped midpoint (node i's unwrapped position is x_i - B wrap), and the distance
// within which its pairs are listed.
struct SegInfo {
    Eigen::Vector2d p0, p1;
    Eigen::Vector2i wrap{0, 0};
    double reach = 0;  // range(1.5 length + skin) + skin / 2
};

// Whether segments a and b (b's first node at image `image` in a's frame) meet at a common node: at a crosslink.
bool touch(const Segment& a, const Segment& b, const Eigen::Vector2i& image) {
    const Eigen::Vector2i bj = image + b.shift;
    return (a.i == b.i && image == Eigen::Vector2i::Zero()) || (a.i == b.j && bj == Eigen::Vector2i::Zero()) ||
           (a.j == b.i && image == a.shift) || (a.j == b.j && bj == a.shift);
}

// An entry of the grid: segment k covers this cell at wrap t (its grown box, moved by -B t, overlaps the cell).
struct Entry {
    int k;
    Eigen::Vector2i t;
};

}  // namespace neighbour_cells

NeighbourList::NeighbourList(const Model& m, std::function<double(double)> range, double skin)
    : m_(m), range_(std::move(range)), skin_(skin) {
    if (!range_ || !(skin > 0)) throw std::invalid_argument("NeighbourList: a range and a skin > 0 are needed");
}

void NeighbourList::nodes(const SegmentPair& p, int node[4], Eigen::Vector2i shift[4]) const {
    const Segment& a = m_.segments[p.a];
    const Segment& b = m_.segments[p.b];
    node[0] = a.i, node[1] = a.j, node[2] = b.i, node[3] = b.j;
    shift[0] = Eigen::Vector2i::Zero(), shift[1] = a.shift, shift[2] = p.image, shift[3] = p.image + b.shift;
}

Eigen::Matrix<double, 8, 1> NeighbourList::coordinates(const SegmentPair& p, const Eigen::VectorXd& x,
                                                       const Eigen::Matrix2d& B) const {
    int node[4];
    Eigen::Vector2i shift[4];
    nodes(p, node, shift);
    Eigen::Matrix<double, 8, 1> X;
    for (int k = 0; k < 4; ++k) X.segment<2>(2 * k) = x.segment<2>(2 * node[k]) + B * shift[k].cast<double>();
    return X;
}

namespace neighbour_cells {

// The segments' ends next to their wrapped midpoints and their reaches, in the frame of the grid's box G (the periodic
// box B, or for an open box a box around every segment, far larger than any reach, without images).
struct Frame {
    Eigen::Matrix2d G, Gi;
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();
    double mean_reach = 1;
};

// Segment k's ends and reach at x (not yet wrapped).
SegInfo segment_info(const Model& m, int k, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                     const std::function<double(double)>& range, double skin) {
    const Segment& s = m.segments[k];
    SegInfo g;
    g.p0 = x.segment<2>(2 * s.i), g.p1 = x.segment<2>(2 * s.j) + B * s.shift.cast<double>();
    g.reach = range(1.5 * (g.p1 - g.p0).norm() + skin) + 0.5 * skin;
    return g;
}

// Moves a periodic segment's ends next to its wrapped midpoint.
void wrap_segment(SegInfo& g, const Frame& fr) {
    const Eigen::Vector2d f = fr.Gi * (0.5 * (g.p0 + g.p1));
    g.wrap = Eigen::Vector2i(static_cast<int>(std::floor(f.x())), static_cast<int>(std::floor(f.y())));
    const Eigen::Vector2d t = fr.G * g.wrap.cast<double>();
    g.p0 -= t, g.p1 -= t;
}

Frame segment_frame(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                    const std::function<double(double)>& range, double skin, std::vector<SegInfo>& seg) {
    const int ns = static_cast<int>(m.segments.size());
    Frame fr;
    fr.G = B;
    seg.assign(ns, SegInfo{});
    double reach_sum = 0;
    Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
    for (int k = 0; k < ns; ++k) {
        SegInfo& g = seg[k];
        g = segment_info(m, k, x, B, range, skin);
        reach_sum += g.reach;
        lo = lo.cwiseMin(g.p0.cwiseMin(g.p1)), hi = hi.cwiseMax(g.p0.cwiseMax(g.p1));
    }
    if (ns > 0) fr.mean_reach = reach_sum / ns;
    if (!m.box.periodic) {
        const double pad = 4 * fr.mean_reach + 1;
        fr.origin = lo - Eigen::Vector2d(pad, pad);
        fr.G = (hi - lo + Eigen::Vector2d(2 * pad, 2 * pad)).asDiagonal();
    }
    fr.Gi = fr.G.inverse();
    if (m.box.periodic)
        for (SegInfo& g : seg) wrap_segment(g, fr);
    return fr;
}

// Each segment's grown box entered into every cell of the grid it covers (cells about twice the mean reach a side,
// widths measured across the box's sides), and per segment the cells it covers.
struct CellGrid {
    int nx = 1, ny = 1;
    std::vector<std::vector<Entry>> cell, covers;  // covers: k is the cell's index
};

// The cells (with wraps) that segment g's box grown by `grow` covers; false if some of it lies outside an open box's grid.
bool cells_of(const SegInfo& g, double grow, const Frame& fr, const CellGrid& grid, bool periodic,
              std::vector<Entry>& out) {
    out.clear();
    bool inside = true;
    const int nx = grid.nx, ny = grid.ny;
    // The grown box's corners in grid coordinates (their bounding box there covers it in a sheared box too).
    const Eigen::Vector2d blo = g.p0.cwiseMin(g.p1) - Eigen::Vector2d::Constant(grow) - fr.origin;
    const Eigen::Vector2d bhi = g.p0.cwiseMax(g.p1) + Eigen::Vector2d::Constant(grow) - fr.origin;
    Eigen::Vector2d flo(1e300, 1e300), fhi(-1e300, -1e300);
    for (const Eigen::Vector2d& c : {blo, bhi, Eigen::Vector2d(blo.x(), bhi.y()), Eigen::Vector2d(bhi.x(), blo.y())}) {
        const Eigen::Vector2d f = fr.Gi * c;
        flo = flo.cwiseMin(f), fhi = fhi.cwiseMax(f);
    }
    const int x0 = static_cast<int>(std::floor(flo.x() * nx)), x1 = static_cast<int>(std::floor(fhi.x() * nx));
    const int y0 = static_cast<int>(std::floor(flo.y() * ny)), y1 = static_cast<int>(std::floor(fhi.y() * ny));
    for (int cy = y0; cy <= y1; ++cy)
        for (int cx = x0; cx <= x1; ++cx) {
            const int wx = static_cast<int>(std::floor(static_cast<double>(cx) / nx));
            const int wy = static_cast<int>(std::floor(static_cast<double>(cy) / ny));
            if (!periodic && (wx != 0 || wy != 0)) {
                inside = false;
                continue;
            }
            out.push_back({(cy - wy * ny) * nx + (cx - wx * nx), Eigen::Vector2i(wx, wy)});
        }
    return inside;
}

CellGrid cover_cells(const std::vector<SegInfo>& seg, const Frame& fr, bool periodic) {
    const int ns = static_cast<int>(seg.size());
    const double area = std::abs(fr.G.determinant()), side = std::max(2 * fr.mean_reach, 1e-9);
    CellGrid grid;
    grid.nx = std::max(1, static_cast<int>(std::floor(area / fr.G.col(1).norm() / side)));
    grid.ny = std::max(1, static_cast<int>(std::floor(area / fr.G.col(0).norm() / side)));
    grid.cell.resize(static_cast<size_t>(grid.nx) * grid.ny);
    grid.covers.resize(ns);
    for (int k = 0; k < ns; ++k) {
        cells_of(seg[k], seg[k].reach, fr, grid, periodic, grid.covers[k]);
        for (const Entry& c : grid.covers[k]) grid.cell[static_cast<size_t>(c.k)].push_back({k, c.t});
    }
    return grid;
}

// Segment a's pairs: every b > a of another fiber sharing a cell, each (b, image) tested once (a mark per b, in
// seen_a / seen_image), within range + skin exactly, sorted by b and image.
void pairs_of(int a, const Model& m, const std::vector<SegInfo>& seg, const CellGrid& grid, const Frame& fr,
              double skin, std::vector<int>& seen_a, std::vector<Eigen::Vector2i>& seen_image,
              std::vector<SegmentPair>& out) {
    const SegInfo& A = seg[a];
    const Segment& sa = m.segments[a];
    for (const Entry& ca : grid.covers[a])
        for (const Entry& eb : grid.cell[static_cast<size_t>(ca.k)]) {
            const int b = eb.k;
            if (b <= a || m.segments[b].fiber == sa.fiber) continue;
            // a's copy moved by -B t_a and b's by -B t_b meet in this cell: b lies at image t_a - t_b next to a in
            // the wrapped frames, (t_a - t_b) - wrap_b + wrap_a from a's first node.
            const Eigen::Vector2i rel = ca.t - eb.t;
            SegmentPair p;
            p.a = a, p.b = b, p.image = rel - seg[b].wrap + A.wrap;
            if (seen_a[b] == a && seen_image[b] == p.image) continue;
            seen_a[b] = a, seen_image[b] = p.image;
            if (touch(sa, m.segments[b], p.image)) continue;
            const SegInfo& Bs = seg[b];
            const Eigen::Vector2d tt = fr.G * rel.cast<double>();
            const double cut = std::max(A.reach, Bs.reach) + 0.5 * skin;
            if (segment_distance(A.p0, A.p1, Bs.p0 + tt, Bs.p1 + tt) >= cut) continue;
            out.push_back(p);
        }
    std::sort(out.begin(), out.end(), [](const SegmentPair& p, const SegmentPair& q) {
        if (p.b != q.b) return p.b < q.b;
        if (p.image.x() != q.image.x()) return p.image.x() < q.image.x();
        return p.image.y() < q.image.y();
    });
    out.erase(std::unique(out.begin(), out.end(),
                          [](const SegmentPair& p, const SegmentPair& q) { return p.b == q.b && p.image == q.image; }),
              out.end());
}

}  // namespace neighbour_cells

// What a full build keeps for update(): the grid's frame, the segments' cells and their ends, wraps and reaches as
// last entered.
struct NeighbourList::Cache {
    neighbour_cells::Frame fr;
    neighbour_cells::CellGrid grid;
    std::vector<neighbour_cells::SegInfo> seg;
    // find()'s work arrays, per segment, kept so that a search costs the segments it moves, not the network: whether
    // a segment is one of those moved (in, cleared after), the pass that last met it next to a moved segment and at
    // which image (seen, seen_image: each (b, image) is tested once per moved segment, not once per cell they share),
    // and its ends and reach at the update's positions (info, valid when info_pass is the update's pass).
    struct Scratch {
        std::vector<char> in;
        std::vector<long> seen, info_pass;
        std::vector<Eigen::Vector2i> seen_image;
        std::vector<neighbour_cells::SegInfo> info;
        long pass = 0;
        void size(size_t ns) {
            if (in.size() == ns) return;
            in.assign(ns, 0), seen.assign(ns, -1), info_pass.assign(ns, -1);
            seen_image.assign(ns, Eigen::Vector2i::Zero()), info.assign(ns, neighbour_cells::SegInfo{});
        }
    } scratch;
};

namespace {
bool pair_less(const SegmentPair& p, const SegmentPair& q) {
    if (p.a != q.a) return p.a < q.a;
    if (p.b != q.b) return p.b < q.b;
    if (p.image.x() != q.image.x()) return p.image.x() < q.image.x();
    return p.image.y() < q.image.y();
}
bool pair_equal(const SegmentPair& p, const SegmentPair& q) { return p.a == q.a && p.b == q.b && p.image == q.image; }
}  // namespace

void NeighbourList::build(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double skin) {
    using namespace neighbour_cells;
    const int ns = static_cast<int>(m_.segments.size());
    built_skin_ = std::max(skin, skin_);
    std::vector<SegInfo> seg;
    const Frame fr = segment_frame(m_, x, B, range_, built_skin_, seg);
    CellGrid grid = cover_cells(seg, fr, m_.box.periodic);
    std::vector<std::vector<SegmentPair>> found(ns);
    parallel_ranges(ns, ns >= 2048 ? thread_count() : 1, [&](size_t lo, size_t hi) {
        std::vector<int> seen_a(ns, -1);
        std::vector<Eigen::Vector2i> seen_image(ns);
        for (size_t a = lo; a < hi; ++a)
            pairs_of(static_cast<int>(a), m_, seg, grid, fr, built_skin_, seen_a, seen_image, found[a]);
    });
    size_t total = 0;
    for (const auto& f : found) total += f.size();
    pairs_.clear();
    pairs_.reserve(total);
    for (const auto& f : found) pairs_.insert(pairs_.end(), f.begin(), f.end());
    x_built_ = x;
    B_built_ = B;
    cache_ = std::make_shared<Cache>(Cache{fr, std::move(grid), std::move(seg), {}});
    found_build_ = -1;
    ++listings_;
    origin_.clear();
    origin_build_ = -1;
    ++builds_;
}

bool NeighbourList::find(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& segments,
                         const std::vector<int>& nodes, std::vector<SegmentPair>& found) {
    using namespace neighbour_cells;
    if (!cache_ || builds_ == 0 || B != B_built_ || x.size() != x_built_.size()) return build(x, B), false;
    if (cache_.use_count() > 1) cache_ = std::make_shared<Cache>(*cache_);  // copies of this list keep theirs
    Cache& c = *cache_;
    const bool periodic = m_.box.periodic;
    // A held node (of either segment) may lie skin / 2 from where it was built and move skin / 2 further, so a pair's
    // distance can change by 2 skins before the list is invalid: pairs are kept within range + 2 skins (one more than
    // a build's range + skin). The grid holds held segments where they were entered, up to skin / 2 from where they
    // are now, and the cells are searched a further skin out.
    const double extra = built_skin_, grow = 2 * built_skin_;
    std::vector<Entry> cells;
    if (!periodic)  // an open box's grid covers the segments as built, with a margin: a segment beyond it needs a build
        for (int a : segments) {
            const SegInfo g = segment_info(m_, a, x, B, range_, built_skin_);
            if (!cells_of(g, g.reach + grow, c.fr, c.grid, periodic, cells)) return build(x, B), false;
        }
    Cache::Scratch& w = c.scratch;
    w.size(m_.segments.size());
    std::vector<char>& in = w.in;
    for (int a : segments) in[a] = 1;
    const long update_pass = ++w.pass;  // info[b] is b's at x if info_pass[b] is this
    // The segments entered anew at x.
    for (int a : segments) {
        for (const Entry& e : c.grid.covers[a]) {
            std::vector<Entry>& cell = c.grid.cell[static_cast<size_t>(e.k)];
            cell.erase(std::remove_if(cell.begin(), cell.end(), [&](const Entry& f) { return f.k == a && f.t == e.t; }),
                       cell.end());
        }
        SegInfo g = segment_info(m_, a, x, B, range_, built_skin_);
        if (periodic) wrap_segment(g, c.fr);
        c.seg[a] = g;
        cells_of(g, g.reach, c.fr, c.grid, periodic, c.grid.covers[a]);
        for (const Entry& e : c.grid.covers[a]) c.grid.cell[static_cast<size_t>(e.k)].push_back({a, e.t});
    }
    found.clear();
    for (int a : segments) {
        const SegInfo& A = c.seg[a];
        const long a_pass = ++w.pass;  // seen[b]: a's pass met b at seen_image[b] already
        cells_of(A, A.reach + grow, c.fr, c.grid, periodic, cells);
        for (const Entry& ca : cells)
            for (const Entry& eb : c.grid.cell[static_cast<size_t>(ca.k)]) {
                const int b = eb.k;
                if (b == a || m_.segments[b].fiber == m_.segments[a].fiber || (in[b] && b < a)) continue;
                const Eigen::Vector2i rel = ca.t - eb.t;
                const Eigen::Vector2i image = rel - c.seg[b].wrap + A.wrap;  // b's first node next to a's
                if (w.seen[b] == a_pass && w.seen_image[b] == image) continue;  // met in another cell
                w.seen[b] = a_pass, w.seen_image[b] = image;
                SegmentPair p;
                if (a < b) p.a = a, p.b = b, p.image = image;
                else p.a = b, p.b = a, p.image = -image;
                if (touch(m_.segments[p.a], m_.segments[p.b], p.image)) continue;
                // b where it is now, in the frame of its cells
                if (w.info_pass[b] != update_pass)
                    w.info[b] = segment_info(m_, b, x, B, range_, built_skin_), w.info_pass[b] = update_pass;
                const SegInfo& Bn = w.info[b];
                const Eigen::Vector2d tt = c.fr.G * (rel - c.seg[b].wrap).cast<double>();
                const double cut = std::max(A.reach, Bn.reach) + 0.5 * built_skin_ + extra;
                if (segment_distance(A.p0, A.p1, Bn.p0 + tt, Bn.p1 + tt) >= cut) continue;
                found.push_back(p);
            }
    }
    std::sort(found.begin(), found.end(), pair_less);
    found.erase(std::unique(found.begin(), found.end(), pair_equal), found.end());
    for (int a : segments) in[a] = 0;
    for (int v : nodes) x_built_.segment<2>(2 * v) = x.segment<2>(2 * v);
    found_build_ = builds_;
    ++listings_;
    return true;
}

void NeighbourList::replace(const std::vector<int>& segments, const std::vector<SegmentPair>& found) {
    if (found_build_ != builds_) throw std::logic_error("NeighbourList::replace: the list changed since find()");
    found_build_ = -1;
    std::vector<char>& in = cache_->scratch.in;
    for (int a : segments) in[a] = 1;
    // The kept pairs (no segment of `segments`) and the found ones, merged in list order; each pair remembers its
    // index before the update (origin(), -1 if found), so that callers re-index only the found ones. The two sets are
    // disjoint, so the order is std::merge's.
    std::vector<SegmentPair>& merged = merged_;
    std::vector<int>& origin = origin_next_;
    merged.clear(), origin.clear();
    merged.reserve(pairs_.size() + found.size()), origin.reserve(pairs_.size() + found.size());
    size_t j = 0;
    for (size_t k = 0; k < pairs_.size(); ++k) {
        const SegmentPair& p = pairs_[k];
        if (in[p.a] || in[p.b]) continue;
        for (; j < found.size() && pair_less(found[j], p); ++j) merged.push_back(found[j]), origin.push_back(-1);
        merged.push_back(p), origin.push_back(static_cast<int>(k));
    }
    for (; j < found.size(); ++j) merged.push_back(found[j]), origin.push_back(-1);
    pairs_.swap(merged);
    origin_.swap(origin);
    origin_build_ = builds_;
    for (int a : segments) in[a] = 0;
    ++builds_;
}

void NeighbourList::update(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& segments,
                           const std::vector<int>& nodes) {
    std::vector<SegmentPair> found;
    if (find(x, B, segments, nodes, found)) replace(segments, found);
}

bool NeighbourList::valid(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    if (builds_ == 0 || B != B_built_ || x.size() != x_built_.size()) return false;
    if (pending()) return false;  // a region's pairs found but not yet replaced: the list is not whole
    const double h2 = 0.25 * built_skin_ * built_skin_;
    for (Eigen::Index k = 0; k + 1 < x.size(); k += 2) {
        const double dx = x[k] - x_built_[k], dy = x[k + 1] - x_built_[k + 1];
        if (dx * dx + dy * dy > h2) return false;
    }
    return true;
}

bool NeighbourList::valid_at(const std::vector<int>& nodes, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    if (builds_ == 0 || B != B_built_ || x.size() != x_built_.size()) return false;
    const double h2 = 0.25 * built_skin_ * built_skin_;
    for (int v : nodes) {
        const double dx = x[2 * v] - x_built_[2 * v], dy = x[2 * v + 1] - x_built_[2 * v + 1];
        if (dx * dx + dy * dy > h2) return false;
    }
    return true;
}

double NeighbourList::max_displacement(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    if (builds_ == 0 || B != B_built_ || x.size() != x_built_.size()) return std::numeric_limits<double>::infinity();
    double m2 = 0;
    for (Eigen::Index k = 0; k + 1 < x.size(); k += 2) {
        const double dx = x[k] - x_built_[k], dy = x[k + 1] - x_built_[k + 1];
        m2 = std::max(m2, dx * dx + dy * dy);
    }
    return std::sqrt(m2);
}

}  // namespace fibernet
