// Pore faces on hand-made networks with known faces; bundles from aligned bridges.
#include <catch2/catch.hpp>
#include <cmath>

#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/bundles.hpp"
#include "fibernet/wet/pores.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

TEST_CASE("pores: a periodic square grid has exactly its cells", "[wet][pores]") {
    // Three horizontal and three vertical fibers of length L = 1 that close on themselves through the box.
    const std::vector<double> ys = {0.14, 0.41, 0.77}, xs = {0.22, 0.5, 0.9};
    std::vector<Line> lines;
    for (double y : ys) lines.push_back({0.05, y, 0, 1, 0});
    for (double x : xs) lines.push_back({x, 0.03, 90, 1, 0});
    const Model m = model_of(network_of(lines, 1.0), 10);
    Eigen::Matrix2d F;
    for (double shear : {0.0, 0.3}) {
        F << 1, shear, 0, 1;
        // Positions mapped affinely: areas scale by det F = 1, cells stay parallelograms of the same area.
        Eigen::VectorXd x(m.x.size());
        for (int i = 0; i < m.num_nodes(); ++i) x.segment<2>(2 * i) = F * m.x.segment<2>(2 * i);
        const PoreStats p = pores(m, x, F * m.box.B0());
        REQUIRE(p.pores.size() == 9);
        std::vector<double> got, want;
        for (const auto& q : p.pores) got.push_back(q.area);
        const std::vector<double> w = {0.28, 0.4, 0.32}, h = {0.27, 0.36, 0.37};
        for (double a : w)
            for (double b : h) want.push_back(100 * a * b);  // seed units: lf = 10
        std::sort(got.begin(), got.end()), std::sort(want.begin(), want.end());
        for (size_t i = 0; i < 9; ++i) CHECK(got[i] == Approx(want[i]).epsilon(1e-10));
        CHECK(std::abs(p.remainder) < 1e-9 * p.box_area);
        CHECK(p.open_faces == 0);
        CHECK(p.pores[0].diameter == Approx(std::sqrt(4 * p.pores[0].area / M_PI)));
    }
}

namespace {
double cross2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
// Four fibers of length 1 crossing at the corners of the square [c - h, c + h]^2 (network units; h = 0.27 keeps the
// corners off the fibers' nodes).
std::vector<Line> square(double c, double h) {
    return {{c, c - h, 0, 1, 0.5}, {c + h, c, 90, 1, 0.5}, {c, c + h, 180, 1, 0.5}, {c - h, c, 270, 1, 0.5}};
}
// Three fibers along the sides of the triangle P, each extended by `overhang` past its corners; its area in seed units.
double add_triangle(std::vector<Line>& lines, const Eigen::Vector2d P[3], double overhang = 0.02) {
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector2d a = P[i], b = P[(i + 1) % 3], c = 0.5 * (a + b), d = b - a;
        lines.push_back({c.x(), c.y(), std::atan2(d.y(), d.x()) * 180 / M_PI, d.norm() + 2 * overhang, 0.5});
    }
    return 100 * 0.5 * std::abs(cross2d(P[1] - P[0], P[2] - P[0]));
}
}  // namespace

TEST_CASE("pores: a single triangle in a box", "[wet][pores]") {
    const Eigen::Vector2d P[3] = {{1.2, 1.2}, {1.9, 1.25}, {1.5, 1.8}};
    std::vector<Line> lines;
    const double area = add_triangle(lines, P, 0.15);
    for (bool periodic : {true, false}) {
        const Model m = model_of(network_of(lines, 3.0, periodic), 10);
        const PoreStats p = pores(m, m.x, m.box.B0());
        INFO("periodic " << periodic);
        REQUIRE(p.pores.size() == 1);
        CHECK(p.pores[0].area == Approx(area).epsilon(1e-10));
        CHECK(p.pores[0].edges >= 3);  // graph edges: fiber nodes split the sides
        CHECK(p.remainder == Approx(p.box_area - area).epsilon(1e-10));
    }
}

TEST_CASE("bundles: fibers joined by aligned bridges", "[wet][bundles]") {
    // Fibers 0 and 1 lie side by side (a bundle); fiber 2 crosses them at 60 deg (not aligned).
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.52, 1.505, 0, 1, 0.5}, {1.5, 1.5, 60, 1, 0.5}}, 3);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    std::vector<Bridge> b = wet_crossings(net, m, m.x, m.box.B0(), {});
    update_bridges(e, e.dofs(m.x), Eigen::Matrix2d::Identity(), b);
    const BundleStats s = bundles(m, m.x, m.box.B0(), b);
    REQUIRE(s.sizes.size() == 1);
    CHECK(s.sizes[0] == 2);
    CHECK(s.bundled_fibers == 2);
    CHECK(s.bundle_of_fiber[0] == s.bundle_of_fiber[1]);
    CHECK(s.bundle_of_fiber[2] != s.bundle_of_fiber[0]);
    CHECK(s.histogram.at(2) == 1);
}

TEST_CASE("pores: a face with an island inside is not a disk", "[wet][pores]") {
    // A triangle of three fibers inside a square of four, touching nothing: the triangle is a pore, the square's face
    // (an annulus) is not, in an open box and on the torus. Before the fix the square counted in full.
    const Eigen::Vector2d P[3] = {{1.4, 1.4}, {1.6, 1.42}, {1.5, 1.6}};
    std::vector<Line> lines = square(1.5, 0.27);
    const double tri = add_triangle(lines, P);
    for (bool periodic : {true, false}) {
        const Model m = model_of(network_of(lines, 3.0, periodic), 10);
        const PoreStats p = pores(m, m.x, m.box.B0());
        INFO("periodic " << periodic);
        REQUIRE(p.pores.size() == 1);
        CHECK(p.pores[0].area == Approx(tri).epsilon(1e-10));
        CHECK(p.islands == 1);
        CHECK(p.island_faces == 1);
        // On the torus the face outside the square winds around it: the void percolates.
        CHECK(p.open_faces == (periodic ? 1 : 0));
        CHECK(p.remainder == Approx(p.box_area - tri).epsilon(1e-12));
        if (periodic) CHECK(p.cover() == Approx(1).epsilon(1e-12));
    }
}

TEST_CASE("pores: an island in a cell that wraps through the periodic box", "[wet][pores]") {
    // The grid of the first test with a triangle across the box's corner, inside the cell [0.9, 1.22] x [0.77, 1.14]:
    // the cell is found through the triangle's periodic image. A free fiber (no area) in another cell leaves it a pore.
    const std::vector<double> ys = {0.14, 0.41, 0.77}, xs = {0.22, 0.5, 0.9};
    std::vector<Line> lines;
    for (double y : ys) lines.push_back({0.05, y, 0, 1, 0});
    for (double x : xs) lines.push_back({x, 0.03, 90, 1, 0});
    const Eigen::Vector2d P[3] = {{0.95, 0.95}, {1.1, 0.97}, {1.02, 1.08}};
    const double tri = add_triangle(lines, P);
    lines.push_back({0.35, 0.6, 20, 0.1, 0.5});  // free fiber in the cell [0.22, 0.5] x [0.41, 0.77]
    const Model m = model_of(network_of(lines, 1.0), 10);
    const PoreStats p = pores(m, m.x, m.box.B0());
    REQUIRE(p.pores.size() == 9);  // 8 cells and the triangle
    double smallest = 1e300;
    for (const auto& q : p.pores) smallest = std::min(smallest, q.area);
    CHECK(smallest == Approx(tri).epsilon(1e-10));
    CHECK(p.islands == 1);
    CHECK(p.remainder == Approx(100 * 0.32 * 0.37 - tri).epsilon(1e-10));
}

TEST_CASE("pores: two fibers zipped on top of each other across a square", "[wet][pores]") {
    // Fibers A and B antiparallel on one line through the square's centre, 1e-13 rad apart: they cross once, where
    // solving t and u separately put the crossing's two ends ~1e-3 apart (before the fix the periodic case traced
    // the whole square as one pore). One point per crossing: two pores of 14.58.
    std::vector<Line> lines = square(1.5, 0.27);
    const double th = 30, dth = 1e-13 * 180 / M_PI;
    lines.push_back({1.5, 1.5, th, 1, 0.53});
    lines.push_back({1.5, 1.5, th + 180 + dth, 1, 0.47});
    for (bool periodic : {true, false}) {
        const Model m = model_of(network_of(lines, 3.0, periodic), 10);
        const PoreStats p = pores(m, m.x, m.box.B0());
        INFO("periodic " << periodic);
        CHECK(p.open_faces == (periodic ? 1 : 0));
        REQUIRE(p.pores.size() == 2);
        CHECK(p.pores[0].area == Approx(14.58).epsilon(1e-9));
        CHECK(p.pores[1].area == Approx(14.58).epsilon(1e-9));
        CHECK(p.remainder == Approx(p.box_area - 29.16).epsilon(1e-12));
    }
}

TEST_CASE("pores: slivers between two fibers at 1 deg are walls, not pores", "[wet][pores]") {
    // Two fibers crossing at the square's centre at 30 and 31 deg: two wide faces and two slivers about 0.03 wide
    // (seed units) along them, below the default wall width 2/a = 0.2. With a wall width below that they are pores.
    std::vector<Line> lines = square(1.5, 0.27);
    lines.push_back({1.5, 1.5, 30, 1, 0.5});
    lines.push_back({1.5, 1.5, 31, 1, 0.5});
    const Model m = model_of(network_of(lines, 3.0, false), 10);
    const PoreStats p = pores(m, m.x, m.box.B0());
    CHECK(p.wall_width == Approx(0.2));
    CHECK(p.pores.size() == 2);
    CHECK(p.walls == 2);
    double sum = p.wall_area;
    for (const auto& q : p.pores) sum += q.area;
    CHECK(sum == Approx(100 * 0.54 * 0.54).epsilon(1e-12));
    const PoreStats fine = pores(m, m.x, m.box.B0(), 0.01);
    CHECK(fine.pores.size() == 4);
    CHECK(fine.walls == 0);
}

TEST_CASE("pores: zipped fiber pairs in a Mikado network leave no area out", "[wet][pores]") {
    // A periodic Mikado network (L = 3, q = 10: percolating, every face a disk) with eight pairs of fibers laid on
    // top of each other, 1e-13 rad apart, as relaxed wet networks zip them: the pores tile the box. Before the fix
    // faces through the pairs' crossings did not close or overlapped (remainder of either sign).
    Network net = mikado(3, 10, 0.5, 2);
    const Eigen::Vector2d at[8] = {{0.7, 0.9}, {1.6, 2.2}, {2.4, 1.1}, {0.3, 2.5}, {1.2, 1.4}, {2.7, 2.8}, {1.9, 0.4}, {0.5, 1.8}};
    for (int k = 0; k < 8; ++k) {
        const double th = 0.3 + 1.1 * k, dth = 2e-14;
        for (int s = 0; s < 2; ++s) {
            Fiber f;
            f.theta = th + s * (M_PI + dth), f.length = 1;
            f.start = at[k] - (s ? 0.47 : 0.53) * f.direction();
            net.fibers.push_back(f);
        }
    }
    net.crossings = find_crossings(net);
    const Model m = model_of(net, 10);
    const PoreStats p = pores(m, m.x, m.box.B0());
    CHECK(p.open_faces == 0);
    CHECK(p.cover() == Approx(1).epsilon(1e-12));
}

TEST_CASE("pores: faces that wind around the torus are open, not pores", "[wet][pores]") {
    // Two horizontal fibers closing on themselves: the box is two bands, each winding around the torus. A single
    // free fiber crossing nothing is pruned: the one face left is the whole torus.
    const Model bands = model_of(network_of({{0.05, 0.3, 0, 1, 0}, {0.05, 0.7, 0, 1, 0}}, 1.0), 10);
    const PoreStats p = pores(bands, bands.x, bands.box.B0());
    CHECK(p.pores.empty());
    CHECK(p.open_faces == 2);
    CHECK(p.open_area == Approx(p.box_area).epsilon(1e-12));
    CHECK(p.cover() == Approx(1).epsilon(1e-12));
    const Model lone = model_of(network_of({{0.98, 0.5, 20, 0.3, 0.5}}, 1.0), 10);  // across the cut
    const PoreStats q = pores(lone, lone.x, lone.box.B0());
    CHECK(q.pores.empty());
    CHECK(q.open_faces == 1);
    CHECK(q.island_faces == 0);
    CHECK(q.open_area == Approx(q.box_area).epsilon(1e-12));
}

TEST_CASE("pores: the grid's cells with fibers on the cut lines, dangling ends across them and shear",
          "[wet][pores]") {
    // A vertical fiber exactly on x = 0 (the natural cut line), a free fiber and a dangling end across the cut, in a
    // sheared box: still exactly the nine cells, with the same areas (det F = 1).
    const std::vector<double> ys = {0.14, 0.41, 0.77}, xs = {0.0, 0.5, 0.9};
    std::vector<Line> lines;
    for (double y : ys) lines.push_back({0.05, y, 0, 1, 0});
    for (double x : xs) lines.push_back({x, 0.03, 90, 1, 0});
    lines.push_back({0.38, 0.3, 15, 0.12, 0.5});  // free, across the cut x = 0.38 (moved off x = 0) in [0, 0.5] x [0.14, 0.41]
    lines.push_back({0.7, 0.999, 70, 0.1, 0.5});  // free, across y = 1 ~ 0 inside [0.5, 0.9] x [0.77, 1.14]
    lines.push_back({0.3, 0.5, 85, 0.5, 0.5});    // dangling: crosses y = 0.41 and 0.77 only
    const Model m = model_of(network_of(lines, 1.0), 10);
    Eigen::Matrix2d F;
    F << 1, 0.4, 0, 1;
    Eigen::VectorXd x(m.x.size());
    for (int i = 0; i < m.num_nodes(); ++i) x.segment<2>(2 * i) = F * m.x.segment<2>(2 * i);
    const PoreStats p = pores(m, x, F * m.box.B0());
    std::vector<double> got, want;
    for (const auto& q : p.pores) got.push_back(q.area);
    for (double a : {0.5, 0.4, 0.1})
        for (double b : {0.27, 0.36, 0.37}) want.push_back(100 * a * b);
    std::sort(got.begin(), got.end()), std::sort(want.begin(), want.end());
    REQUIRE(got.size() == 9);
    for (size_t i = 0; i < 9; ++i) CHECK(got[i] == Approx(want[i]).epsilon(1e-10));
    CHECK(p.open_faces + p.island_faces + p.walls == 0);
}

TEST_CASE("pores: a sheared Mikado network is tiled exactly", "[wet][pores]") {
    // Every face classified, on the torus: the classes sum to the box area to round-off, at any shear.
    const Model m = model_of(mikado(4, 8, 0.5, 5), 6);
    for (double shear : {0.0, 0.25, -0.6}) {
        Eigen::Matrix2d F;
        F << 1, shear, 0, 1;
        Eigen::VectorXd x(m.x.size());
        for (int i = 0; i < m.num_nodes(); ++i) x.segment<2>(2 * i) = F * m.x.segment<2>(2 * i);
        const PoreStats p = pores(m, x, F * m.box.B0());
        INFO("shear " << shear);
        CHECK(p.cover() == Approx(1).epsilon(1e-12));
        CHECK(p.pores.size() > 10);
        CHECK(p.remainder == Approx(p.wall_area + p.island_area + p.open_area).margin(1e-9 * p.box_area));
    }
}
