#include <catch2/catch.hpp>
#include <cmath>
#include <sstream>

#include "fibernet/model/discretize.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
Network net_L4(double pl = 0.6) {
    MikadoParams p;
    p.L = 4, p.q = 6, p.pl = pl, p.seed = 5;
    return generate_mikado(p);
}
}  // namespace

TEST_CASE("discretize seed scheme: n_seg segments per fiber, split at each crosslink", "[model]") {
    const Network net = net_L4();
    DiscretizationParams d;
    const Model m = discretize(net, d);
    const int nf = static_cast<int>(net.fibers.size()), nx = net.num_crosslinks();
    // Each crosslink adds one node on each of its two fibers, merged into one supernode.
    CHECK(m.supernodes.size() == static_cast<size_t>(nx));
    CHECK(m.segments.size() == static_cast<size_t>(nf * 10 + 2 * nx));
    CHECK(m.num_nodes() == nf * 11 + nx);
    CHECK(m.hinges.size() == static_cast<size_t>(nf * 9 + 2 * nx));
    double total = 0;
    for (const auto& s : m.segments) total += s.l0;
    CHECK(total == Approx(nf * 10.0).epsilon(1e-12));
    // Free crossings are kept in the network but make no node.
    int free_crossings = 0;
    for (size_t k = 0; k < net.crossings.size(); ++k) {
        if (!net.crossings[k].crosslink) {
            ++free_crossings;
            CHECK(m.crossing_node[k] == -1);
        } else {
            CHECK(m.crossing_node[k] >= 0);
        }
    }
    CHECK(free_crossings > 0);
}

TEST_CASE("discretize: segment vectors equal the straight fibers (image shifts are right)", "[model]") {
    for (Scheme s : {Scheme::Seed, Scheme::Even}) {
        const Network net = net_L4();
        DiscretizationParams d;
        d.scheme = s;
        const Model m = discretize(net, d);
        const Eigen::Matrix2d B = m.box.B0();
        for (const auto& seg : m.segments) {
            const Eigen::Vector2d v = m.x.segment<2>(2 * seg.j) - m.x.segment<2>(2 * seg.i) + B * seg.shift.cast<double>();
            CHECK(v.norm() == Approx(seg.l0).epsilon(1e-9));
            const Eigen::Vector2d u = net.fibers[seg.fiber].direction();
            CHECK(std::abs(u.x() * v.y() - u.y() * v.x()) < 1e-9 * seg.l0 + 1e-12);
            CHECK(u.dot(v) > 0);
        }
        for (int i = 0; i < m.num_nodes(); ++i) {
            CHECK(m.x[2 * i] >= 0);
            CHECK(m.x[2 * i] < m.box.L);
        }
    }
}

TEST_CASE("discretize even scheme: crosslinks are nodes and pieces are split evenly", "[model]") {
    const Network net = net_L4(1.0);
    DiscretizationParams d;
    d.scheme = Scheme::Even;
    d.h = 1.5;
    const Model m = discretize(net, d);
    CHECK(m.supernodes.size() == static_cast<size_t>(net.num_crosslinks()));
    for (const auto& seg : m.segments) CHECK(seg.l0 <= 1.5 + 1e-12);
    // Even pieces: consecutive segments between two breakpoints share one length.
    const ModelSummary seed_summary = summarize(discretize(net, DiscretizationParams{}));
    const ModelSummary even_summary = summarize(m);
    CHECK(even_summary.shortest_segment >= seed_summary.shortest_segment);
}

TEST_CASE("discretize: coincident pins on a fiber become one supernode", "[model]") {
    // Three fibers meeting at one point (a hand-made triangle corner) and a pin at a fiber end.
    Network net;
    net.L = 10;
    net.periodic = false;
    net.fibers.push_back({Eigen::Vector2d(0, 0), 0.0, 1.0, {}});
    net.fibers.push_back({Eigen::Vector2d(0, 0), M_PI / 3, 1.0, {}});
    net.fibers.push_back({Eigen::Vector2d(0.5, -0.5), M_PI / 2, 1.0, {}});
    auto pin = [&](int a, int b, double sa, double sb) {
        Crossing c;
        c.f1 = a, c.f2 = b, c.s1 = sa, c.s2 = sb, c.crosslink = true;
        net.crossings.push_back(c);
    };
    pin(0, 1, 0, 0);  // both fibers start at the origin
    pin(0, 2, 0.5, 0.5);
    DiscretizationParams d;
    d.n_seg = 2;
    const Model m = discretize(net, d);
    CHECK(m.supernodes.size() == 2);
    CHECK(m.num_nodes() == 3 * 3 - 2);  // 3 nodes per fiber, two merges at the origin... and one at (0.5, 0)
    CHECK(m.crossing_node[0] == m.chains[0].nodes.front());
    CHECK(m.crossing_node[0] == m.chains[1].nodes.front());
}

TEST_CASE("discretize: bad parameters name the value", "[model][input]") {
    DiscretizationParams d;
    d.n_seg = 0;
    CHECK_THROWS_WITH(discretize(net_L4(), d), Catch::Contains("n_seg = 0"));
    d = {};
    d.aspect_ratio = -2;
    CHECK_THROWS_WITH(discretize(net_L4(), d), Catch::Contains("a (aspect ratio) = -2"));
    d = {};
    d.h = 0;
    CHECK_THROWS_AS(discretize(net_L4(), d), InputError);
}

TEST_CASE("model export round-trips exactly", "[model][io]") {
    DiscretizationParams d;
    d.scheme = Scheme::Even;
    const Model m = discretize(net_L4(), d);
    Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.25);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(m.x.size());
    u[3] = 0.125;
    u[4] = 1e-13;  // below the round-off of x_ref + u: only the displacement column keeps it
    std::stringstream ss;
    write_model(ss, m, u, F);
    Eigen::VectorXd u2;
    Eigen::Matrix2d F2;
    const Model r = read_model(ss, "memory", &u2, &F2);
    CHECK(F2 == F);
    CHECK(u2 == u);
    CHECK(r.x == m.x);
    CHECK(r.box.L == m.box.L);
    CHECK(r.aspect_ratio == m.aspect_ratio);
    REQUIRE(r.segments.size() == m.segments.size());
    for (size_t k = 0; k < m.segments.size(); ++k) {
        CHECK(r.segments[k].i == m.segments[k].i);
        CHECK(r.segments[k].j == m.segments[k].j);
        CHECK(r.segments[k].shift == m.segments[k].shift);
        CHECK(r.segments[k].l0 == m.segments[k].l0);
    }
    REQUIRE(r.hinges.size() == m.hinges.size());
    for (size_t k = 0; k < m.hinges.size(); ++k) {
        CHECK(r.hinges[k].k == m.hinges[k].k);
        CHECK(r.hinges[k].shift2 == m.hinges[k].shift2);
        CHECK(r.hinges[k].lt0 == m.hinges[k].lt0);
    }
    CHECK(r.supernodes.size() == m.supernodes.size());
    std::stringstream again;
    write_model(again, r, u2, F2);
    CHECK(again.str() == ss.str());
    std::istringstream bad("fibernet-model 1\nbox 3 periodic\ndeformation 1 0 0 1\naspect_ratio 10\nfiber_length 10\n"
                           "softcore_eps_star -0.95\nnodes 1\n0 0 0 0 0\nsegments 1\n0 3 0 0 1 0 400\n");
    CHECK_THROWS_WITH(read_model(bad, "m.txt"), Catch::Contains("m.txt:10: segment node j = 3 is out of range"));
    std::istringstream v2_short("fibernet-model 2\nbox 3 periodic\ndeformation 1 0 0 1\naspect_ratio 10\n"
                                "fiber_length 10\nsoftcore_eps_star -0.95\nnodes 1\n0 0 0 0 0\n");
    CHECK_THROWS_WITH(read_model(v2_short, "m.txt"), Catch::Contains("m.txt:8: missing node ux"));
}

TEST_CASE("model format 1 (positions only) is still read", "[model][io]") {
    std::istringstream v1("fibernet-model 1\nbox 3 periodic\ndeformation 1 0 0 1\naspect_ratio 10\nfiber_length 10\n"
                          "softcore_eps_star -0.95\nnodes 2\n0.5 0 0 0.25 0\n1 1 0 1 1\nsegments 0\nhinges 0\n"
                          "supernodes 0\n");
    Eigen::VectorXd u;
    read_model(v1, "v1.txt", &u);
    REQUIRE(u.size() == 4);
    CHECK(u[0] == 0.25);
    CHECK(u.tail(3).isZero());
}

TEST_CASE("discretize trim_ends: chains run from the first to the last crosslink, interior unchanged", "[model][prune]") {
    for (Scheme s : {Scheme::Seed, Scheme::Even}) {
        const Network net = net_L4(0.6);
        DiscretizationParams d;
        d.scheme = s;
        const Model full = discretize(net, d);
        d.trim_ends = true;
        const Model trimmed = discretize(net, d);
        REQUIRE(trimmed.chains.size() == full.chains.size());
        CHECK(trimmed.supernodes.size() == full.supernodes.size());
        CHECK(trimmed.num_nodes() < full.num_nodes());
        int empty = 0, single = 0;
        for (size_t f = 0; f < full.chains.size(); ++f) {
            const FiberChain &a = full.chains[f], &b = trimmed.chains[f];
            int pins = 0;
            for (int v : a.nodes)
                for (const auto& sn : full.supernodes) pins += sn.node == v;
            if (pins == 0) {
                CHECK(b.nodes.empty());
                ++empty;
                continue;
            }
            REQUIRE(!b.nodes.empty());
            single += pins == 1;
            CHECK(b.segments.size() + 1 == b.nodes.size());
            // The trimmed chain is a contiguous run of the full one: same arc positions, same node positions.
            size_t k0 = 0;
            while (k0 < a.s.size() && a.s[k0] != b.s.front()) ++k0;
            REQUIRE(k0 + b.s.size() <= a.s.size());
            for (size_t k = 0; k < b.s.size(); ++k) {
                CHECK(b.s[k] == a.s[k0 + k]);
                CHECK((trimmed.x.segment<2>(2 * b.nodes[k]) - full.x.segment<2>(2 * a.nodes[k0 + k])).norm() == 0);
            }
            // Both ends are crosslinks: nothing hangs beyond them.
            auto is_pin = [&](int v) {
                for (const auto& sn : trimmed.supernodes)
                    if (sn.node == v) return true;
                return false;
            };
            CHECK(is_pin(b.nodes.front()));
            CHECK(is_pin(b.nodes.back()));
        }
        CHECK(empty > 0);   // pl = 0.6 leaves fibers without crosslinks: the test covers them
        CHECK(single > 0);  // and fibers pinned once (reduced to their pin)
        // Every crosslink still maps to a node.
        for (size_t k = 0; k < net.crossings.size(); ++k)
            CHECK((trimmed.crossing_node[k] >= 0) == net.crossings[k].crosslink);
    }
}
