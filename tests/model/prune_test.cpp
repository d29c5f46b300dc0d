#include <catch2/catch.hpp>

#include <sstream>

#include "fibernet/model/discretize.hpp"
#include "fibernet/model/prune.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/network/mikado.hpp"

using namespace fibernet;

TEST_CASE("prune dangling: every kept fiber has >= 2 crosslinks to kept fibers", "[model][prune]") {
    MikadoParams p;
    p.L = 6, p.q = 4, p.pl = 0.7, p.seed = 3;
    const Network net = generate_mikado(p);
    std::vector<int> kept;
    const Network pr = prune(net, {true, false}, &kept);
    REQUIRE(pr.fibers.size() < net.fibers.size());
    REQUIRE(pr.fibers.size() > 0);
    std::vector<int> deg(pr.fibers.size(), 0);
    for (const auto& c : pr.crossings)
        if (c.crosslink) ++deg[c.f1], ++deg[c.f2];
    for (int d : deg) CHECK(d >= 2);
    // Kept fibers are the originals, with their crossings.
    for (size_t i = 0; i < kept.size(); ++i) CHECK(pr.fibers[i].start == net.fibers[kept[i]].start);
}

TEST_CASE("prune nonspanning: only clusters that wrap the periodic box stay", "[model][prune]") {
    // Two fibers crossing once do not wrap; far above percolation the big cluster wraps.
    MikadoParams p;
    p.L = 5, p.q = 8, p.pl = 1, p.seed = 2;
    const Network net = generate_mikado(p);
    const auto w = wrapping_fibers(net);
    const auto comp = crosslink_components(net);
    int wrapping = 0;
    for (char c : w) wrapping += c;
    CHECK(wrapping > 0.8 * net.fibers.size());
    const Network pr = prune(net, {false, true});
    CHECK(pr.fibers.size() == static_cast<size_t>(wrapping));
    // A dilute network (q = 1) has no wrapping cluster at all.
    p.q = 1;
    const Network dilute = generate_mikado(p);
    CHECK(prune(dilute, {false, true}).fibers.empty());
    // Open boxes never wrap.
    p.q = 8, p.periodic = false;
    for (char c : wrapping_fibers(generate_mikado(p))) CHECK(c == 0);
}

TEST_CASE("prune: kept fibers are discretized exactly as in the unpruned model", "[model][prune]") {
    MikadoParams p;
    p.L = 5, p.q = 8, p.pl = 0.8, p.seed = 6;
    const Network net = generate_mikado(p);
    std::vector<int> kept;
    const Network pr = prune(net, {true, true}, &kept);
    REQUIRE(!pr.fibers.empty());
    REQUIRE(pr.fibers.size() < net.fibers.size());
    int with_breakpoints = 0;
    for (const auto& f : pr.fibers) with_breakpoints += !f.breakpoints.empty();
    REQUIRE(with_breakpoints > 0);  // some kept fiber lost a crosslink partner
    for (Scheme s : {Scheme::Seed, Scheme::Even}) {
        DiscretizationParams d;
        d.scheme = s;
        const Model full = discretize(net, d), part = discretize(pr, d);
        for (size_t i = 0; i < kept.size(); ++i) {
            const auto& a = full.chains[kept[i]].s;
            const auto& b = part.chains[i].s;
            REQUIRE(a.size() == b.size());
            for (size_t k = 0; k < a.size(); ++k) CHECK(b[k] == Approx(a[k]).margin(1e-12));
        }
    }
    // Breakpoints survive a save and load.
    std::stringstream ss;
    write_network(ss, pr);
    const Network back = read_network(ss, "memory");
    for (size_t i = 0; i < pr.fibers.size(); ++i) CHECK(back.fibers[i].breakpoints == pr.fibers[i].breakpoints);
}
