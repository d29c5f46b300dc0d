// A region of the wet network (wet_region.hpp) is the whole energy restricted to its coordinates: same gradient and
// Hessian entries, value changes equal, with the rest held; hot_region grows by whole elements. And the active-set loop
// with local rounds still ends at an equilibrium of every coordinate.
#include <catch2/catch.hpp>

#include "fibernet/solve/newton.hpp"
#include "fibernet/util/parallel.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_region.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {
void check_region(const Model& m, const Eigen::Matrix2d& F, std::uint64_t seed) {
    NetworkEnergy dry(m);
    Eigen::VectorXd q = perturb(dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F), 0.02, seed);
    const std::vector<Bridge> bridges = segment_crossings(m, dry.positions(q, F), F * m.box.B0());
    REQUIRE(bridges.size() >= 5);
    WetParams p;
    p.beta = 0.7;
    WetEnergy W(dry, F, bridges, p);
    // A random third of the nodes (fixed nodes included: they have no coordinates and stay out).
    Rng rng(seed + 7);
    std::vector<char> active(m.num_nodes());
    for (auto& a : active) a = rng.uniform() < 0.33;
    std::vector<int> nodes;
    for (int i = 0; i < m.num_nodes(); ++i)
        if (active[i]) nodes.push_back(i);
    RegionState state(W, q);
    WetRegion R(W, state, nodes, element_incidence(W));
    REQUIRE(R.size() > 10);
    REQUIRE(R.size() < W.size());
    Eigen::VectorXd g, ga;
    Eigen::SparseMatrix<double> H = W.hessian_pattern(), Ha = R.hessian_pattern();
    W.hessian(q, g, H, false);
    const Eigen::VectorXd qa = R.restrict(q);
    R.hessian(qa, ga, Ha, false);
    const Eigen::MatrixXd Hf = dense(H), Hr = dense(Ha);
    const std::vector<int>& d = R.dofs();
    double dg = 0, dH = 0;
    for (int i = 0; i < R.size(); ++i) {
        dg = std::max(dg, std::abs(ga[i] - g[d[i]]));
        for (int j = 0; j < R.size(); ++j) dH = std::max(dH, std::abs(Hr(i, j) - Hf(d[i], d[j])));
    }
    CHECK(dg <= 1e-12 * g.cwiseAbs().maxCoeff());
    CHECK(dH <= 1e-12 * Hf.cwiseAbs().maxCoeff());
    // Every region coordinate belongs to an active node, and only free coordinates are in.
    for (int i = 0; i < m.num_nodes(); ++i)
        for (int c = 0; c < 2; ++c)
            if (dry.dof(i, c) >= 0)
                CHECK(active[i] == (std::find(d.begin(), d.end(), dry.dof(i, c)) != d.end()));
    // A step in the region changes both values alike, and embed writes only the region's coordinates.
    const Eigen::VectorXd qa2 = perturb(qa, 0.01, seed + 3);
    Eigen::VectorXd q2 = q;
    R.embed(qa2, q2);
    CHECK(R.value(qa2) - R.value(qa) == Approx(W.value(q2) - W.value(q)).margin(1e-10));
    int changed = 0;
    for (int i = 0; i < q.size(); ++i) changed += q2[i] != q[i];
    CHECK(changed <= R.size());
    CHECK((R.restrict(q2) - qa2).norm() == 0);

    // The incidence of another bridge set, updated from this one's bridge rows, is that set's own.
    const ElementIncidence inc = element_incidence(W);
    {
        WetEnergy W2(dry, F, std::vector<Bridge>(bridges.begin() + bridges.size() / 2, bridges.end()), p);
        ElementIncidence inc2 = inc;
        update_bridge_incidence(W2, inc2);
        const ElementIncidence fresh = element_incidence(W2);
        CHECK(inc2.seg_start == fresh.seg_start);
        CHECK(inc2.seg == fresh.seg);
        CHECK(inc2.hinge == fresh.hinge);
        CHECK(inc2.bridge_start == fresh.bridge_start);
        CHECK(inc2.bridge == fresh.bridge);
        CHECK(inc2.bridge != inc.bridge);
    }
    // The parts of the region are independent: moved one after another through one shared state, each part's gradient
    // at its own new coordinates is the whole energy's at the final state.
    const auto parts = region_parts(W, inc, active);
    REQUIRE(parts.size() >= 2);
    RegionState shared(W, q);
    Eigen::VectorXd q3 = q, gfull;
    std::vector<Eigen::VectorXd> part_g;
    std::vector<std::vector<int>> part_dofs;
    for (size_t k = 0; k < parts.size(); ++k) {
        WetRegion P(W, shared, parts[k], inc);
        const Eigen::VectorXd qk = perturb(P.restrict(q3), 0.01, seed + 11 + k);
        Eigen::VectorXd gk;
        P.gradient(qk, gk);
        P.value(perturb(qk, 0.05, seed + 99));  // a rejected trial point left in the shared state
        P.embed(qk, q3);
        part_g.push_back(gk), part_dofs.push_back(P.dofs());
    }
    W.gradient(q3, gfull);
    double dp = 0;
    for (size_t k = 0; k < parts.size(); ++k)
        for (size_t i = 0; i < part_dofs[k].size(); ++i) dp = std::max(dp, std::abs(part_g[k][i] - gfull[part_dofs[k][i]]));
    CHECK(dp <= 1e-12 * gfull.cwiseAbs().maxCoeff());

    // The gradient brought up to date where the region's nodes moved and some bridges changed is the whole gradient
    // bit for bit (relax_wet after a local round): every third bridge removed, one appended again at the end.
    {
        Eigen::VectorXd gu;
        W.gradient(q, gu);
        Eigen::VectorXd q4 = q;
        R.embed(perturb(qa, 0.01, seed + 5), q4);
        std::vector<Bridge> kept;
        std::vector<char> touched(m.num_nodes(), 0);
        for (size_t k = 0; k < bridges.size(); ++k) {
            if (k % 3 == 1) {
                for (int v : resolve(m, bridges[k]).node)
                    if (v >= 0) touched[v] = 1;
            } else {
                kept.push_back(bridges[k]);
            }
        }
        kept.push_back(bridges[1]);
        WetEnergy W4(dry, F, kept, p);
        ElementIncidence inc4 = inc;
        update_bridge_incidence(W4, inc4);
        update_gradient(W4, inc4, q4, active, touched, gu);
        Eigen::VectorXd gw;
        W4.gradient(q4, gw);
        REQUIRE(gu.size() == gw.size());
        int differ = 0;
        for (int i = 0; i < gw.size(); ++i) differ += gu[i] != gw[i];
        CHECK(differ == 0);
        // Rows at arbitrary flagged nodes are the whole gradient's exactly, the others left as they were.
        Eigen::VectorXd gr = Eigen::VectorXd::Constant(gw.size(), 123.0);
        gradient_rows(W4, inc4, q4, touched, gr);
        int wrong = 0, rows = 0;
        for (int i = 0; i < m.num_nodes(); ++i)
            for (int c = 0; c < 2; ++c) {
                const int r = dry.dof(i, c);
                if (r < 0) continue;
                rows += touched[i];
                wrong += touched[i] ? gr[r] != gw[r] : gr[r] != 123.0;
            }
        CHECK(rows > 0);
        CHECK(wrong == 0);
    }
}
}  // namespace

TEST_CASE("wet region: gradient, Hessian and value changes are the whole energy's", "[wet][region]") {
    const Network net = mikado(2.5, 6, 0.5, 5);
    Eigen::Matrix2d F;
    F << 1.02, 0.08, 0.0, 0.99;  // sheared, across periodic images
    check_region(model_of(net, 8), F, 1);
    check_region(model_of(net, 8), Eigen::Matrix2d::Identity(), 2);
    // Fixed nodes (clamps) sit at F x_ref and have no coordinates.
    Model mc = model_of(net, 8);
    mc.fixed.assign(mc.num_nodes(), 0);
    for (int i = 0; i < mc.num_nodes(); i += 7) mc.fixed[i] = 1;
    check_region(mc, F, 3);
}

TEST_CASE("wet region: nodes by |g|, grown by whole elements, split into independent parts", "[wet][region]") {
    // Two straight fibers far apart, 10 segments each: node k's elements reach k +- 1 (segments) and k +- 2 (hinges).
    const Network net = network_of({{1.0, 1.0, 0.0, 1.0, 0.5}, {1.0, 2.5, 0.0, 1.0, 0.5}}, 4.0);
    const Model m = model_of(net, 10);
    NetworkEnergy dry(m);
    WetEnergy W(dry, Eigen::Matrix2d::Identity(), {}, WetParams{});
    const auto& chain = m.chains[0].nodes;
    const int k = chain[5];
    Eigen::VectorXd g = Eigen::VectorXd::Zero(dry.num_dofs());
    g[dry.dof(k, 1)] = -1e-3;
    g[dry.dof(chain[1], 0)] = 1e-5;  // under the threshold
    auto count = [](const std::vector<char>& v) { return std::count(v.begin(), v.end(), 1); };
    auto grown = [&](double thr, int hops) {
        std::vector<char> in = nodes_above(dry, g, thr);
        grow_region(W, element_incidence(W), in, hops);
        return in;
    };
    CHECK(count(grown(1e-4, 0)) == 1);
    CHECK(grown(1e-4, 0)[k]);
    const std::vector<char> one = grown(1e-4, 1);
    CHECK(count(one) == 5);
    for (int j = 3; j <= 7; ++j) CHECK(one[chain[j]]);
    CHECK(count(grown(1e-4, 2)) == 9);
    CHECK(count(grown(1e-6, 0)) == 2);
    CHECK(count(grown(1e-2, 3)) == 0);
    // Parts: nodes 1 and 5 of fiber 0 grown by one hop (segments and hinges reach 2 nodes) touch: one part; with a
    // node of fiber 1 added, two.
    const ElementIncidence inc = element_incidence(W);
    std::vector<char> in = grown(1e-6, 1);
    CHECK(region_parts(W, inc, in).size() == 1);
    in[m.chains[1].nodes[4]] = 1;
    const auto parts = region_parts(W, inc, in);
    REQUIRE(parts.size() == 2);
    CHECK(parts[0].size() + parts[1].size() == static_cast<size_t>(count(in)));
    // Nodes 0 and 9 of fiber 0 alone share no element (hinges reach 2 nodes): two parts.
    std::vector<char> ends(m.num_nodes(), 0);
    ends[chain[0]] = ends[chain[9]] = 1;
    CHECK(region_parts(W, inc, ends).size() == 2);
    ends[chain[2]] = 1;  // shares a hinge with node 0
    CHECK(region_parts(W, inc, ends).size() == 2);
}

TEST_CASE("wet relaxation: local rounds end at an equilibrium of the whole network", "[wet][region][relax]") {
    const Network net = mikado(4.0, 6, 0.5, 3);
    const Model m = model_of(net, 8);
    NetworkEnergy e(m);
    WetParams p;
    p.beta = 0.05;
    const auto initial = wet_crossings(net, m, m.x, m.box.B0(), {});
    SolverOptions so;
    so.tol = 1e-9, so.max_iter = 300;
    ActiveSetOptions opt;
    opt.local_fraction = 0.5;  // a small network: let regions be half of it
    Eigen::VectorXd q = e.dofs(m.x);
    auto s = make_solver("newton", so);
    const ActiveSetResult r = relax_wet(e, Eigen::Matrix2d::Identity(), p, initial, *s, q, opt);
    INFO(r.message << "; local rounds " << r.local_rounds << " of " << r.rounds);
    CHECK(r.local_rounds > 0);
    REQUIRE(r.stable);
    REQUIRE(r.last.converged());
    Eigen::VectorXd g;
    WetEnergy W(e, Eigen::Matrix2d::Identity(), r.bridges, p);
    CHECK(W.gradient(q, g) == Approx(r.last.energy).epsilon(1e-12));
    CHECK(g.cwiseAbs().maxCoeff() <= so.tol);
    std::vector<Bridge> b = r.bridges;
    // max_rounds bounds the global rounds only: the same run with max_rounds = its global rounds ends the same; one
    // less ends unstable, saying so.
    const int global = r.rounds - r.local_rounds;
    for (int cap : {global, global - 1}) {
        ActiveSetOptions o2 = opt;
        o2.max_rounds = cap;
        Eigen::VectorXd q2 = e.dofs(m.x);
        auto s2 = make_solver("newton", so);
        const ActiveSetResult r2 = relax_wet(e, Eigen::Matrix2d::Identity(), p, initial, *s2, q2, o2);
        INFO("max_rounds " << cap << ": " << r2.message);
        CHECK(r2.stable == (cap == global));
        CHECK(r2.rounds - r2.local_rounds == cap);
        if (cap == global) CHECK(r2.rounds == r.rounds);
        else CHECK(r2.message.find("(" + std::to_string(cap) + " global;") != std::string::npos);
    }
    CHECK(static_cast<int>(r.frozen.size()) == r.frozen_pairs);
    CHECK(update_bridges(e, q, Eigen::Matrix2d::Identity(), b, {}, &r.frozen).total() == 0);  // but on frozen pairs

    // A local round's parts are solved on several threads (the last one by the caller's solver, whose shift a later
    // global round resumes): the same run, bit for bit, on 1 and 3 threads.
    struct RestoreThreads {
        ~RestoreThreads() { set_thread_count(0); }
    } restore_threads;
    for (const int threads : {1, 3}) {
        set_thread_count(threads);
        Eigen::VectorXd qt = e.dofs(m.x);
        auto st = make_solver("newton", so);
        const ActiveSetResult rt = relax_wet(e, Eigen::Matrix2d::Identity(), p, initial, *st, qt, opt);
        INFO(threads << " thread(s): " << rt.message);
        CHECK(rt.rounds == r.rounds);
        CHECK(rt.local_iterations == r.local_iterations);
        CHECK((qt - q).cwiseAbs().maxCoeff() == 0.0);
    }
}

TEST_CASE("wet region: crossing and contact search from flagged segments finds the full search's pairs", "[wet][region]") {
    for (double L : {2.5, 6.0}) {  // one cell holding everything, and a cell list
        const Network net = mikado(L, 8, 0.5, 9);
        const Model m = model_of(net, 8);
        NetworkEnergy dry(m);
        Eigen::Matrix2d F;
        F << 1.0, 0.1, 0.0, 1.0;
        const Eigen::VectorXd x = dry.positions(perturb(dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F), 0.05, 4), F);
        const Eigen::Matrix2d B = F * m.box.B0();
        Rng rng(17);
        std::vector<char> only(m.segments.size());
        for (auto& o : only) o = rng.uniform() < 0.2;
        auto flagged = [&](const Bridge& b) {
            return only[m.chains[b.f1].segments[b.k1]] || only[m.chains[b.f2].segments[b.k2]];
        };
        auto keys = [](std::vector<Bridge> v) {
            std::vector<std::array<int, 6>> k;
            for (const Bridge& b : v) k.push_back({b.f1, b.f2, b.k1, b.k2, b.image.x(), b.image.y()});
            std::sort(k.begin(), k.end());
            return k;
        };
        std::vector<Bridge> all = segment_crossings(m, x, B), want;
        for (const Bridge& b : all)
            if (flagged(b)) want.push_back(b);
        INFO("L " << L << ": " << all.size() << " crossings, " << want.size() << " at flagged segments");
        REQUIRE(want.size() >= 5);
        REQUIRE(want.size() < all.size());
        CHECK(keys(segment_crossings(m, x, B, &only)) == keys(want));
        std::vector<Bridge> ca = segment_contacts(m, x, B, 0.05, 30), cw;
        for (const Bridge& b : ca)
            if (flagged(b)) cw.push_back(b);
        INFO(ca.size() << " contacts, " << cw.size() << " at flagged segments");
        REQUIRE(cw.size() >= 2);
        CHECK(keys(segment_contacts(m, x, B, 0.05, 30, &only)) == keys(cw));
    }
}
