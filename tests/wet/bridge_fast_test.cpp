// The bridge element's derivatives by the chain rule through the 8 signed distances (bridge.cpp) against the original
// Jet<16> evaluation, on many random elements: crossings near nodes (blend zones on one or both sides), near-parallel
// pairs (lambda fading), missing neighbours at fiber ends, locked bridges and crossings mid-segment (constant weights).
#include <catch2/catch.hpp>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "../energy/fd.hpp"
#include "fibernet/util/random.hpp"
#include "fibernet/wet/bridge.hpp"

using namespace fibernet;

namespace {

enum class Kind { Blend, Fade, Mid, Locked, Far };

// Side 0 along x (home segment from (0, 0) to (l, 0)), side 1 crossing it at angle alpha; both bent a little, rest
// lengths a little off the actual ones, the whole element moved and turned at random.
Vector16d random_element(Rng& rng, Kind kind, BridgeElement& e) {
    const double deg = M_PI / 180;
    double alpha;
    if (kind == Kind::Fade) alpha = rng.uniform(2.3, 4.7) * deg * (rng.bernoulli(0.5) ? 1 : -1);
    else alpha = rng.uniform(15, 165) * deg;
    double len[2][3];
    for (auto& s : len)
        for (double& l : s) l = rng.uniform(0.05, 0.15);
    // Where each side's crossing is, as the fraction of its home: near a node (blend zone |z| < l / 4), or mid.
    const int far_side = rng.bernoulli(0.5) ? 1 : 0;
    const bool far_plus = rng.bernoulli(0.5);
    auto place = [&](int s) {
        if (kind == Kind::Mid || kind == Kind::Locked || (kind == Kind::Far && s != far_side)) return rng.uniform(0.35, 0.65);
        if (kind == Kind::Far) {  // past a neighbour's far node, inside the window fade (a quarter of the neighbour)
            const double u = rng.uniform(0.05, 0.95) * 0.25;
            return far_plus ? 1 + len[s][2] * (1 + u) / len[s][1] : -len[s][0] * (1 + u) / len[s][1];
        }
        if (rng.bernoulli(0.15)) return rng.uniform(0.3, 0.7);  // this side off its zones
        return (rng.bernoulli(0.5) ? 0.0 : 1.0) + rng.uniform(-0.3, 0.3) * std::min(len[s][0], len[s][2]) / len[s][1];
    };
    const double f0 = place(0), f1 = place(1);
    Eigen::Vector2d P[8];
    const Eigen::Vector2d c(f0 * len[0][1], 0), u(std::cos(alpha), std::sin(alpha));
    P[1] = {0, 0}, P[2] = {len[0][1], 0}, P[0] = {-len[0][0], 0}, P[3] = {len[0][1] + len[0][2], 0};
    P[5] = c - f1 * len[1][1] * u, P[6] = P[5] + len[1][1] * u;
    P[4] = P[5] - len[1][0] * u, P[7] = P[6] + len[1][2] * u;
    const double bend = kind == Kind::Fade ? 0.002 : 0.01;
    for (auto& p : P) p += bend * Eigen::Vector2d(rng.uniform(-1, 1), rng.uniform(-1, 1));
    const Eigen::Rotation2Dd rot(rng.uniform(0, 2 * M_PI));
    const Eigen::Vector2d t(rng.uniform(-2, 2), rng.uniform(-2, 2));
    Vector16d X;
    for (int a = 0; a < 8; ++a) X.segment<2>(2 * a) = rot * P[a] + t;
    for (int s = 0; s < 2; ++s)
        for (int i = 0; i < 3; ++i) e.l0[3 * s + i] = len[s][i] * rng.uniform(0.95, 1.05);
    for (int a = 0; a < 8; ++a) e.node[a] = a, e.shift[a] = {0, 0};
    e.locked = kind == Kind::Locked;
    // Fiber ends: a missing neighbour (its coordinates zero, its segment's l0 zero, as resolve() makes them).
    for (int s = 0; s < 2; ++s)
        for (int end : {0, 3})
            if (rng.bernoulli(kind == Kind::Far ? 0.05 : 0.2)) {
                e.node[4 * s + end] = -1, e.l0[3 * s + (end == 0 ? 0 : 2)] = 0;
                X.segment<2>(2 * (4 * s + end)).setZero();
            }
    return X;
}

}  // namespace

TEST_CASE("bridge element: chain rule through the signed distances equals the Jet<16> evaluation", "[wet][bridge]") {
    Rng rng(2024);
    CapillaryLaw law;
    const double beta = 1.7;
    int n_zone = 0, n_fade = 0, n_end = 0;
    for (Kind kind : {Kind::Blend, Kind::Fade, Kind::Mid, Kind::Locked, Kind::Far})
        for (int n = 0; n < 400; ++n) {
            BridgeElement e;
            const Vector16d X = random_element(rng, kind, e);
            const CrossingPosition cp = crossing_position(e, X);
            bool zone = false;
            for (int s = 0; s < 2; ++s)
                for (int k = 0; k < 2; ++k) zone = zone || std::abs(cp.z[s][k]) < cp.delta[s][k];
            n_zone += cp.defined && zone;
            // Fading: a rate below sin 5 deg (crossing undefined) yet not the home-only energy (lambda > 0).
            BridgeElement home = e;
            home.locked = true;
            n_fade += !e.locked && !cp.defined &&
                      bridge_element_energy(e, X, beta, law, nullptr, nullptr) !=
                          bridge_element_energy(home, X, beta, law, nullptr, nullptr);
            n_end += *std::min_element(e.node, e.node + 8) < 0;
            for (bool psd : {false, true}) {
                Vector16d g0, g1, gg;
                Matrix16d H0, H1;
                const double E0 = bridge_element_energy_reference(e, X, beta, law, &g0, &H0, psd);
                const double E1 = bridge_element_energy(e, X, beta, law, &g1, &H1, psd);
                const double Eg = bridge_element_energy(e, X, beta, law, &gg, nullptr, psd);
                INFO("kind " << static_cast<int>(kind) << ", element " << n << ", psd " << psd);
                // Relative to |E0|, or to the element's scale beta l where a fade takes E0 to 0.
                const double es = std::abs(E0) + 1e-3 * beta * e.l0[1];
                CHECK(std::abs(E1 - E0) <= 1e-12 * es);  // seen: 1.3e-13
                CHECK(Eg == E1);
                // The value alone goes through law_ rather than bridge_energy: the same to round-off.
                CHECK(std::abs(bridge_element_energy(e, X, beta, law, nullptr, nullptr) - E0) <= 1e-12 * es);
                const double gs = g0.cwiseAbs().maxCoeff(), hs = H0.cwiseAbs().maxCoeff();
                CHECK((g1 - g0).cwiseAbs().maxCoeff() <= 1e-11 * gs);  // seen: 5e-13
                CHECK((gg - g1).cwiseAbs().maxCoeff() == 0);
                CHECK((H1 - H0).cwiseAbs().maxCoeff() <= 1e-10 * hs);  // seen: 1.3e-12
            }
        }
    INFO("in a blend zone " << n_zone << ", fading " << n_fade << ", at a fiber end " << n_end);
    CHECK(n_zone > 300);
    CHECK(n_fade > 100);
    CHECK(n_end > 300);
}

TEST_CASE("bridge element: derivatives match finite differences while lambda or the window fades", "[wet][bridge][gradient]") {
    // The network tests rarely reach the near-parallel fade, the window's end or a locked (bundle) bridge; check them
    // here directly, with the default law and a tabulated one. (Strain derivatives are these derivatives along
    // dX_a = dF B0 shift_a: WetEnergy::strain_derivatives composes them, checked in wet_energy_test.cpp.)
    Rng rng(7);
    std::vector<double> ta, tv;
    for (int i = 0; i <= 18; ++i) {
        const double r = 5.0 * i * M_PI / 180;
        ta.push_back(5.0 * i), tv.push_back(-std::cos(r) * std::cos(r) + 0.1 * std::sin(2 * r) * std::sin(2 * r));
    }
    const CapillaryLaw table = CapillaryLaw::tabulated(ta, tv, "test table");
    const Kind kinds[] = {Kind::Fade, Kind::Far, Kind::Locked};
    for (int n = 0; n < 180; ++n) {
        const CapillaryLaw law = n % 2 ? table : CapillaryLaw();
        BridgeElement e;
        const Vector16d X0 = random_element(rng, kinds[n / 60], e);
        const Eigen::VectorXd X = X0;
        auto val = [&](const Eigen::VectorXd& v) {
            return bridge_element_energy(e, Vector16d(v), 1.0, law, nullptr, nullptr);
        };
        auto grad = [&](const Eigen::VectorXd& v) {
            Vector16d g;
            bridge_element_energy(e, Vector16d(v), 1.0, law, &g, nullptr);
            return Eigen::VectorXd(g);
        };
        Vector16d g;
        Matrix16d H;
        bridge_element_energy(e, X0, 1.0, law, &g, &H);
        const Eigen::VectorXd fg = fdtest::fd_gradient(val, X, 1e-7);
        const Eigen::MatrixXd fh = fdtest::fd_jacobian(grad, X, 1e-7);
        INFO("element " << n);
        CHECK((Eigen::VectorXd(g) - fg).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, g.cwiseAbs().maxCoeff()));
        CHECK((Eigen::MatrixXd(H) - fh).cwiseAbs().maxCoeff() <= 1e-5 * std::max(1.0, H.cwiseAbs().maxCoeff()));
    }
}

TEST_CASE("bridge element: a crossing that left the window of home +- 1 segment pulls no more", "[wet][bridge]") {
    // Side 0 along x, segments of 0.1 (home from 0 to 0.1); side 1 at 60 deg through (x, 0). A stale set (a long solve
    // of a fixed set) can carry a crossing past the + neighbour's far node at x = 0.2: the neighbour's term fades out
    // over a quarter of its length beyond it, and the home takes no share.
    CapillaryLaw law;
    BridgeElement e;
    for (int a = 0; a < 8; ++a) e.node[a] = a, e.shift[a] = {0, 0};
    for (double& l : e.l0) l = 0.1;
    const Eigen::Vector2d u(std::cos(M_PI / 3), std::sin(M_PI / 3));
    auto at = [&](double x) {
        Vector16d X;
        for (int a = 0; a < 4; ++a) X.segment<2>(2 * a) = Eigen::Vector2d(0.1 * (a - 1), 0);
        for (int a = 0; a < 4; ++a) X.segment<2>(8 + 2 * a) = Eigen::Vector2d(x, 0) + 0.1 * (a - 1.5) * u;
        return X;
    };
    Vector16d g;
    const double full = bridge_element_energy(e, at(0.15), 1.0, law, &g, nullptr);  // inside the + neighbour
    CHECK(full == Approx(-0.1 * 0.25));                                             // -beta l cos^2 60
    const double zone = bridge_element_energy(e, at(0.2 + 0.0125), 1.0, law, &g, nullptr);  // mid-fade
    CHECK(zone == Approx(0.5 * full));
    const double out = bridge_element_energy(e, at(0.2 + 0.03), 1.0, law, &g, nullptr);  // past the fade
    CHECK(out == 0);
    CHECK(g.cwiseAbs().maxCoeff() == 0);
    CHECK(bridge_element_energy(e, at(-0.1 - 0.03), 1.0, law, &g, nullptr) == 0);  // the same on the - side
    CHECK(bridge_element_energy(e, at(-0.1 - 0.0125), 1.0, law, &g, nullptr) == Approx(0.5 * full));
}
