// Linear moduli of wet equilibria (wet_moduli.hpp): with beta = 0 they are the dry energy's linear moduli; with
// capillary load and the bridge set frozen they are the limit of the relaxed second difference as the strain step
// goes to zero; and they are what is reported for a wet run (the second difference at 1e-4 can jump branches near a
// capillary instability, docs/wet.md "Shear modulus dry and wet").
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "fibernet/mechanics/equilibrium.hpp"  // affine_start, StrainedEnergy
#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_moduli.hpp"
#include "fibernet/wet/wet_run.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

TEST_CASE("wet linear moduli: beta = 0 gives the dry linear moduli", "[wet][moduli]") {
    // A rigid network relaxed in a sheared box (not the stress-free reference: the non-affine part is not zero).
    const Network net = mikado(2.5, 10, 1.0, 4);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    Eigen::Matrix2d F;
    F << 1, 0.04, 0, 1;
    SolverOptions so;
    so.tol = 1e-11;
    auto solver = make_solver("newton", so);
    Eigen::VectorXd q = affine_start(e, F);
    StrainedEnergy se(e, F);
    REQUIRE(solver->minimize(se, q).converged());
    const double A = std::abs((F * m.box.B0()).determinant());
    const std::vector<StrainMode> modes{shear_mode(F, A), bulk_mode(F, A)};
    const auto dry = linear_moduli(e, q, F, modes);
    // Bridges at every crossing, but beta = 0: no capillary term is evaluated, so this checks the shared relaxed part
    // (relaxed_moduli) and the plumbing of wet_linear_moduli, not the bridges' terms (the next test does).
    WetEnergy W(e, F, wet_crossings(net, m, e.positions(q, F), F * m.box.B0(), {}), WetParams{});
    const auto wet = wet_linear_moduli(W, q, modes);
    for (size_t k = 0; k < modes.size(); ++k) {
        INFO(modes[k].name << ": dry " << dry[k].value << ", wet energy with beta = 0 " << wet[k].value);
        REQUIRE(dry[k].ok);
        REQUIRE(wet[k].ok);
        CHECK(dry[k].value > 1e-3);
        CHECK(wet[k].value == Approx(dry[k].value).epsilon(1e-10));
        CHECK(std::isnan(wet[k].affine));
    }
}

TEST_CASE("wet linear moduli: the limit of the relaxed second difference with the bridge set frozen", "[wet][moduli]") {
    const Network net = mikado(2.5, 10, 0.5, 4);
    const Model m = model_of(net, 10);
    NetworkEnergy e(m);
    const Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    SolverOptions so;
    so.tol = 1e-11;
    so.max_iter = 500;
    auto solver = make_solver("newton", so);
    Eigen::VectorXd q = e.dofs(m.x);
    WetParams p;
    p.beta = 0.05;
    const ActiveSetResult r = relax_wet(e, F, p, wet_crossings(net, m, m.x, m.box.B0(), {}), *solver, q);
    REQUIRE(r.stable);
    const double A = m.box.area();
    WetEnergy W(e, F, r.bridges, p);
    ModuliInfo info;
    const auto G = wet_linear_moduli(W, q, {shear_mode(F, A)}, {}, &info);
    INFO(info.message);
    REQUIRE(G.front().ok);
    // The bridges matter: the dry network's own modulus, at its (reference) equilibrium. (Before 2026-11-25 this took
    // the dry energy at the wet state, no equilibrium of it: linear_moduli now refuses such a state.)
    const auto G_dry = linear_moduli(e, e.dofs(m.x), F, {shear_mode(F, A)});
    REQUIRE(G_dry.front().ok);
    INFO("G wet " << G.front().value << ", G dry " << G_dry.front().value);
    CHECK(std::abs(G.front().value - G_dry.front().value) > 0.1 * std::abs(G.front().value));  // the bridges matter
    // Central second differences of relaxed energies: error O(h^2) until a step leaves the branch.
    const double G5 = relaxed_shear_modulus(e, F, q, r.bridges, p, *solver, 1e-5);
    const double G6 = relaxed_shear_modulus(e, F, q, r.bridges, p, *solver, 3e-6);
    INFO("relaxed second differences: h = 1e-5: " << G5 << ", h = 3e-6: " << G6);
    CHECK(G.front().value > 0);
    // Each relaxed energy carries round-off of about 16 eps times the sum of its terms' sizes (the dry energy and the
    // capillary energy, of opposite signs); the stencil (1, -2, 1) / (A h^2) multiplies it by 4 / (A h^2).
    EnergyEval ev;
    e.evaluate(q, F, Eigen::Matrix2d::Zero(), 0, ev);
    const double dry = ev.energy, cap = W.value(q) - dry;
    const double noise = 16 * std::numeric_limits<double>::epsilon() * (std::abs(dry) + std::abs(cap));
    INFO("energy round-off " << noise << " (dry " << dry << ", capillary " << cap << ")");
    CHECK(G5 == Approx(G.front().value).epsilon(1e-5).margin(4 * noise / (A * 1e-10)));
    CHECK(G6 == Approx(G.front().value).epsilon(3e-5).margin(4 * noise / (A * 9e-12)));
}
