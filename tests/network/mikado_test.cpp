#include <catch2/catch.hpp>
#include <cmath>

#include "fibernet/network/mikado.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/random.hpp"

using namespace fibernet;

TEST_CASE("random: the stream is pinned (same seed, same numbers on every platform)", "[network][random]") {
    // xoshiro256** seeded through splitmix64; integer arithmetic only, so these values hold everywhere.
    Rng r(1);
    CHECK(r.next() == 12966619160104079557ULL);
    CHECK(r.next() == 9600361134598540522ULL);
}

TEST_CASE("mikado: a seed gives the same network every time, and the values are pinned", "[network]") {
    MikadoParams p;
    p.L = 10, p.q = 8, p.pl = 0.5, p.seed = 1;
    const Network a = generate_mikado(p), b = generate_mikado(p);
    REQUIRE(a.fibers.size() == 800);
    REQUIRE(a.crossings.size() == b.crossings.size());
    for (size_t i = 0; i < a.fibers.size(); ++i) {
        REQUIRE(a.fibers[i].start == b.fibers[i].start);
        REQUIRE(a.fibers[i].theta == b.fibers[i].theta);
    }
    for (size_t k = 0; k < a.crossings.size(); ++k) REQUIRE(a.crossings[k].crosslink == b.crossings[k].crosslink);
    // Orientation is an exact function of the random stream (no libm): pinned bit for bit.
    CHECK(a.fibers[0].theta == 3.0266240336242332);
    CHECK(a.fibers[1].theta == 2.9453278977872053);
    // Starts involve cos/sin; pinned to 1e-14.
    CHECK(a.fibers[0].start.x() == Approx(7.6241840511161847).epsilon(1e-14));
    CHECK(a.fibers[0].start.y() == Approx(4.112223551963333).epsilon(1e-14));
    p.seed = 2;
    CHECK(generate_mikado(p).fibers[0].theta != a.fibers[0].theta);
}

TEST_CASE("mikado: the generator reproduces the committed reference network", "[network][random]") {
    // data/mikado_L10_q8_pl0.5_seed1.net was written by `fibernet generate --L 10 --q 8 --pl 0.5 --seed 1`: the same
    // seed must give the same network on any platform and standard library (no std:: distributions). Orientations and
    // crosslink draws are exact functions of the stream; positions go through cos/sin (to 1e-13).
    const Network ref = load_network(std::string(FIBERNET_SOURCE_DIR) + "/data/mikado_L10_q8_pl0.5_seed1.net");
    MikadoParams p;
    p.L = 10, p.q = 8, p.pl = 0.5, p.seed = 1;
    const Network net = generate_mikado(p);
    REQUIRE(net.fibers.size() == ref.fibers.size());
    for (size_t i = 0; i < net.fibers.size(); ++i) {
        INFO("fiber " << i);
        CHECK(net.fibers[i].theta == ref.fibers[i].theta);
        CHECK((net.fibers[i].start - ref.fibers[i].start).norm() <= 1e-13 * p.L);
    }
    REQUIRE(net.crossings.size() == ref.crossings.size());
    int mismatched = 0;
    for (size_t k = 0; k < net.crossings.size(); ++k) {
        const Crossing &a = net.crossings[k], &b = ref.crossings[k];
        mismatched += a.f1 != b.f1 || a.f2 != b.f2 || a.image != b.image || a.crosslink != b.crosslink ||
                      std::abs(a.s1 - b.s1) > 1e-12 || std::abs(a.s2 - b.s2) > 1e-12;
    }
    CHECK(mismatched == 0);
}

TEST_CASE("mikado: the cell list finds exactly the crossings of a brute-force search", "[network]") {
    // q = 0.05 at L = 60: a sparse network in a large box, where the cell grid is capped at about 4 cells per fiber
    // (not (L / lf)^2 cells).
    for (bool periodic : {true, false})
        for (double L : {2.2, 2.9, 3.5, 5.0, 60.0})
            for (std::uint64_t seed : {1, 2, 3}) {
                MikadoParams p;
                p.L = L, p.q = L > 10 ? 0.05 : 7, p.pl = 1, p.seed = seed, p.periodic = periodic;
                const Network net = generate_mikado(p);
                const auto fast = net.crossings;
                const auto slow = find_crossings_brute_force(net);
                INFO("L = " << L << ", seed = " << seed << ", periodic = " << periodic);
                REQUIRE(fast.size() == slow.size());
                for (size_t k = 0; k < fast.size(); ++k) {
                    CHECK(fast[k].f1 == slow[k].f1);
                    CHECK(fast[k].f2 == slow[k].f2);
                    CHECK(fast[k].image == slow[k].image);
                    CHECK(fast[k].s1 == slow[k].s1);
                    CHECK(fast[k].s2 == slow[k].s2);
                }
            }
}

TEST_CASE("mikado: mean crossings per fiber is 2q/pi", "[network]") {
    // Per fiber the crossing count is ~Poisson(2q/pi); over N fibers (counted twice per crossing) the mean has a
    // standard error of about sqrt(2 (2q/pi) / N). Accept 4 standard errors.
    MikadoParams p;
    p.L = 30, p.q = 6, p.pl = 1, p.seed = 7;
    const Network net = generate_mikado(p);
    const auto s = statistics(net);
    const double expected = 2 * p.q / M_PI;
    const double se = std::sqrt(2 * expected / s.fibers);
    CHECK(std::abs(s.crossings_per_fiber - expected) < 4 * se);
}

TEST_CASE("mikado: pl sets the fraction of crosslinks", "[network]") {
    MikadoParams p;
    p.L = 20, p.q = 6, p.pl = 0.3, p.seed = 4;
    const auto s = statistics(generate_mikado(p));
    const double frac = double(s.crosslinks) / s.crossings;
    CHECK(std::abs(frac - 0.3) < 4 * std::sqrt(0.3 * 0.7 / s.crossings));
    p.pl = 0;
    CHECK(generate_mikado(p).num_crosslinks() == 0);
}

TEST_CASE("mikado: bad parameters name the value", "[network][input]") {
    MikadoParams p;
    p.q = -1;
    CHECK_THROWS_WITH(generate_mikado(p), Catch::Contains("q (density) = -1"));
    p = {};
    p.pl = 1.5;
    CHECK_THROWS_WITH(generate_mikado(p), Catch::Contains("pl (crosslink probability) = 1.5"));
    p = {};
    p.L = 1.5;
    CHECK_THROWS_WITH(generate_mikado(p), Catch::Contains("L (box side in fiber lengths) = 1.5"));
    p = {};
    p.q = std::nan("");
    CHECK_THROWS_AS(generate_mikado(p), InputError);
}

TEST_CASE("network: connected components of the crosslink graph", "[network]") {
    Network net;
    net.L = 10;
    net.periodic = false;
    for (int i = 0; i < 4; ++i) net.fibers.push_back({Eigen::Vector2d(i, 0), 0.0, 1.0, {}});
    Crossing c;
    c.f1 = 0, c.f2 = 1, c.crosslink = true;
    net.crossings.push_back(c);
    c.f1 = 2, c.f2 = 3, c.crosslink = false;
    net.crossings.push_back(c);
    const auto s = statistics(net);
    CHECK(s.components == 3);
    CHECK(s.largest_component == 2);
}
