// NeighbourList (neighbour_list.hpp): a build holds every pair of segments of different fibers within range, against a
// brute-force search over all pairs and periodic images, in a sheared box; it stays complete while every node moves
// less than half the skin; update() after a region moved far holds the pairs at the new state and keeps the list
// complete under further moves within half the skin of where each node was last built.
#include <catch2/catch.hpp>
#include <cmath>
#include <algorithm>
#include <map>
#include <set>
#include <tuple>

#include "fibernet/wet/capillary_pair.hpp"
#include "fibernet/wet/neighbour_list.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {

constexpr double kRange = 0.8, kSkin = 0.5;

// Pairs (a < b, image) of segments of different fibers sharing no node, within kRange at positions x in box B: every
// image within two box lengths.
std::set<std::tuple<int, int, int, int>> brute_force(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                                     double range = kRange) {
    std::set<std::tuple<int, int, int, int>> out;
    const int ns = static_cast<int>(m.segments.size());
    for (int a = 0; a < ns; ++a)
        for (int b = a + 1; b < ns; ++b) {
            const Segment &sa = m.segments[a], &sb = m.segments[b];
            if (sa.fiber == sb.fiber || sa.i == sb.i || sa.i == sb.j || sa.j == sb.i || sa.j == sb.j) continue;
            const Eigen::Vector2d a0 = x.segment<2>(2 * sa.i), a1 = x.segment<2>(2 * sa.j) + B * sa.shift.cast<double>();
            for (int tx = -2; tx <= 2; ++tx)
                for (int ty = -2; ty <= 2; ++ty) {
                    const Eigen::Vector2i t(tx, ty);
                    const Eigen::Vector2d b0 = x.segment<2>(2 * sb.i) + B * t.cast<double>();
                    const Eigen::Vector2d b1 = x.segment<2>(2 * sb.j) + B * (t + sb.shift).cast<double>();
                    if (segment_distance(a0, a1, b0, b1) < range) out.insert({a, b, tx, ty});
                }
        }
    return out;
}

// The pairs within range that the list lacks.
int missing(const NeighbourList& list, const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
            double range = kRange) {
    std::set<std::tuple<int, int, int, int>> listed;
    for (const SegmentPair& p : list.pairs()) listed.insert({p.a, p.b, p.image.x(), p.image.y()});
    int n = 0;
    for (const auto& p : brute_force(m, x, B, range)) n += !listed.count(p);
    return n;
}

// x with every node moved by a random vector of length below r (seeded).
Eigen::VectorXd jiggle(Eigen::VectorXd x, double r, std::uint64_t seed, const std::vector<int>& nodes) {
    const Eigen::VectorXd d = perturb(Eigen::VectorXd::Zero(x.size()), 1.0, seed);
    for (int v : nodes) {
        const Eigen::Vector2d u = d.segment<2>(2 * v);
        x.segment<2>(2 * v) += 0.99 * r * u / std::max(1.0, u.norm());
    }
    return x;
}

// Node positions of m's reference state under the deformation F.
Eigen::VectorXd deformed(const Model& m, const Eigen::Matrix2d& F) {
    Eigen::VectorXd x(2 * m.num_nodes());
    for (int v = 0; v < m.num_nodes(); ++v) x.segment<2>(2 * v) = F * m.x.segment<2>(2 * v);
    return x;
}

// Whether the pairs are in the list's order (segment a, then b, then image) with none twice.
bool strictly_ordered(const std::vector<SegmentPair>& P) {
    bool ordered = true;
    for (size_t k = 1; k < P.size(); ++k)
        ordered = ordered && std::tie(P[k - 1].a, P[k - 1].b, P[k - 1].image.x(), P[k - 1].image.y()) <
                                 std::tie(P[k].a, P[k].b, P[k].image.x(), P[k].image.y());
    return ordered;
}

// A region: the nodes within `radius` of c at x, and the segments with a node among them.
void region_of(const Model& m, const Eigen::VectorXd& x, const Eigen::Vector2d& c, double radius, std::vector<int>& nodes,
               std::vector<int>& segs) {
    std::vector<char> in(m.num_nodes(), 0);
    nodes.clear(), segs.clear();
    for (int v = 0; v < m.num_nodes(); ++v)
        if ((x.segment<2>(2 * v) - c).norm() < radius) nodes.push_back(v), in[v] = 1;
    for (int s = 0; s < static_cast<int>(m.segments.size()); ++s)
        if (in[m.segments[s].i] || in[m.segments[s].j]) segs.push_back(s);
}

}  // namespace

TEST_CASE("neighbour list: every pair within range, built and updated", "[wet][neighbour_list]") {
    const Model m = model_of(mikado(2.5, 6, 0.5, 5), 8);
    Eigen::Matrix2d F;
    F << 1.02, 0.08, 0.0, 0.99;
    const Eigen::Matrix2d B = F * m.box.B0();
    const Eigen::VectorXd x = deformed(m, F);
    std::vector<int> all(m.num_nodes());
    for (int v = 0; v < m.num_nodes(); ++v) all[v] = v;
    NeighbourList list(m, [](double) { return kRange; }, kSkin);
    list.build(x, B);
    REQUIRE(brute_force(m, x, B).size() > 50);
    CHECK(missing(list, m, x, B) == 0);
    // Every node moved by less than half the skin: still complete, still valid.
    const Eigen::VectorXd x1 = jiggle(x, kSkin / 2, 3, all);
    CHECK(list.valid(x1, B));
    CHECK(missing(list, m, x1, B) == 0);

    // A region (the nodes within 6 of a node) moved by 4 along x: invalid there; update() for its segments.
    const Eigen::Vector2d c = x1.segment<2>(2 * (m.num_nodes() / 2));
    std::vector<int> nodes, segs;
    region_of(m, x1, c, 6, nodes, segs);
    REQUIRE(nodes.size() > 10);
    Eigen::VectorXd x2 = x1;
    for (int v : nodes) x2[2 * v] += 4.0;
    CHECK(!list.valid_at(nodes, x2, B));
    const int before = missing(list, m, x2, B);
    CHECK(before > 0);  // the move brought pairs into range that the list lacks
    const int builds = list.builds();
    CHECK(list.origin_build() == -1);  // built, not updated
    const std::vector<SegmentPair> old_pairs = list.pairs();
    list.update(x2, B, segs, nodes);
    CHECK(list.builds() == builds + 1);
    // Each pair's origin: its index in the list before the update (the same pair), or -1 for one found anew, which
    // holds a segment of the region.
    REQUIRE(list.origin_build() == builds);
    REQUIRE(list.origin().size() == list.pairs().size());
    std::vector<char> in_segs(m.segments.size(), 0);
    for (int s : segs) in_segs[s] = 1;
    int kept = 0, found = 0, wrong = 0;
    for (size_t k = 0; k < list.pairs().size(); ++k) {
        const SegmentPair& p = list.pairs()[k];
        const int o = list.origin()[k];
        if (o < 0) {
            ++found;
            wrong += !(in_segs[p.a] || in_segs[p.b]);
            continue;
        }
        ++kept;
        const SegmentPair& q = old_pairs[static_cast<size_t>(o)];
        wrong += q.a != p.a || q.b != p.b || q.image != p.image || in_segs[p.a] || in_segs[p.b];
    }
    CHECK(wrong == 0);
    CHECK(kept > 0);
    CHECK(found > 0);
    CHECK(list.valid(x2, B));
    CHECK(missing(list, m, x2, B) == 0);
    // Then every node within half the skin of where it was last built (the region's nodes of x2, the others of x):
    // complete. Held nodes already lay up to half a skin from their build in x1, so the pairs changed by two skins.
    for (std::uint64_t seed : {5, 6, 7}) {
        Eigen::VectorXd x3 = jiggle(list.built_at(), kSkin / 2, seed, all);
        REQUIRE(list.valid(x3, B));
        CHECK(missing(list, m, x3, B) == 0);
    }
    // A second region, overlapping the first, moved the other way: the same.
    std::vector<int> nodes2, segs2;
    region_of(m, x2, c + Eigen::Vector2d(4.0, 5.0), 5, nodes2, segs2);
    REQUIRE(nodes2.size() > 10);
    Eigen::VectorXd x4 = x2;
    for (int v : nodes2) x4[2 * v + 1] -= 3.0;
    list.update(x4, B, segs2, nodes2);
    CHECK(missing(list, m, x4, B) == 0);
    for (std::uint64_t seed : {8, 9}) {
        Eigen::VectorXd x5 = jiggle(list.built_at(), kSkin / 2, seed, all);
        REQUIRE(list.valid(x5, B));
        CHECK(missing(list, m, x5, B) == 0);
    }
    // The pairs stay in the list's order (segment a, then b, then image), as a build gives them.
    CHECK(strictly_ordered(list.pairs()));
}

TEST_CASE("neighbour list: update() lists the pairs that held nodes' drift and the region's can bring into range",
          "[wet][neighbour_list]") {
    // Two parallel fibers, 5 apart (not listed). At the update the held fiber has drifted 0.2475 away from where the
    // region (the other fiber) is put, 1.54 from it: beyond range + skin (1.3), so a build would not list the pair.
    // Then the held fiber drifts 0.2475 the other way (within half the skin of its build) and the region 0.2475 toward
    // it: 0.7975 apart, within range. update() must have listed the pair: a margin of 1.5 skins beyond the range is
    // needed here (2 where the moved segment also has a held node).
    const Model m = model_of(network_of({{1.5, 1.5, 0, 1, 0.5}, {1.5, 2.0, 0, 1, 0.5}}, 3));
    const Eigen::Matrix2d B = m.box.B0();
    const Eigen::VectorXd x = m.x;
    std::vector<int> held, region, segs;
    for (int v = 0; v < m.num_nodes(); ++v) (x[2 * v + 1] < 17.5 ? held : region).push_back(v);
    for (int s = 0; s < static_cast<int>(m.segments.size()); ++s)
        if (m.segments[s].fiber == m.segments[0].fiber + 1) segs.push_back(s);
    REQUIRE(held.size() == region.size());
    REQUIRE(!segs.empty());
    NeighbourList list(m, [](double) { return kRange; }, kSkin);
    list.build(x, B);
    CHECK(list.pairs().empty());
    const double drift = 0.99 * kSkin / 2;
    Eigen::VectorXd xu = x;
    for (int v : held) xu[2 * v + 1] -= drift;
    for (int v : region) xu[2 * v + 1] = x[2 * held[0] + 1] - drift + 1.54;
    list.update(xu, B, segs, region);
    Eigen::VectorXd xf = xu;
    for (int v : held) xf[2 * v + 1] = x[2 * v + 1] + drift;
    for (int v : region) xf[2 * v + 1] -= drift;
    REQUIRE(list.valid(xf, B));
    REQUIRE(!brute_force(m, xf, B).empty());
    CHECK(missing(list, m, xf, B) == 0);
}

TEST_CASE("neighbour list: update() with a range beyond half the box lists each pair at every image in range",
          "[wet][neighbour_list]") {
    // A range of 12 in a sheared box 21 units wide: a pair of segments lies within range at several images, the grid
    // has a single cell, and update() meets each neighbour there at several wraps. It must test each (segment, image)
    // on its own and list each once.
    constexpr double kWide = 12;
    const Model m = model_of(mikado(2.1, 2, 0.5, 11), 4);
    Eigen::Matrix2d F;
    F << 1.0, 0.3, 0.0, 1.0;
    const Eigen::Matrix2d B = F * m.box.B0();
    const Eigen::VectorXd x = deformed(m, F);
    NeighbourList list(m, [](double) { return kWide; }, kSkin);
    list.build(x, B);
    REQUIRE(missing(list, m, x, B, kWide) == 0);
    // Pairs within range at two or more images: the case this test is about.
    std::map<std::pair<int, int>, int> images;
    for (const auto& p : brute_force(m, x, B, kWide)) ++images[{std::get<0>(p), std::get<1>(p)}];
    int multi = 0;
    for (const auto& ab_n : images) multi += ab_n.second > 1;
    REQUIRE(multi > 5);
    // The first fiber's nodes moved by 5 along x and 3 along y, then the list updated for their segments.
    std::vector<char> in(m.num_nodes(), 0);
    for (const Segment& s : m.segments)
        if (s.fiber == 0) in[s.i] = in[s.j] = 1;
    std::vector<int> nodes, segs;
    for (int v = 0; v < m.num_nodes(); ++v)
        if (in[v]) nodes.push_back(v);
    for (int s = 0; s < static_cast<int>(m.segments.size()); ++s)
        if (in[m.segments[s].i] || in[m.segments[s].j]) segs.push_back(s);
    Eigen::VectorXd x2 = x;
    for (int v : nodes) x2[2 * v] += 5.0, x2[2 * v + 1] += 3.0;
    REQUIRE(missing(list, m, x2, B, kWide) > 0);
    list.update(x2, B, segs, nodes);
    CHECK(missing(list, m, x2, B, kWide) == 0);
    CHECK(strictly_ordered(list.pairs()));
}

TEST_CASE("neighbour list: find() then replace() is update(); the list is not valid in between", "[wet][neighbour_list]") {
    const Model m = model_of(mikado(2.5, 6, 0.5, 5), 8);
    const Eigen::Matrix2d B = m.box.B0();
    const Eigen::VectorXd x = m.x;
    // A region (the nodes within 6 of a node) moved by 4 along x.
    std::vector<int> nodes, segs;
    region_of(m, x, x.segment<2>(2 * (m.num_nodes() / 2)), 6, nodes, segs);
    REQUIRE(nodes.size() > 10);
    Eigen::VectorXd x2 = x;
    for (int v : nodes) x2[2 * v] += 4.0;
    auto same = [](const std::vector<SegmentPair>& p, const std::vector<SegmentPair>& q) {
        bool eq = p.size() == q.size();
        for (size_t k = 0; eq && k < p.size(); ++k) eq = p[k].a == q[k].a && p[k].b == q[k].b && p[k].image == q[k].image;
        return eq;
    };
    NeighbourList split(m, [](double) { return kRange; }, kSkin), whole(m, [](double) { return kRange; }, kSkin);
    split.build(x, B), whole.build(x, B);
    const std::vector<SegmentPair> before = split.pairs();
    const int builds = split.builds();
    std::vector<SegmentPair> found;
    REQUIRE(split.find(x2, B, segs, nodes, found));
    // In between: the pairs as they were, the region's nodes recorded as built at x2, the whole list not valid.
    CHECK(split.pending());
    CHECK(same(split.pairs(), before));
    CHECK(split.builds() == builds);
    CHECK(split.valid_at(nodes, x2, B));
    CHECK(!split.valid(x2, B));
    split.replace(segs, found);
    whole.update(x2, B, segs, nodes);
    CHECK(!split.pending());
    CHECK(split.valid(x2, B));
    CHECK(same(split.pairs(), whole.pairs()));
    CHECK(split.origin() == whole.origin());
    CHECK(missing(split, m, x2, B) == 0);
    // `found` is the region's share of the list: the pairs that hold one of its segments.
    std::vector<char> is_seg(m.segments.size(), 0);
    for (int s : segs) is_seg[s] = 1;
    std::vector<SegmentPair> share;
    for (const SegmentPair& p : whole.pairs())
        if (is_seg[p.a] || is_seg[p.b]) share.push_back(p);
    CHECK(same(found, share));
    // A build voids a pending find, and replace() then refuses it.
    Eigen::VectorXd x3 = x2;
    for (int v : nodes) x3[2 * v + 1] += 4.0;
    REQUIRE(split.find(x3, B, segs, nodes, found));
    split.build(x3, B);
    CHECK(!split.pending());
    CHECK(split.valid(x3, B));
    CHECK_THROWS_AS(split.replace(segs, found), std::logic_error);
}
