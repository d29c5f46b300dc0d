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
        CHECK(p.open_cycles == 0);
        CHECK(p.pores[0].diameter == Approx(std::sqrt(4 * p.pores[0].area / M_PI)));
    }
}

TEST_CASE("pores: a single triangle in a box", "[wet][pores]") {
    const Eigen::Vector2d P[3] = {{1.2, 1.2}, {1.9, 1.25}, {1.5, 1.8}};
    std::vector<Line> lines;
    for (int i = 0; i < 3; ++i) {
        const Eigen::Vector2d a = P[i], b = P[(i + 1) % 3], c = 0.5 * (a + b), d = b - a;
        lines.push_back({c.x(), c.y(), std::atan2(d.y(), d.x()) * 180 / M_PI, d.norm() + 0.3, 0.5});
    }
    const double area = 100 * 0.5 * std::abs((P[1] - P[0]).x() * (P[2] - P[0]).y() - (P[1] - P[0]).y() * (P[2] - P[0]).x());
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
