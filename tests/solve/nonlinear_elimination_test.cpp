// Nonlinear elimination inside Newton (issue 23, solve/nonlinear_elimination.hpp): it must return an equilibrium of
// the whole energy (max|g| <= tol on every coordinate), the same one plain Newton finds, with the energy never rising,
// through an objective's own restriction and through SubsetObjective alike; options are checked by name.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/prune.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/solve/nonlinear_elimination.hpp"
#include "fibernet/solve/subset_objective.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {

// The default scene's network (L = 10, q = 8, pl = 1, seed 1), dangling fibers and end arms pruned: sheared to 0.01
// from the affine start, plain Newton needs ~50 iterations, most of them on a few local places.
struct Sheared {
    Model m;
    std::unique_ptr<NetworkEnergy> e;
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    Sheared() {
        MikadoParams mp;
        mp.L = 10, mp.q = 8, mp.pl = 1, mp.seed = 1;
        DiscretizationParams dp;
        dp.scheme = Scheme::Even, dp.aspect_ratio = 10, dp.trim_ends = true;
        m = discretize(prune(generate_mikado(mp), PruneOptions{true, false}), dp);
        e = std::make_unique<NetworkEnergy>(m);
        F(0, 1) = 0.01;
    }
};

// Records the energy of every full Hessian assembly (Newton assembles at each accepted state, and again after each
// elimination). Its restriction is the wrapped objective's own (kind 0), a SubsetObjective of the wrapped one (kind 1;
// so that the local solves are not recorded: their trial points lie above the current energy), or none (kind 2:
// Newton then forms a SubsetObjective of this wrapper, and energies are not compared).
class Recording : public Objective {
public:
    Recording(Objective& f, int kind) : f_(f), kind_(kind) {}
    int size() const override { return f_.size(); }
    double value(const Eigen::VectorXd& q) override { return f_.value(q); }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override { return f_.gradient(q, g); }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        const double E = f_.hessian(q, g, H, psd);
        energies.push_back(E);
        restrictions_at.push_back(restrictions);
        return E;
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return f_.hessian_pattern(); }
    std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& c) override {
        ++restrictions;
        if (kind_ == 0) return f_.restriction(q, c);
        if (kind_ == 1) return std::make_unique<SubsetObjective>(f_, q, c);
        return nullptr;
    }
    std::vector<double> energies;
    std::vector<int> restrictions_at;  // restrictions made before each assembly
    int restrictions = 0;

private:
    Objective& f_;
    int kind_;
};

// The Hessian pattern of a chain of n coordinates (tridiagonal, upper triangle).
Eigen::SparseMatrix<double> chain_pattern(int n) {
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < n; ++i) {
        t.emplace_back(i, i, 0.0);
        if (i + 1 < n) t.emplace_back(i, i + 1, 0.0);
    }
    Eigen::SparseMatrix<double> P(n, n);
    P.setFromTriplets(t.begin(), t.end());
    return P;
}

// Energy at every full assembly: non-increasing (local solves and accepted steps only lower it), up to what Newton
// accepts in the round-off regime, a rise of at most 1e-12 (1 + |E|) per accepted step (newton.hpp), the global
// step's and each local solve's between the two assemblies (a part's energy is at most E: every term is >= 0). Rises
// of 1e-15 relative occur with some CPUs' kernels.
void check_never_rising(const Recording& rec) {
    for (size_t k = 1; k < rec.energies.size(); ++k) {
        const int steps = 1 + rec.restrictions_at[k] - rec.restrictions_at[k - 1];
        INFO("assembly " << k << ": " << steps << " solves since the last");
        CHECK(rec.energies[k] - rec.energies[k - 1] <= 1e-12 * steps * (1 + std::abs(rec.energies[k - 1])));
    }
}

SolveResult solve(Objective& f, Eigen::VectorXd& q, bool eliminate) {
    SolverOptions o;
    o.tol = 1e-9, o.eliminate = eliminate;
    NewtonSolver s(o);
    return s.minimize(f, q);
}

// The sheared network, its affine start and plain Newton's solve from there.
struct PlainReference {
    Sheared net;
    StrainedEnergy f{*net.e, net.F};
    Eigen::VectorXd q0 = affine_start(*net.e, net.F);
    SolveResult plain;
    PlainReference() {
        Eigen::VectorXd q = q0;
        plain = solve(f, q, false);
    }
};

}  // namespace

TEST_CASE("Newton with elimination returns plain Newton's equilibrium of the whole network, energy never rising",
          "[solve][elimination][slow]") {
    PlainReference ref;
    REQUIRE(ref.plain.converged());
    StrainedEnergy& f = ref.f;
    const Eigen::VectorXd& q0 = ref.q0;
    const SolveResult& plain = ref.plain;
    for (int kind : {0, 1, 2}) {
        CAPTURE(kind);
        Recording rec(f, kind);
        Eigen::VectorXd q = q0;
        const SolveResult r = solve(rec, q, true);
        REQUIRE(r.converged());
        CHECK(r.local_solves > 0);  // the network has hot places: elimination ran
        CHECK(r.eliminating_iterations > 0);
        CHECK(r.eliminating_iterations <= r.iterations);
        CHECK(rec.restrictions == r.local_solves);
        // The whole gradient, recomputed here, not the solver's word.
        Eigen::VectorXd g;
        const double E = f.gradient(q, g);
        CHECK(g.lpNorm<Eigen::Infinity>() <= 1e-9);
        if (kind < 2) check_never_rising(rec);
        // The same minimum: with max|g| <= 1e-9 on both, the energies differ by O(|g|^2 / stiffness), far below 1e-12.
        CHECK(std::abs(E - plain.energy) <= 1e-12 * std::abs(plain.energy) + 1e-15);
        CHECK(r.factorizations < plain.factorizations);  // the point of it, on this network 30 against 58
    }
}

TEST_CASE("Newton with elimination reports an unconverged solve as such", "[solve][elimination]") {
    Sheared net;
    StrainedEnergy f(*net.e, net.F);
    Eigen::VectorXd q = affine_start(*net.e, net.F);
    SolverOptions o;
    o.tol = 1e-9, o.eliminate = true, o.max_iter = 3;
    NewtonSolver s(o);
    const SolveResult r = s.minimize(f, q);
    CHECK(r.status == SolveStatus::IterationLimit);
    Eigen::VectorXd g;
    f.gradient(q, g);
    CHECK(g.lpNorm<Eigen::Infinity>() == Approx(r.grad_max).epsilon(1e-12));
}

TEST_CASE("elimination options out of range are refused by name", "[solve][elimination]") {
    auto refused = [](EliminationOptions o, const std::string& what) {
        try {
            o.check("newton");
        } catch (const InputError& e) {
            CHECK_THAT(e.what(), Catch::Contains(what));
            return true;
        }
        return false;
    };
    EliminationOptions o;
    CHECK_NOTHROW(o.check("newton"));
    o.threshold = 1.5;
    CHECK(refused(o, "elimination.threshold = 1.5"));
    o = {}, o.hops = -1;
    CHECK(refused(o, "elimination.hops = -1"));
    o = {}, o.max_fraction = 0;
    CHECK(refused(o, "elimination.max_fraction = 0"));
    o = {}, o.local_rtol = 1;
    CHECK(refused(o, "elimination.local_rtol = 1"));
    o = {}, o.local_max_iter = 0;
    CHECK(refused(o, "elimination.local_max_iter = 0"));
    o = {}, o.block = -3;
    CHECK(refused(o, "elimination.block = -3"));
    o = {}, o.overlap = -1;
    CHECK(refused(o, "elimination.overlap = -1"));
}

TEST_CASE("the Schwarz sweep's blocks cover every coordinate, connected, grown by the overlap", "[solve][elimination]") {
    const int n = 10;
    const Eigen::SparseMatrix<double> P = chain_pattern(n);
    EliminationOptions o;
    o.block = 4, o.overlap = 0;
    NonlinearElimination ne(P, o);
    Eigen::VectorXd g = Eigen::VectorXd::Zero(n);
    CHECK_FALSE(ne.select(g));  // nothing to relax
    g[0] = 1;                   // the blocks do not depend on where the gradient is
    REQUIRE(ne.select(g));
    CHECK(ne.parts() == std::vector<std::vector<int>>{{0, 1, 2, 3}, {4, 5, 6, 7}, {8, 9}});
    CHECK(ne.coordinates() == n);
    o.overlap = 1;
    NonlinearElimination over(P, o);
    REQUIRE(over.select(g));
    CHECK(over.parts() == std::vector<std::vector<int>>{{0, 1, 2, 3, 4}, {3, 4, 5, 6, 7, 8}, {7, 8, 9}});
    // A remainder below a quarter of the block size joins its neighbour: {9} into {0..8}.
    o.block = 9, o.overlap = 0;
    NonlinearElimination merged(P, o);
    REQUIRE(merged.select(g));
    CHECK(merged.parts() == std::vector<std::vector<int>>{{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}});
    CHECK_FALSE(merged.at_trial_points());
    CHECK(NonlinearElimination(P, EliminationOptions{}).at_trial_points());
}

TEST_CASE("Newton with the Schwarz sweep returns plain Newton's equilibrium of the whole network, energy never rising",
          "[solve][elimination][slow]") {
    PlainReference ref;
    REQUIRE(ref.plain.converged());
    for (int kind : {0, 1}) {
        CAPTURE(kind);
        Recording rec(ref.f, kind);
        Eigen::VectorXd q = ref.q0;
        SolverOptions o;
        o.tol = 1e-9, o.eliminate = true, o.elimination.block = 200;
        NewtonSolver s(o);
        const SolveResult r = s.minimize(rec, q);
        REQUIRE(r.converged());
        // A sweep before every global step, and one more if the last sweep left the whole gradient within tol.
        CHECK(r.eliminating_iterations >= r.iterations);
        CHECK(r.eliminating_iterations <= r.iterations + 1);
        CHECK(r.local_solves >= 2 * r.eliminating_iterations);
        Eigen::VectorXd g;
        const double E = ref.f.gradient(q, g);
        CHECK(g.lpNorm<Eigen::Infinity>() <= 1e-9);
        check_never_rising(rec);
        CHECK(std::abs(E - ref.plain.energy) <= 1e-12 * std::abs(ref.plain.energy) + 1e-15);
    }
}

TEST_CASE("elimination selects connected parts of the hot coordinates grown through the pattern", "[solve][elimination]") {
    // A chain of 10 coordinates (tridiagonal pattern), hot at 1 and 8: one hop grows {0,1,2} and {7,8,9}, two parts.
    const int n = 10;
    const Eigen::SparseMatrix<double> P = chain_pattern(n);
    EliminationOptions o;
    o.threshold = 0.5, o.hops = 1, o.max_fraction = 1;
    NonlinearElimination ne(P, o);
    Eigen::VectorXd g = Eigen::VectorXd::Constant(n, 0.01);
    g[1] = 1, g[8] = -0.9;
    REQUIRE(ne.select(g));
    REQUIRE(ne.parts().size() == 2);
    CHECK(ne.parts()[0] == std::vector<int>{0, 1, 2});
    CHECK(ne.parts()[1] == std::vector<int>{7, 8, 9});
    // Three hops join them; a share limit below the grown size turns elimination off.
    o.hops = 3;
    NonlinearElimination joined(P, o);
    REQUIRE(joined.select(g));
    CHECK(joined.parts().size() == 1);
    o.max_fraction = 0.5;
    NonlinearElimination capped(P, o);
    CHECK_FALSE(capped.select(g));
    CHECK_FALSE(ne.select(Eigen::VectorXd::Zero(n)));
}

TEST_CASE("elimination's local solves share the caller's time budget", "[solve][elimination]") {
    Sheared s;
    StrainedEnergy f(*s.e, s.F);
    Eigen::VectorXd q = affine_start(*s.e, s.F), g;
    f.gradient(q, g);
    EliminationOptions eo;
    eo.hops = 1, eo.max_fraction = 1;  // places small enough to be selected at the affine start
    NonlinearElimination ne(f.hessian_pattern(), eo);
    REQUIRE(ne.select(g));
    // A budget spent before the first part: no part moves (none is solved, or its solve stops at its first time test).
    Eigen::VectorXd q1 = q;
    ne.eliminate(f, q1, 1e-10, 1e-300);
    CHECK(q1 == q);
    // No budget: every part is solved, and the energy does not rise.
    const int before = ne.counts().local_solves;
    Eigen::VectorXd q2 = q;
    ne.eliminate(f, q2, 1e-10, 0);
    CHECK(ne.counts().local_solves - before == static_cast<int>(ne.parts().size()));
    CHECK(q2 != q);
    CHECK(f.value(q2) <= f.value(q));
    // Newton with elimination and a spent budget stops at the loop's time test, saying so.
    SolverOptions o;
    o.eliminate = true, o.max_seconds = 1e-9;
    Eigen::VectorXd q3 = q;
    const SolveResult r = NewtonSolver(o).minimize(f, q3);
    CHECK(r.status == SolveStatus::IterationLimit);
    CHECK(r.message == "time limit reached");
}

TEST_CASE("Newton's observe_within sees the state after each local solve of a sweep, its energy never rising",
          "[solve][elimination][slow]") {
    PlainReference ref;
    Eigen::VectorXd q = ref.q0;
    SolverOptions o;
    o.tol = 1e-9, o.eliminate = true, o.elimination.block = 200;
    // Energies in the order the hooks see them: iterates (observe) and states between local solves (observe_within).
    std::vector<double> seen;
    std::vector<char> within;
    o.observe = [&](const Eigen::VectorXd&, double E, double) { seen.push_back(E), within.push_back(0); };
    o.observe_within = [&](const Eigen::VectorXd& qw, const std::function<double()>& energy) {
        const double E = energy();
        CHECK(E == ref.f.value(qw));  // energy() evaluates the whole objective at the state handed over
        seen.push_back(E), within.push_back(1);
    };
    const SolveResult r = NewtonSolver(o).minimize(ref.f, q);
    REQUIRE(r.converged());
    // Every local solve of the sweep is followed by a call (none at a line search's trial points: the sweep has none).
    CHECK(std::count(within.begin(), within.end(), 1) == r.local_solves);
    CHECK(std::count(within.begin(), within.end(), 0) == r.iterations);
    REQUIRE(within.size() >= 2);
    CHECK(within.front() == 1);  // the first sweep comes before the first iterate
    const double E0 = ref.f.value(ref.q0);
    for (size_t k = 0; k < seen.size(); ++k) {
        const double before = k == 0 ? E0 : seen[k - 1];
        INFO("state " << k << (within[k] ? " (between local solves)" : " (iterate)"));
        CHECK(seen[k] - before <= 1e-12 * (1 + std::abs(before)));
    }
}
