#pragma once
// Segment pairs within a distance, with a skin (as molecular dynamics lists atoms; issue 22). The distance may grow
// with the segments' lengths: range(L) for a segment of length up to L (a pair's is the larger of its two). Built at
// positions x_b for range + skin, the list holds every pair of segments of different fibers that can come within range
// while no node has moved more than skin / 2 from x_b, no segment has grown beyond 1.5x its length plus the skin, and
// the box is unchanged. Pairs of segments that share a node (at a crosslink) are left out. Broad phase: each segment's
// bounding box, grown by its range and half the skin, is entered into every cell of a grid over the (possibly sheared)
// periodic box that it covers (long segments cover several cells, so one long segment does not coarsen the grid);
// pairs sharing a cell are then tested exactly. Pairs are in a fixed order (segment a ascending, then b, then image),
// so every sum over them is the same on every platform and for any thread count.
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "fibernet/model/model.hpp"

namespace fibernet {

struct SegmentPair {
    int a = 0, b = 0;             // segments, a < b, of different fibers
    Eigen::Vector2i image{0, 0};  // b's first node is taken at x + B image, next to a's first node
};

class NeighbourList {
public:
    // Keeps a reference to m. range(L) > 0, skin > 0.
    NeighbourList(const Model& m, std::function<double(double)> range, double skin);

    // Rebuilds the list at node positions x (2 per node) in the box B (model units), with the skin given at
    // construction or, for this build, `skin` (>= that one).
    void build(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double skin = 0);
    // The list anew for the pairs that hold one of `segments`, at x, after the nodes `nodes` moved (a region's local
    // solve). `segments` must hold every segment with a node in `nodes`, and every other node must lie within skin / 2
    // of where it was built; only `nodes` are recorded as built anew. The pairs are found on the grid of the last full
    // build and kept within the range plus 2 skins (a pair's distance can change by 2 skins before the list is invalid
    // again: a held node may lie skin / 2 from its build and move skin / 2 further), at the cost of the segments'
    // neighbours plus one pass over the pairs. Counts as a build. Without a full build before, in another box, or with
    // a segment beyond an open box's grid: a full build at x.
    void update(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& segments,
                const std::vector<int>& nodes);
    // update() in two steps, so that a region's local solve can keep its pairs to itself while it moves and pay for the
    // list's other pairs once, when it ends. find() lists the pairs that hold one of `segments` at x (`found`, in list
    // order) and records `nodes` as built anew, but leaves pairs() as they were: until replace(), the list holds the
    // pairs of every other segment, valid as before, and stale ones of `segments`. False (and `found` unused) when it
    // made a full build at x instead (see update()). replace() then puts `found` in place of the pairs of `segments`
    // (the same segments), with origin() as update() gives it; the list must not have changed since find().
    bool find(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& segments,
              const std::vector<int>& nodes, std::vector<SegmentPair>& found);
    void replace(const std::vector<int>& segments, const std::vector<SegmentPair>& found);
    // A find() awaits its replace(): valid() is false meanwhile (valid_at() is not), so that a whole-list user
    // rebuilds instead of reading stale pairs; a build makes the pending find void.
    bool pending() const { return found_build_ >= 0 && found_build_ == builds_; }
    // The largest displacement of a node from its position at the last build (infinity if none or B differs).
    double max_displacement(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const;
    const Eigen::VectorXd& built_at() const { return x_built_; }
    // Whether the list still holds every pair within `range` at x in the box B (built, same B, every node within
    // skin / 2 of where it was at the build, no find() pending).
    bool valid(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const;
    // valid() for a state that differs from one where the list is valid only at `nodes` (a region's local solve).
    bool valid_at(const std::vector<int>& nodes, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const;
    const std::vector<SegmentPair>& pairs() const { return pairs_; }
    // Changes of pairs() (builds and replacements): what an index over the pairs is kept against.
    int builds() const { return builds_; }
    // Searches for pairs: full builds, and find() for a region (update() is one).
    int listings() const { return listings_; }
    // When the list was last changed by update(): the build it was updated from (builds() - 1), and per pair its index
    // in that build's list, or -1 for a pair found anew. After a full build: -1 and no origins.
    int origin_build() const { return origin_build_; }
    const std::vector<int>& origin() const { return origin_; }
    double skin() const { return skin_; }

    // Local coordinates (p0, p1, q0, q1) of pair k at positions x in box B.
    Eigen::Matrix<double, 8, 1> coordinates(const SegmentPair& p, const Eigen::VectorXd& x,
                                            const Eigen::Matrix2d& B) const;
    // The four nodes of a pair and their images (in the order of coordinates()).
    void nodes(const SegmentPair& p, int node[4], Eigen::Vector2i shift[4]) const;

private:
    const Model& m_;
    std::function<double(double)> range_;
    double skin_, built_skin_ = 0;
    std::vector<SegmentPair> pairs_;
    Eigen::VectorXd x_built_;
    Eigen::Matrix2d B_built_ = Eigen::Matrix2d::Zero();
    int builds_ = 0, listings_ = 0;
    int found_build_ = -1;  // builds_ at the last find(), -1 once replaced or rebuilt
    int origin_build_ = -1;
    std::vector<int> origin_;
    std::vector<SegmentPair> merged_;  // replace()'s buffers (swapped with pairs_ and origin_), kept between calls
    std::vector<int> origin_next_;
    struct Cache;
    std::shared_ptr<Cache> cache_;  // the last full build's grid, for update()
};

}  // namespace fibernet
