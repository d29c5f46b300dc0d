// The smooth capillary pair term (capillary_pair.hpp): exact gradient and Hessian against finite differences in
// every regime (a crossing mid-segment at any angle, near and across the nodes of one or both segments, the angle
// blend, the contact cutoff in distance, the overlap's smoothed ends, a tabulated law), the reduction to today's law
// at a crossing, the telescoping of crossing shares and overlaps along a fiber, and exact zeros beyond the support.
#include <catch2/catch.hpp>
#include <Eigen/Geometry>
#include <cmath>

#include "../energy/fd.hpp"
#include "fibernet/util/random.hpp"
#include "fibernet/wet/capillary_pair.hpp"

using namespace fibernet;

namespace {

const double kDeg = M_PI / 180;

CapillaryPairParams params(double beta = 0.7) {
    CapillaryPairParams p;
    p.beta = beta;
    return p;
}

// Segment a from (0, 0) to (la, 0); segment b of length lb at angle alpha crossing a's line at x = xa, with the
// crossing at fraction fb along b, and offset `off` across a (0: the lines cross at (xa, 0)); then both bent a little
// and the pair moved and turned at random.
Vector8d pair_at(Rng& rng, double la, double lb, double alpha, double xa, double fb, double off = 0) {
    const Eigen::Vector2d u(std::cos(alpha), std::sin(alpha)), n(-u.y(), u.x());
    Eigen::Vector2d P[4];
    P[0] = {0, 0}, P[1] = {la, 0};
    P[2] = Eigen::Vector2d(xa, 0) - fb * lb * u + off * n;
    P[3] = P[2] + lb * u;
    const Eigen::Rotation2Dd rot(rng.uniform(0, 2 * M_PI));
    const Eigen::Vector2d t(rng.uniform(-3, 3), rng.uniform(-3, 3));
    Vector8d X;
    for (int k = 0; k < 4; ++k) X.segment<2>(2 * k) = rot * P[k] + t;
    return X;
}

// max relative error of the gradient (from values) and the Hessian (from gradients); 0 if the term is zero there.
void check_derivatives(const Vector8d& X, bool wet, const CapillaryPairParams& p, double tol = 1e-6) {
    Vector8d g;
    Matrix8d H;
    capillary_pair_energy(X, 1.0, 0.9, wet, p, &g, &H);
    auto f = [&](const Eigen::VectorXd& Y) { return capillary_pair_energy(Y, 1.0, 0.9, wet, p, nullptr, nullptr); };
    auto grad = [&](const Eigen::VectorXd& Y) {
        Vector8d gy;
        capillary_pair_energy(Y, 1.0, 0.9, wet, p, &gy, nullptr);
        return Eigen::VectorXd(gy);
    };
    const double h = 1e-6;
    const Eigen::VectorXd gf = fdtest::fd_gradient(f, X, h);
    const Eigen::MatrixXd Hf = fdtest::fd_jacobian(grad, X, h);
    const double scale = p.beta;  // energies are of order beta
    CHECK((Eigen::VectorXd(g) - gf).cwiseAbs().maxCoeff() <= tol * scale * 10);
    CHECK((Eigen::MatrixXd(H) - Hf).cwiseAbs().maxCoeff() <= tol * scale * 100);
    CHECK((H - H.transpose()).cwiseAbs().maxCoeff() == 0);
}

}  // namespace

TEST_CASE("capillary pair: a crossing mid-segment is today's law", "[wet][capillary_pair]") {
    Rng rng(11);
    const CapillaryPairParams p = params();
    for (int t = 0; t < 40; ++t) {
        const double alpha = rng.uniform(25, 155) * kDeg;
        const Vector8d X = pair_at(rng, 1.0, 0.9, alpha, rng.uniform(0.35, 0.65), rng.uniform(0.35, 0.65));
        const Eigen::Vector2d d1 = X.segment<2>(2) - X.segment<2>(0), d2 = X.segment<2>(6) - X.segment<2>(4);
        CapillaryPairParts parts;
        const double E = capillary_pair_energy(X, 1.0, 0.9, true, p, nullptr, nullptr, false, &parts);
        CHECK(parts.crossing_weight == 1.0);
        CHECK(E == Approx(bridge_energy(d1, d2, 0.95, p.beta, p.law, nullptr, nullptr)).epsilon(1e-13));
        check_derivatives(X, true, p);
        // A dry crossing has no term at these angles.
        CHECK(capillary_pair_energy(X, 1.0, 0.9, false, p, nullptr, nullptr) == 0);
    }
}

TEST_CASE("capillary pair: derivatives near and across nodes, at any angle", "[wet][capillary_pair]") {
    Rng rng(12);
    const CapillaryPairParams p = params();
    int blended = 0;
    for (int t = 0; t < 200; ++t) {
        const double alpha = rng.uniform(21, 159) * kDeg;
        // Within a crossing width (over sin alpha) of a node of a, of b, or of both.
        const double s = std::sin(alpha), r = p.crossing_width / s;
        const int which = t % 3;
        const double xa = which != 1 ? (rng.bernoulli(0.5) ? 0.0 : 1.0) + rng.uniform(-1.2, 1.2) * r : 0.5;
        const double fb = which != 0 ? (rng.bernoulli(0.5) ? 0.0 : 1.0) + rng.uniform(-1.2, 1.2) * r / 0.9 : 0.5;
        const Vector8d X = pair_at(rng, 1.0, 0.9, alpha, xa, fb);
        CapillaryPairParts parts;
        capillary_pair_energy(X, 1.0, 0.9, true, p, nullptr, nullptr, false, &parts);
        if (parts.crossing_weight > 0 && parts.crossing_weight < 1) ++blended;
        check_derivatives(X, true, p);
    }
    CHECK(blended > 100);
}

TEST_CASE("capillary pair: derivatives through the angle blend, the contact cutoff and the overlap ends",
          "[wet][capillary_pair]") {
    Rng rng(13);
    for (const bool law_table : {false, true}) {
        CapillaryPairParams p = params(0.3);
        if (law_table) p.law = CapillaryLaw::tabulated({0, 30, 60, 90}, {-1, -0.8, -0.3, 0.1}, "test");
        int blend = 0, cutoff = 0, ends = 0;
        for (int t = 0; t < 300; ++t) {
            const int kind = t % 3;
            double alpha = rng.uniform(0.5, 25) * kDeg, off = rng.uniform(-0.1, 0.1), xa = 0.5, fb = 0.5;
            if (kind == 0) alpha = rng.uniform(9.5, 20.5) * kDeg;                     // the angle blend
            if (kind == 1) off = (rng.bernoulli(0.5) ? 1 : -1) * rng.uniform(0.18, 0.32), alpha = rng.uniform(0, 8) * kDeg;
            if (kind == 2) xa = rng.uniform(-0.55, -0.35) + (rng.bernoulli(0.5) ? 0 : 1.9), alpha = rng.uniform(0, 8) * kDeg;
            if (rng.bernoulli(0.5)) alpha = M_PI - alpha;  // b antiparallel to a
            const Vector8d X = pair_at(rng, 1.0, 0.9, alpha, xa, fb, off);
            CapillaryPairParts parts;
            capillary_pair_energy(X, 1.0, 0.9, true, p, nullptr, nullptr, false, &parts);
            const double s = std::sqrt(parts.sin2);
            blend += s > std::sin(10 * kDeg) && s < std::sin(20 * kDeg) && parts.contact_weight > 0;
            cutoff += parts.contact_weight > 0 && parts.contact_weight < 1 && s < std::sin(10 * kDeg);
            ends += parts.overlap > 0 && parts.overlap < 0.2;
            for (const bool wet : {true, false}) check_derivatives(X, wet, p);
            CHECK(parts.overlap >= -1e-12);
        }
        CHECK(blend > 30);
        CHECK(cutoff > 30);
        CHECK(ends > 30);
    }
}

TEST_CASE("capillary pair: crossing shares telescope along a fiber, overlaps add up", "[wet][capillary_pair]") {
    // Fiber A along x from 0 to 3 in segments of uneven length; segment b crosses it at 60 deg. The crossing shares
    // of A's segments sum to 1 wherever the crossing is on the fiber, and fade to 0 off its ends.
    const CapillaryPairParams p = params(1.0);
    const double cuts[] = {0, 0.7, 1.05, 1.12, 2.0, 3.0};
    const double alpha = 60 * kDeg;
    const Eigen::Vector2d u(std::cos(alpha), std::sin(alpha));
    for (double xc = -0.3; xc <= 3.3; xc += 0.01) {
        double sum = 0;
        for (int k = 0; k + 1 < 6; ++k) {
            Vector8d X;
            X << cuts[k], 0, cuts[k + 1], 0, Eigen::Vector2d(xc, 0) - 0.5 * u, Eigen::Vector2d(xc, 0) + 0.5 * u;
            CapillaryPairParts parts;
            capillary_pair_energy(X, 1, 1, true, p, nullptr, nullptr, false, &parts);
            sum += parts.crossing_weight;
        }
        const double r = p.crossing_width / std::sin(alpha);
        if (xc > r && xc < 3 - r) CHECK(sum == Approx(1).epsilon(1e-12));
        if (xc < -r || xc > 3 + r) CHECK(sum == 0);
        CHECK(sum >= 0);
        CHECK(sum <= 1 + 1e-12);
    }
    // Two parallel fibers 0.1 apart, cut differently: the overlaps of their segments add up to the fibers' overlap,
    // the same as the fiber pair as a whole, wherever B slides (ends more than w apart).
    const double cb[] = {0, 0.4, 1.3, 1.35, 2.2};
    for (double shift = -1.0; shift <= 1.8; shift += 0.05) {
        double sum = 0;
        for (int i = 0; i + 1 < 6; ++i)
            for (int j = 0; j + 1 < 5; ++j) {
                Vector8d X;
                X << cuts[i], 0, cuts[i + 1], 0, cb[j] + shift, 0.1, cb[j + 1] + shift, 0.1;
                CapillaryPairParts parts;
                capillary_pair_energy(X, 1, 1, true, p, nullptr, nullptr, false, &parts);
                sum += parts.overlap;
            }
        Vector8d whole;
        whole << 0, 0, 3, 0, shift, 0.1, 2.2 + shift, 0.1;
        CapillaryPairParts parts;
        capillary_pair_energy(whole, 1, 1, true, p, nullptr, nullptr, false, &parts);
        CHECK(sum == Approx(parts.overlap).margin(1e-12));
        if (shift > 0.2 && shift < 0.7) CHECK(sum == Approx(2.2).margin(1e-12));  // B inside A: no end in play
    }
}

TEST_CASE("capillary pair: exactly zero beyond the support distance", "[wet][capillary_pair]") {
    Rng rng(14);
    const CapillaryPairParams p = params();
    const double support = p.support_distance(1.0);
    int zero = 0;
    for (int t = 0; t < 2000; ++t) {
        const double alpha = rng.uniform(0, 180) * kDeg;
        const Vector8d X = pair_at(rng, 1.0, rng.uniform(0.2, 1.0), alpha, rng.uniform(-4, 5), rng.uniform(-4, 5),
                                   rng.uniform(-3, 3));
        const double d = segment_distance(X.segment<2>(0), X.segment<2>(2), X.segment<2>(4), X.segment<2>(6));
        Vector8d g;
        Matrix8d H;
        const double E = capillary_pair_energy(X, 1, 1, true, p, &g, &H);
        if (d >= support) {
            ++zero;
            CHECK(capillary_pair_vanishes(X, true, p));
            CHECK(E == 0);
            CHECK(g.isZero(0));
        }
        if (capillary_pair_vanishes(X, true, p)) CHECK((E == 0 && g.isZero(0) && H.isZero(0)));
    }
    CHECK(zero > 500);
}

TEST_CASE("capillary pair: bad widths and angles are refused by name", "[wet][capillary_pair]") {
    CapillaryPairParams p = params();
    p.contact = -1;
    CHECK_THROWS_WITH(p.check("scene.toml [wet]"), Catch::Contains("contact_distance = -1"));
    p = params();
    p.crossing_width = NAN;
    CHECK_THROWS_WITH(p.check("w"), Catch::Contains("crossing_width"));
    p = params();
    p.angle_lo_deg = 30;
    CHECK_THROWS_WITH(p.check("w"), Catch::Contains("lo < hi"));
}
