// The (3,3) pebble game on hand-made frameworks with known answers and against the rank of the dense
// body-and-pin rigidity matrix on random small networks (issue 4, "Tests").
#include <catch2/catch.hpp>

#include "fibernet/network/clamp.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/pebble_game.hpp"
#include "fibernet/rigidity/rigidity.hpp"
#include "fibernet/rigidity/rigidity_matrix.hpp"

using namespace fibernet;

namespace {
// A rod from a to b.
Fiber rod(Eigen::Vector2d a, Eigen::Vector2d b) {
    Fiber f;
    f.start = a;
    const Eigen::Vector2d d = b - a;
    f.length = d.norm();
    f.theta = std::atan2(d.y(), d.x());
    return f;
}
// Pins the end `ea` (0 start, 1 end) of fiber i to the end `eb` of fiber j.
Crossing end_pin(const Network& n, int i, int ea, int j, int eb) {
    Crossing c;
    c.f1 = std::min(i, j), c.f2 = std::max(i, j);
    const double si = ea ? n.fibers[i].length : 0, sj = eb ? n.fibers[j].length : 0;
    c.s1 = i < j ? si : sj, c.s2 = i < j ? sj : si;
    c.crosslink = true;
    return c;
}
// A closed polygon of rods pinned at the corners.
Network polygon(const std::vector<Eigen::Vector2d>& corners) {
    Network n;
    n.periodic = false;
    n.L = 2;
    const int k = static_cast<int>(corners.size());
    for (int i = 0; i < k; ++i) n.fibers.push_back(rod(corners[i], corners[(i + 1) % k]));
    for (int i = 0; i < k; ++i) n.crossings.push_back(end_pin(n, i, 1, (i + 1) % k, 0));
    return n;
}
}  // namespace

TEST_CASE("three rods pinned in a triangle are rigid", "[rigidity][pebble]") {
    const Network n = polygon({{0, 0}, {1, 0}, {0.4, 0.8}});
    const RigidityResult r = analyze_rigidity(body_pin_framework(n));
    CHECK(r.floppy_modes == 3);  // trivial motions only
    CHECK(r.independent == 6);
    CHECK(r.redundant == 0);
    CHECK(r.clusters == 1);
    CHECK(r.largest_cluster == 3);
}

TEST_CASE("four rods in a quadrilateral have one internal floppy mode", "[rigidity][pebble]") {
    const Network n = polygon({{0, 0}, {1, 0}, {1.1, 0.9}, {0.1, 0.8}});
    const RigidityResult r = analyze_rigidity(body_pin_framework(n));
    CHECK(r.floppy_modes == 3 + 1);
    CHECK(r.independent == 8);
    CHECK(r.clusters == 4);
    CHECK(r.largest_cluster == 1);
}

TEST_CASE("a rod pinned to one other rod rotates freely", "[rigidity][pebble]") {
    Network n;
    n.periodic = false;
    n.fibers = {rod({0, 0}, {1, 0}), rod({0.5, -0.5}, {0.6, 0.5})};
    double sa, sb;
    REQUIRE(intersect(n.fibers[0], n.fibers[1], {0, 0}, sa, sb));
    n.crossings.push_back({0, 1, sa, sb, {0, 0}, true});
    const RigidityResult r = analyze_rigidity(body_pin_framework(n));
    CHECK(r.floppy_modes == 3 + 1);
    CHECK(r.clusters == 2);
}

TEST_CASE("a triangle with a diagonal brace has one redundant pin's worth of bars", "[rigidity][pebble]") {
    // Triangle + a fourth rod pinned at two points to two sides: 4 rods, 5 pins = 10 bars, 12 - 3 = 9 needed.
    Network n = polygon({{0, 0}, {2, 0}, {1, 1.6}});
    n.fibers.push_back(rod({0.5, -0.2}, {1.3, 1.5}));
    for (int side : {0, 1, 2}) {
        double sa, sb;
        if (intersect(n.fibers[side], n.fibers[3], {0, 0}, sa, sb)) n.crossings.push_back({side, 3, sa, sb, {0, 0}, true});
    }
    REQUIRE(n.num_crosslinks() == 5);
    const RigidityResult r = analyze_rigidity(body_pin_framework(n));
    CHECK(r.independent == 9);
    CHECK(r.redundant == 1);
    CHECK(r.floppy_modes == 3);
    CHECK(r.clusters == 1);
}

TEST_CASE("three rods sharing one pin are one pin, not three", "[rigidity][pebble]") {
    // Rods meeting at the origin (a hand-made junction): the pin leaves each rod its rotation, 9 - 4 = 5.
    Network n;
    n.periodic = false;
    n.fibers = {rod({0, 0}, {1, 0}), rod({0, 0}, {0.3, 1}), rod({0, 0}, {-1, 0.4})};
    n.crossings = {end_pin(n, 0, 0, 1, 0), end_pin(n, 0, 0, 2, 0), end_pin(n, 1, 0, 2, 0)};
    const BodyPinFramework fw = body_pin_framework(n);
    CHECK(fw.num_pins() == 1);
    CHECK(fw.num_bars() == 4);
    CHECK(analyze_rigidity(fw).floppy_modes == 5);
    CHECK(dense_rigidity(fw).nullity == 5);
}

TEST_CASE("an empty network and one without crosslinks have valid answers", "[rigidity][pebble]") {
    Network empty;
    empty.periodic = false;
    const RigidityResult r0 = analyze_rigidity(body_pin_framework(empty));
    CHECK(r0.floppy_modes == 0);
    CHECK(r0.clusters == 0);
    const RigidityResult c0 = analyze_rigidity(body_pin_framework(clamp_network(empty)));
    CHECK(c0.d == 3);
    CHECK_FALSE(c0.connected_spanning);

    Network loose = generate_mikado({3, 4, 0.0, 7, false});
    REQUIRE(loose.num_crosslinks() == 0);
    const RigidityResult r1 = analyze_rigidity(body_pin_framework(loose));
    CHECK(r1.floppy_modes == 3L * static_cast<long>(loose.fibers.size()));
    CHECK(r1.clusters == static_cast<int>(loose.fibers.size()));
}

TEST_CASE("clamps: one tilted rod from bottom to top leaves the top clamp 2 degrees of freedom", "[rigidity][clamp]") {
    Network n;
    n.periodic = false;
    n.L = 1;
    n.fibers = {rod({0.3, -0.2}, {0.6, 1.2})};
    const ClampedNetwork cl = clamp_network(n);
    REQUIRE(cl.pins.size() == 2);
    CHECK(cl.net.fibers[0].point(0).y() == Approx(0).margin(1e-14));
    CHECK(cl.net.fibers[0].point(cl.net.fibers[0].length).y() == Approx(1));
    const BodyPinFramework fw = body_pin_framework(cl);
    const RigidityResult r = analyze_rigidity(fw);
    CHECK(r.d == 2);
    CHECK(r.carries_shear);
    CHECK_FALSE(r.rigid_spanning);
    CHECK(r.connected_spanning);
    CHECK(dense_rigidity(fw).d == 2);
}

TEST_CASE("clamps: two rods between the clamps are a four-bar linkage until they are pinned together", "[rigidity][clamp]") {
    // Bottom clamp, rod, top clamp, rod: a quadrilateral of bodies, 1 internal mode (d = 1). Pinning the rods
    // where they cross makes a triangle with each clamp (d = 0, and 1 of the 10 bars is redundant).
    Network n;
    n.periodic = false;
    n.L = 1;
    n.fibers = {rod({0.1, -0.1}, {0.9, 1.1}), rod({0.9, -0.1}, {0.1, 1.1})};
    const BodyPinFramework open_x = body_pin_framework(clamp_network(n));
    const RigidityResult a = analyze_rigidity(open_x);
    CHECK(a.d == 1);
    CHECK(dense_rigidity(open_x).d == 1);
    CHECK(a.carries_shear);
    CHECK(a.connected_spanning);
    double sa, sb;
    REQUIRE(intersect(n.fibers[0], n.fibers[1], {0, 0}, sa, sb));
    n.crossings.push_back({0, 1, sa, sb, {0, 0}, true});
    const BodyPinFramework x = body_pin_framework(clamp_network(n));
    const RigidityResult b = analyze_rigidity(x);
    CHECK(b.d == 0);
    CHECK(dense_rigidity(x).d == 0);
    CHECK(b.rigid_spanning);
    CHECK(b.redundant == 1);
    CHECK(b.clusters == 1);
}

TEST_CASE("pebble game matches the rank of the dense rigidity matrix on random networks", "[rigidity][pebble][dense]") {
    int tested = 0, clamped_rigid = 0, clamped_free = 0;
    double worst_zero = 0, worst_nonzero = 1e300;
    for (std::uint64_t seed = 1; seed <= 120; ++seed) {
        const double q = 3 + (seed % 7);            // 3 .. 9
        const double pl = 0.5 + 0.1 * (seed % 6);   // 0.5 .. 1.0
        const double L = std::sqrt((20.0 + seed % 30) / q);
        const Network net = generate_mikado({L, q, pl, seed, false});
        for (bool clamped : {false, true}) {
            const BodyPinFramework fw = clamped ? body_pin_framework(clamp_network(net)) : body_pin_framework(net);
            const RigidityResult r = analyze_rigidity(fw);
            const DenseRigidity dr = dense_rigidity(fw);
            INFO("seed " << seed << " q " << q << " pl " << pl << " L " << L << " clamped " << clamped);
            CHECK(r.floppy_modes == dr.nullity);
            CHECK(r.independent == dr.rank);
            CHECK(r.independent + r.redundant == fw.num_bars());
            CHECK(r.cluster == dr.cluster);
            if (clamped) {
                CHECK(r.d == dr.d);
                (r.d == 0 ? clamped_rigid : clamped_free) += 1;
            }
            if (dr.largest_zero > 0) worst_zero = std::max(worst_zero, dr.largest_zero / dr.singular_values(0));
            if (dr.smallest_nonzero > 0) worst_nonzero = std::min(worst_nonzero, dr.smallest_nonzero / dr.singular_values(0));
            ++tested;
        }
    }
    // Both populations occur, and the singular values leave a wide gap around the cut (1e-8 relative).
    CHECK(clamped_rigid > 5);
    CHECK(clamped_free > 5);
    CHECK(worst_zero < 1e-12);
    CHECK(worst_nonzero > 1e-6);
    WARN("dense rank check: " << tested << " frameworks; singular values: zero <= " << worst_zero
                              << ", nonzero >= " << worst_nonzero << " (relative); clamped rigid " << clamped_rigid
                              << ", not " << clamped_free);
}

TEST_CASE("pebble game results do not depend on the order of the bars", "[rigidity][pebble]") {
    const Network net = generate_mikado({6, 6.5, 1.0, 11, false});
    const BodyPinFramework fw = body_pin_framework(clamp_network(net));
    const RigidityResult a = analyze_rigidity(fw);
    BodyPinFramework rev;
    rev.fibers = fw.fibers, rev.bodies = fw.bodies, rev.clamped = true;
    for (int k = fw.num_pins() - 1; k >= 0; --k) {
        rev.pin_point.push_back(fw.pin_point[k]);
        for (int i = fw.pin_offset[k + 1] - 1; i >= fw.pin_offset[k]; --i) rev.pin_body.push_back(fw.pin_body[i]);
        rev.pin_offset.push_back(static_cast<int>(rev.pin_body.size()));
    }
    const RigidityResult b = analyze_rigidity(rev);
    CHECK(a.independent == b.independent);
    CHECK(a.d == b.d);
    CHECK(a.cluster == b.cluster);
    CHECK(a.redundant > 0);
}
