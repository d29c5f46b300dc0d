#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>

#include "fd.hpp"
#include "fibernet/energy/capillary.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
CapillaryLaw table_law(int n) {
    // A Surface-Evolver-like table: E/(beta l) = -cos^2(alpha) + 0.1 sin^2(2 alpha), n points from 0 to 90 deg.
    std::vector<double> a, v;
    for (int i = 0; i < n; ++i) {
        const double deg = 90.0 * i / (n - 1), r = deg * M_PI / 180;
        a.push_back(deg);
        v.push_back(-std::cos(r) * std::cos(r) + 0.1 * std::sin(2 * r) * std::sin(2 * r));
    }
    return CapillaryLaw::tabulated(a, v, "table");
}

void check_bridge(const CapillaryLaw& law, double alpha_deg, double len2) {
    const double r = alpha_deg * M_PI / 180 + 0.4;
    const Eigen::Vector2d d1(std::cos(0.4), std::sin(0.4));
    const Eigen::Vector2d d2 = len2 * Eigen::Vector2d(std::cos(r), std::sin(r));
    Eigen::Vector4d x;
    x << 1.3 * d1, d2;
    const double l = 0.9, beta = 2.5;
    auto f = [&](const Eigen::VectorXd& v) { return bridge_energy(v.head<2>(), v.tail<2>(), l, beta, law, nullptr, nullptr); };
    auto gf = [&](const Eigen::VectorXd& v) {
        Eigen::Vector4d g;
        bridge_energy(v.head<2>(), v.tail<2>(), l, beta, law, &g, nullptr);
        return Eigen::VectorXd(g);
    };
    Eigen::Vector4d g;
    Eigen::Matrix4d H;
    bridge_energy(x.head<2>(), x.tail<2>(), l, beta, law, &g, &H);
    INFO("alpha = " << alpha_deg << ", |d2| = " << len2 << ", tabulated = " << !law.is_default());
    CHECK(fdtest::rel_err(g, fdtest::fd_gradient(f, x, 1e-7), beta * l) < 1e-6);
    CHECK(fdtest::rel_err(H, fdtest::fd_jacobian(gf, x, 1e-7), beta * l) < 1e-6);
}
}  // namespace

TEST_CASE("capillary: gradient and Hessian match finite differences at all angles", "[energy][capillary][gradient][hessian]") {
    const CapillaryLaw def, tab = table_law(19);
    for (double a : {0.0, 1e-3, 20.0, 45.0, 75.0, 89.9, 90.0, 120.0, 180.0})
        for (double len2 : {1.0, 0.1, 4.0}) {
            check_bridge(def, a, len2);
            check_bridge(tab, a, len2);
        }
}

TEST_CASE("capillary: a table that does not span 0-90 deg is continued linearly, C2, with exact derivatives",
          "[energy][capillary][gradient][hessian]") {
    // A Surface Evolver table often stops short of 0 and 90 deg: here 10 ... 80 deg. Outside, the natural spline is
    // continued along its end tangent (CapillaryLaw::eval).
    std::vector<double> a, v;
    for (int deg = 10; deg <= 80; deg += 5) {
        const double r = deg * M_PI / 180;
        a.push_back(deg), v.push_back(-std::cos(r) * std::cos(r) + 0.1 * std::sin(2 * r) * std::sin(2 * r));
    }
    const CapillaryLaw law = CapillaryLaw::tabulated(a, v, "partial table");
    for (double deg : {0.0, 1e-3, 5.0, 9.0, 45.0, 81.0, 85.0, 89.9, 90.0, 100.0, 175.0})
        for (double len2 : {1.0, 0.1}) check_bridge(law, deg, len2);
    // Across each end of the table (c = cos^2 alpha at 10 and 80 deg): value, slope and curvature continuous.
    for (double deg : {10.0, 80.0}) {
        const double c = std::pow(std::cos(deg * M_PI / 180), 2), h = 1e-7;
        double p0, d0, s0, p1, d1, s1;
        law.eval(c - h, p0, d0, s0);
        law.eval(c + h, p1, d1, s1);
        INFO("table end at " << deg << " deg");
        CHECK(std::abs(p1 - p0) <= 1e-6);
        CHECK(std::abs(d1 - d0) <= 1e-5);
        CHECK(std::abs(s1 - s0) <= 1e-4 * (1 + std::abs(s0)));
    }
}

TEST_CASE("capillary: default law has E(90) - E(0) = beta l and no torque at 0 and 90 deg", "[energy][capillary]") {
    const CapillaryLaw law;
    const Eigen::Vector2d d1(1, 0);
    const double l = 0.7, beta = 3;
    const double E0 = bridge_energy(d1, Eigen::Vector2d(2, 0), l, beta, law, nullptr, nullptr);
    const double E90 = bridge_energy(d1, Eigen::Vector2d(0, 2), l, beta, law, nullptr, nullptr);
    CHECK(E90 - E0 == Approx(beta * l));
    CHECK(E0 == Approx(-beta * l));
    // Fibers have no direction: anti-parallel segments are aligned too.
    CHECK(bridge_energy(d1, Eigen::Vector2d(-2, 0), l, beta, law, nullptr, nullptr) == Approx(E0));
    Eigen::Vector4d g;
    bridge_energy(d1, Eigen::Vector2d(0, 2), l, beta, law, &g, nullptr);
    CHECK(g.norm() < 1e-12);
    bridge_energy(d1, Eigen::Vector2d(2, 0), l, beta, law, &g, nullptr);
    CHECK(g.norm() < 1e-12);
    // Sliding (translating the segments) cannot change E: it depends on d1, d2 only, and scaling a length neither.
    CHECK(bridge_energy(2 * d1, Eigen::Vector2d(1, 1), l, beta, law, nullptr, nullptr) ==
          Approx(bridge_energy(d1, Eigen::Vector2d(3, 3), l, beta, law, nullptr, nullptr)));
}

TEST_CASE("capillary: a tabulated law reproduces its table and converges to the exact law", "[energy][capillary]") {
    const CapillaryLaw tab = table_law(37);
    for (double deg : {0.0, 10.0, 45.0, 90.0}) {
        const double r = deg * M_PI / 180, c = std::cos(r) * std::cos(r);
        double phi, dphi, d2phi;
        tab.eval(c, phi, dphi, d2phi);
        CHECK(phi == Approx(-c + 0.1 * std::sin(2 * r) * std::sin(2 * r)).margin(1e-12));
    }
    // Between knots: error of the spline falls as the table is refined.
    auto err = [](const CapillaryLaw& law) {
        double e = 0;
        for (int i = 0; i < 200; ++i) {
            const double deg = 0.45 * i + 0.2, r = deg * M_PI / 180, c = std::cos(r) * std::cos(r);
            double phi, d, d2;
            law.eval(c, phi, d, d2);
            e = std::max(e, std::abs(phi - (-c + 0.1 * std::sin(2 * r) * std::sin(2 * r))));
        }
        return e;
    };
    CHECK(err(table_law(37)) < err(table_law(10)));
    CHECK(err(table_law(91)) < 2e-3);
}

TEST_CASE("capillary: malformed tables are rejected naming the row and value", "[energy][capillary][input]") {
    CHECK_THROWS_WITH(CapillaryLaw::tabulated({0, 50, 40}, {1, 2, 3}, "law.txt"), Catch::Contains("row 3: alpha = 40"));
    CHECK_THROWS_WITH(CapillaryLaw::tabulated({0, 95}, {1, 2}, "law.txt"), Catch::Contains("alpha = 95"));
    CHECK_THROWS_WITH(CapillaryLaw::tabulated({0, 90}, {1, NAN}, "law.txt"), Catch::Contains("value = nan"));
    CHECK_THROWS_AS(CapillaryLaw::tabulated({0}, {1}, "law.txt"), InputError);
    const std::string path = "/tmp/fibernet_law_test.txt";
    std::ofstream(path) << "# alpha value\n0 -1\n45 x\n";
    CHECK_THROWS_WITH(CapillaryLaw::read(path), Catch::Contains(path + ":3"));
    std::ofstream(path) << "# alpha value\n0 -1\n90 0\n";
    double phi, d, d2;
    CapillaryLaw::read(path).eval(0.5, phi, d, d2);
    CHECK(phi == Approx(-0.5));
}

TEST_CASE("capillary: a law file may end a row with a comment", "[energy][capillary][input]") {
    // docs/formats.md allows '#' comments; a trailing one ("90 0 # end") was read as a third field and refused.
    const std::string path = "/tmp/fibernet_law_comment_test.txt";
    std::ofstream(path) << "# alpha value\n0 -1   # aligned\n90 0 # end\n";
    double phi, d, d2;
    CapillaryLaw::read(path).eval(0.5, phi, d, d2);
    CHECK(phi == Approx(-0.5));
    // A comment does not stand in for a missing value, and '#' inside a number is no comment.
    std::ofstream(path) << "0 -1\n90 # 0\n";
    CHECK_THROWS_WITH(CapillaryLaw::read(path), Catch::Contains(path + ":2"));
    std::ofstream(path) << "0 -1\n90 0#\n";
    CHECK_NOTHROW(CapillaryLaw::read(path));
    std::ofstream(path) << "0 -1\n90 0x# c\n";
    CHECK_THROWS_WITH(CapillaryLaw::read(path), Catch::Contains(path + ":2"));
}
