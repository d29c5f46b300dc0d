#include "fibernet/wet/neighbour_list.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fibernet/util/parallel.hpp"
#include "fibernet/wet/capillary_pair.hpp"

namespace fibernet {

namespace {

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

}  // namespace

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

void NeighbourList::build(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double skin) {
    const int ns = static_cast<int>(m_.segments.size());
    built_skin_ = std::max(skin, skin_);
    const bool periodic = m_.box.periodic;
    // Open box: a box around every segment, far larger than any reach, with no images.
    Eigen::Matrix2d G = B;
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();
    std::vector<SegInfo> seg(ns);
    double reach_sum = 0;
    Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
    for (int k = 0; k < ns; ++k) {
        const Segment& s = m_.segments[k];
        const Eigen::Vector2d a = x.segment<2>(2 * s.i), b = x.segment<2>(2 * s.j) + B * s.shift.cast<double>();
        SegInfo& g = seg[k];
        g.reach = range_(1.5 * (b - a).norm() + built_skin_) + 0.5 * built_skin_;
        reach_sum += g.reach;
        lo = lo.cwiseMin(a.cwiseMin(b)), hi = hi.cwiseMax(a.cwiseMax(b));
        g.p0 = a, g.p1 = b;
    }
    if (!periodic) {
        const double pad = 4 * (ns > 0 ? reach_sum / ns : 1) + 1;
        origin = lo - Eigen::Vector2d(pad, pad);
        const Eigen::Vector2d ext = hi - lo + Eigen::Vector2d(2 * pad, 2 * pad);
        G = ext.asDiagonal();
    }
    const Eigen::Matrix2d Gi = G.inverse();
    for (SegInfo& g : seg) {
        if (periodic) {
            const Eigen::Vector2d f = Gi * (0.5 * (g.p0 + g.p1));
            g.wrap = Eigen::Vector2i(static_cast<int>(std::floor(f.x())), static_cast<int>(std::floor(f.y())));
            const Eigen::Vector2d t = G * g.wrap.cast<double>();
            g.p0 -= t, g.p1 -= t;
        }
    }
    // Cells about twice the mean reach a side (at least 1 per side); widths across the box's sides.
    const double area = std::abs(G.determinant());
    const double side = std::max(2 * (ns > 0 ? reach_sum / ns : 1.0), 1e-9);
    const int nx = std::max(1, static_cast<int>(std::floor(area / G.col(1).norm() / side)));
    const int ny = std::max(1, static_cast<int>(std::floor(area / G.col(0).norm() / side)));
    std::vector<std::vector<Entry>> cell(static_cast<size_t>(nx) * ny);
    std::vector<std::vector<Entry>> covers(ns);  // per segment: the cells it covers (k: the cell's index) and wraps
    for (int k = 0; k < ns; ++k) {
        const SegInfo& g = seg[k];
        // The grown box's corners in grid coordinates (their bounding box there covers it in a sheared box too).
        const Eigen::Vector2d blo = g.p0.cwiseMin(g.p1) - Eigen::Vector2d::Constant(g.reach) - origin;
        const Eigen::Vector2d bhi = g.p0.cwiseMax(g.p1) + Eigen::Vector2d::Constant(g.reach) - origin;
        Eigen::Vector2d flo(1e300, 1e300), fhi(-1e300, -1e300);
        for (const Eigen::Vector2d& c : {blo, bhi, Eigen::Vector2d(blo.x(), bhi.y()), Eigen::Vector2d(bhi.x(), blo.y())}) {
            const Eigen::Vector2d f = Gi * c;
            flo = flo.cwiseMin(f), fhi = fhi.cwiseMax(f);
        }
        const int x0 = static_cast<int>(std::floor(flo.x() * nx)), x1 = static_cast<int>(std::floor(fhi.x() * nx));
        const int y0 = static_cast<int>(std::floor(flo.y() * ny)), y1 = static_cast<int>(std::floor(fhi.y() * ny));
        for (int cy = y0; cy <= y1; ++cy)
            for (int cx = x0; cx <= x1; ++cx) {
                const int wx = static_cast<int>(std::floor(static_cast<double>(cx) / nx));
                const int wy = static_cast<int>(std::floor(static_cast<double>(cy) / ny));
                if (!periodic && (wx != 0 || wy != 0)) continue;
                const int ci = (cy - wy * ny) * nx + (cx - wx * nx);
                cell[static_cast<size_t>(ci)].push_back({k, Eigen::Vector2i(wx, wy)});
                covers[k].push_back({ci, Eigen::Vector2i(wx, wy)});
            }
    }
    // Per segment a: every b > a sharing a cell, each (b, image) tested once (a mark per b), then sorted.
    std::vector<std::vector<SegmentPair>> found(ns);
    const int threads = ns >= 2048 ? thread_count() : 1;
    parallel_ranges(ns, threads, [&](size_t lo_k, size_t hi_k) {
        std::vector<int> seen_a(ns, -1);
        std::vector<Eigen::Vector2i> seen_image(ns);
        for (size_t ka = lo_k; ka < hi_k; ++ka) {
            const int a = static_cast<int>(ka);
            const SegInfo& A = seg[a];
            const Segment& sa = m_.segments[a];
            std::vector<SegmentPair>& out = found[a];
            for (const Entry& ca : covers[a])
                for (const Entry& eb : cell[static_cast<size_t>(ca.k)]) {
                    const int b = eb.k;
                    if (b <= a || m_.segments[b].fiber == sa.fiber) continue;
                    // a's copy moved by -B t_a and b's by -B t_b meet in this cell: b lies at image t_a - t_b next to
                    // a in the wrapped frames, (t_a - t_b) - wrap_b + wrap_a from a's first node.
                    const Eigen::Vector2i rel = ca.t - eb.t;
                    SegmentPair p;
                    p.a = a, p.b = b, p.image = rel - seg[b].wrap + A.wrap;
                    if (seen_a[b] == a && seen_image[b] == p.image) continue;
                    seen_a[b] = a, seen_image[b] = p.image;
                    if (touch(sa, m_.segments[b], p.image)) continue;
                    const SegInfo& Bs = seg[b];
                    const Eigen::Vector2d tt = G * rel.cast<double>();
                    const double cut = std::max(A.reach, Bs.reach) + 0.5 * built_skin_;
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
    });
    size_t total = 0;
    for (const auto& f : found) total += f.size();
    pairs_.clear();
    pairs_.reserve(total);
    for (const auto& f : found) pairs_.insert(pairs_.end(), f.begin(), f.end());
    x_built_ = x;
    B_built_ = B;
    ++builds_;
}

bool NeighbourList::valid(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    if (builds_ == 0 || B != B_built_ || x.size() != x_built_.size()) return false;
    const double h2 = 0.25 * built_skin_ * built_skin_;
    for (Eigen::Index k = 0; k + 1 < x.size(); k += 2) {
        const double dx = x[k] - x_built_[k], dy = x[k + 1] - x_built_[k + 1];
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
