// The outer loop on random networks: beta = 0 reproduces the dry relaxation exactly; with capillary load it
// terminates (stable or cycling reported) and its final state is an equilibrium of its final bridge set.
#include <catch2/catch.hpp>

#include "fibernet/mechanics/equilibrium.hpp"  // affine_start
#include "fibernet/solve/newton.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_run.hpp"
#include "fibernet/wet/wetting.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {
std::unique_ptr<Solver> newton() {
    SolverOptions so;
    so.tol = 1e-9;
    so.max_iter = 300;
    return make_solver("newton", so);
}
}  // namespace

TEST_CASE("wet relaxation: beta = 0 gives the dry equilibrium bit for bit", "[wet][relax]") {
    const Network net = mikado(3.0, 5, 0.5, 12);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    Eigen::Matrix2d F;
    F << 1, 0.05, 0, 1;
    auto s1 = newton();
    Eigen::VectorXd q_dry = affine_start(e, F);
    StrainedEnergy dry_energy(e, F);
    REQUIRE(s1->minimize(dry_energy, q_dry).converged());
    Eigen::VectorXd q = affine_start(e, F);
    auto s2 = newton();
    const ActiveSetResult r = relax_wet(e, F, WetParams{}, wet_crossings(net, m, m.x, m.box.B0(), {}), *s2, q);
    REQUIRE(r.last.converged());
    CHECK(r.stable);
    CHECK((q.array() == q_dry.array()).all());
}

TEST_CASE("wet relaxation: the active-set loop terminates and reports", "[wet][relax]") {
    // Kept small: Newton needs a few hundred iterations here (floppy parts move far under any capillary load).
    for (std::uint64_t seed : {2})
        for (double beta : {0.05, 0.5}) {
            const Network net = mikado(2.5, 6, 0.8, seed);
            const Model m = model_of(net, 10);
            NetworkEnergy e(m);
            Eigen::VectorXd q = e.dofs(m.x);
            auto s = newton();
            s->options().max_iter = 1000;  // headroom over the few hundred it needs: the budget is not what is tested
            WetParams p;
            p.beta = beta;
            const auto initial = wet_crossings(net, m, m.x, m.box.B0(), {});
            const ActiveSetResult r = relax_wet(e, Eigen::Matrix2d::Identity(), p, initial, *s, q);
            INFO("seed " << seed << ", beta " << beta << ": " << r.message << "; moves " << r.events.moves << ", formed "
                         << r.events.formed << ", ruptures " << r.events.ruptures << ", merged " << r.events.merged);
            CHECK(!r.message.empty());
            CHECK(r.rounds >= 1);
            CHECK(static_cast<int>(r.per_round.size()) <= r.rounds);
            CHECK(r.rounds <= ActiveSetOptions().max_rounds);
            CHECK((r.stable || r.cycling));
            CHECK(r.last.converged());
            if (r.stable) {
                // The final set is consistent: one more update finds nothing to do.
                std::vector<Bridge> b = r.bridges;
                CHECK(update_bridges(e, q, Eigen::Matrix2d::Identity(), b).total() == 0);
            }
        }
}


TEST_CASE("wet relaxation: rounds are capped while the bridge set changes, then solved to the end", "[wet][relax]") {
    const Network net = mikado(2.5, 6, 0.8, 2);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    WetParams p;
    p.beta = 0.5;
    const auto initial = wet_crossings(net, m, m.x, m.box.B0(), {});
    for (int cap : {4, 0}) {
        SolverOptions so;
        so.tol = 1e-9, so.max_iter = 300;
        Recording s(so);
        ActiveSetOptions opt;
        opt.round_iterations = cap;
        opt.local_fraction = 0;  // one solve of the whole network per round (local rounds: wet_region_test.cpp)
        Eigen::VectorXd q = e.dofs(m.x);
        const ActiveSetResult r = relax_wet(e, Eigen::Matrix2d::Identity(), p, initial, s, q, opt);
        INFO("cap " << cap << ": " << r.message << ", rounds " << r.rounds);
        REQUIRE(r.stable);
        CHECK(r.last.converged());
        std::vector<Bridge> b = r.bridges;
        CHECK(update_bridges(e, q, Eigen::Matrix2d::Identity(), b).total() == 0);
        // The solver's own options are back as they were.
        CHECK(s.options().max_iter == 300);
        CHECK(!s.options().warm_start);
        CHECK(!s.options().ldl);
        REQUIRE(s.caps.size() == static_cast<size_t>(r.rounds));
        for (bool l : s.ldl) CHECK(l);  // Newton's LDL^T rung on every round (ActiveSetOptions::newton_ldl)
        CHECK(!s.warm[0]);
        int capped = 0;
        for (int k = 0; k < r.rounds; ++k) {
            INFO("round " << k + 1);
            // A round after one cut at the cap resumes its solve (warm start); others start afresh.
            if (k > 0) CHECK(s.warm[k] == (s.caps[k - 1] == cap && s.iterations[k - 1] == cap));
            if (cap == 0) {
                CHECK(s.caps[k] == 300);
                continue;
            }
            // Round 1 is capped; a later one only if the round before it changed the set (to one not seen before).
            const bool changed = k == 0 || r.per_round[k - 1].total() + r.per_round[k - 1].locked > 0;
            CHECK((s.caps[k] == cap || s.caps[k] == 300));
            if (!changed) CHECK(s.caps[k] == 300);
            if (k == 0) CHECK(s.caps[k] == cap);
            capped += s.caps[k] == cap && s.iterations[k] == cap;
        }
        if (cap > 0) CHECK(capped >= 1);  // the cap did stop a round here
    }
}

TEST_CASE("wet relaxation: Newton's LDL^T rung only under capillary load, and only if asked", "[wet][relax]") {
    const Network net = mikado(2.5, 6, 0.8, 2);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    const auto initial = wet_crossings(net, m, m.x, m.box.B0(), {});
    for (double beta : {0.0, 0.5})
        for (bool use : {true, false}) {
            WetParams p;
            p.beta = beta;
            SolverOptions so;
            so.tol = 1e-9, so.max_iter = 300;
            Recording s(so);
            ActiveSetOptions opt;
            opt.newton_ldl = use;
            Eigen::VectorXd q = e.dofs(m.x);
            const ActiveSetResult r = relax_wet(e, Eigen::Matrix2d::Identity(), p, initial, s, q, opt);
            INFO("beta " << beta << ", newton_ldl " << use << ": " << r.message);
            CHECK(r.stable);
            REQUIRE(!s.ldl.empty());
            for (bool l : s.ldl) CHECK(l == (use && beta > 0));  // beta = 0 stays the dry solve, bit for bit
            CHECK(!s.options().ldl);
        }
}

TEST_CASE("wet relaxation: crossings the wetting rule leaves dry stay dry", "[wet][relax]") {
    // Before, the first update gave every free crossing a bridge again (fraction 0 at beta = 0 ended with a bridge on
    // each of them), since it had no record of which crossings the rule had left dry.
    const Network net = mikado(3.0, 10, 0.5, 2);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    for (const WetWhich which : {WetWhich::Fraction, WetWhich::Free}) {
        for (const double fraction : {0.0, 0.5}) {
            if (which == WetWhich::Free && fraction > 0) continue;
            WettingRule rule;
            rule.which = which, rule.fraction = fraction, rule.seed = 3;
            const FiberPairs dry = dry_pairs(net, rule);
            const auto initial = wet_crossings(net, m, m.x, m.box.B0(), rule);
            INFO(to_string(which) << " " << fraction << ": " << dry.size() << " dry pairs, " << initial.size()
                                  << " initial bridges of " << net.crossings.size() << " crossings");
            REQUIRE(dry.size() > 10);
            CHECK(initial.size() + dry.size() >= net.crossings.size() - 2);  // a pair may cross twice (images)
            for (const Bridge& b : initial) CHECK(dry.count({b.f1, b.f2}) == 0);
            // One update with new bridges allowed, as after a round: no crossing bridge forms between a dry pair
            // (contacts, locked from the start, form as for any pair).
            ActiveSetOptions opt;
            opt.dry_pairs = std::make_shared<const FiberPairs>(dry);
            std::vector<Bridge> b = initial;
            update_bridges(e, e.dofs(m.x), Eigen::Matrix2d::Identity(), b, opt);
            int on_dry = 0;
            for (const Bridge& x : b) on_dry += static_cast<int>(!x.locked && dry.count({x.f1, x.f2}));
            CHECK(on_dry == 0);
            // Without the record, the same update wets most of them again.
            std::vector<Bridge> open = initial;
            update_bridges(e, e.dofs(m.x), Eigen::Matrix2d::Identity(), open, ActiveSetOptions{});
            int reopened = 0;
            for (const Bridge& x : open) reopened += static_cast<int>(!x.locked && dry.count({x.f1, x.f2}));
            // Free: crosslinked pairs share a node, which no crossing bridge spans anyway.
            if (which == WetWhich::Fraction) CHECK(reopened > static_cast<int>(dry.size()) / 3);  // about half are crosslinked
        }
    }
    // The whole run: at beta > 0 no dry pair holds a crossing bridge at the end either (a contact may have locked
    // there, and a locked bridge never was a crossing bridge of a dry pair: none could form).
    WetRunOptions opt;
    opt.params.beta = 0.05;
    opt.moduli = false;
    opt.rule.which = WetWhich::Fraction, opt.rule.fraction = 0.5, opt.rule.seed = 3;
    opt.solver_options.tol = 1e-9;
    const WetRun run = run_wet(net, m, Eigen::Matrix2d::Identity(), opt);
    INFO(run.active.message);
    CHECK(run.active.stable);
    const FiberPairs dry = dry_pairs(net, opt.rule);
    int on_dry = 0;
    for (const Bridge& x : run.active.bridges) on_dry += static_cast<int>(!x.locked && dry.count({x.f1, x.f2}));
    CHECK(on_dry == 0);
    CHECK(run.active.events.formed > 0);  // new crossings and contacts of other pairs still get bridges
}

TEST_CASE("wet relaxation: a solve that uses its whole iteration budget without changing the set ends unconverged",
          "[wet][relax]") {
    // L-BFGS with a small budget on a network it cannot settle in that many iterations: before, every round ran its
    // max_iter again with the set unchanged, towards max_rounds (239 rounds of 500 iterations on a 90-fiber network).
    const Network net = mikado(3.0, 10, 0.5, 2);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    SolverOptions so;
    so.tol = 1e-10, so.max_iter = 20;
    auto lbfgs = make_solver("lbfgs", so);
    WetParams p;
    p.beta = 0.01;
    Eigen::VectorXd q = e.dofs(m.x);
    ActiveSetOptions opt;
    opt.round_iterations = 0, opt.local_fraction = 0;  // as run_wet sets them for first-order solvers
    opt.max_rounds = 200;
    const ActiveSetResult r = relax_wet(e, Eigen::Matrix2d::Identity(), p, wet_crossings(net, m, m.x, m.box.B0(), {}),
                                        *lbfgs, q, opt);
    INFO(r.message << " after " << r.rounds << " rounds");
    CHECK(!r.stable);
    CHECK(!r.last.converged());
    CHECK(r.rounds < opt.max_rounds);
    CHECK(r.message.find("iteration limit") != std::string::npos);
}

TEST_CASE("run_wet refuses what the CLI refuses, and computes no modulus for an unsettled bridge set", "[wet][relax]") {
    const Network net = mikado(3.0, 10, 0.5, 2);
    WetRunOptions opt;
    opt.params.beta = 0.01;
    opt.solver_options.tol = 1e-9;
    // A model whose end arms are trimmed: bridges sit on them (before: a segfault in make_bridge).
    DiscretizationParams trimmed;
    trimmed.trim_ends = true;
    const Model mt = discretize(net, trimmed);
    CHECK_THROWS_WITH(run_wet(net, mt, Eigen::Matrix2d::Identity(), opt), Catch::Contains("not whole"));
    // A model of another network (before: thousands of bogus bridges).
    const Model other = model_of(mikado(3.0, 10, 0.5, 3), 10);
    CHECK_THROWS_WITH(run_wet(net, other, Eigen::Matrix2d::Identity(), opt), Catch::Contains("not discretized from"));
    // The same fibers and crossings with other crosslinks (another pl draws other ones from the same seed).
    const Model other_pl = model_of(mikado(3.0, 10, 0.8, 2), 10);
    REQUIRE(other_pl.crossing_node.size() == net.crossings.size());
    CHECK_THROWS_WITH(run_wet(net, other_pl, Eigen::Matrix2d::Identity(), opt), Catch::Contains("not discretized from"));
    // The free box of an open network (before: "converged after 0 iterations", a meaningless s = 1).
    MikadoParams mp;
    mp.L = 3, mp.q = 10, mp.pl = 0.5, mp.seed = 2, mp.periodic = false;
    const Network open = generate_mikado(mp);
    const Model mo = model_of(open, 10);
    WetRunOptions fb = opt;
    fb.free_box.enabled = true;
    CHECK_THROWS_WITH(run_wet(open, mo, Eigen::Matrix2d::Identity(), fb), Catch::Contains("periodic"));
    // A start state on the event model (its state includes the bridge set), and one of the wrong size.
    const Model ms = model_of(net, 10);
    WetRunOptions start = opt;
    start.wet_start = Eigen::VectorXd::Zero(NetworkEnergy(ms).num_dofs());
    CHECK_THROWS_WITH(run_wet(net, ms, Eigen::Matrix2d::Identity(), start), Catch::Contains("smooth model only"));
    start.model = WetModel::Smooth;
    start.wet_start = Eigen::VectorXd::Zero(3);
    CHECK_THROWS_WITH(run_wet(net, ms, Eigen::Matrix2d::Identity(), start), Catch::Contains("the start state has 3 coordinates"));
    // Stopped after 2 rounds: the last solve converged but the set is not stable, so no modulus (before: a G of an
    // inconsistent set, 0.00983 against the stable 0.01178 on problems/wet.toml).
    const Model m = model_of(net, 10);
    WetRunOptions two = opt;
    two.active_set.max_rounds = 2;
    two.active_set.round_iterations = 0;
    const WetRun r = run_wet(net, m, Eigen::Matrix2d::Identity(), two);
    INFO(r.active.message);
    REQUIRE(!r.active.stable);
    REQUIRE(r.wet.converged);  // the last solve converged: only the set's stability decides
    CHECK(std::isfinite(r.dry.shear_modulus));
    CHECK(std::isnan(r.wet.shear_modulus));
    CHECK(std::isnan(r.wet.shear_modulus_fd));
}
