// The smooth wet energy (smooth_wet_energy.hpp): derivatives of the whole energy and of its capillary part against
// central differences (crossings near nodes, at fiber ends, across the periodic box edge, in a sheared box, contacts of
// aligned fibers, a tabulated law, fixed nodes) with the strain derivatives; beta = 0 bit for bit dry; the same on any
// thread count; energy constant as a straight fiber slides along itself or across a crossing, and continuous along a
// drag across nodes and off a fiber end; a bundle adheres with -beta per unit overlap; a Hessian that follows the
// pattern covers the pairs that came into range.
#include <catch2/catch.hpp>
#include <cmath>

#include "../energy/fd.hpp"
#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/parallel.hpp"
#include "fibernet/wet/smooth_wet_energy.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {

SmoothWetParams smooth(double beta, const CapillaryLaw& law = {}, int partners = 0) {
    SmoothWetParams p;
    p.pair.beta = beta, p.pair.law = law, p.bundle_partners = partners;
    return p;
}

// The whole energy and its capillary part (the dry part is much stiffer and would hide an error in it), and the strain
// derivatives along simple shear and a general direction. min_pairs: non-zero pairs the layout must have.
void check_derivatives(const Model& m, const Eigen::Matrix2d& F, double amp, std::uint64_t seed,
                       const CapillaryLaw& law, size_t min_pairs, bool strained = false, int partners = 0) {
    NetworkEnergy dry(m);
    Eigen::VectorXd q = perturb(dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F), amp, seed);
    const SmoothWetParams p = smooth(2.5, law, partners), p0 = smooth(0);
    SmoothWetEnergy W(dry, F, p, {}, q), D(dry, F, p0, {}, q);
    REQUIRE(W.bridges(q).size() >= min_pairs);
    if (partners > 0) {  // the cap must act here: some segment saturates
        SmoothWetEnergy U(dry, F, smooth(2.5, law), {}, q);
        REQUIRE(std::abs(W.value(q) - U.value(q)) > 1e-3);
    }
    const auto hessians = check_against_differences(W, D, q);
    const Eigen::MatrixXd& Hcap = hessians.second;
    CHECK(!W.pattern_stale());

    Eigen::Matrix2d shear = Eigen::Matrix2d::Zero(), general;
    shear(0, 1) = 1;
    general << 0.3, -0.7, 0.4, 0.2;
    for (const Eigen::Matrix2d& dF : {Eigen::Matrix2d(shear * F), general}) {
        auto at = [&](const SmoothWetParams& pp, double t) { return SmoothWetEnergy(dry, F + t * dF, pp, {}, q); };
        auto terms = [&](const SmoothWetParams& pp, double t) {
            EnergyEval ev;
            at(pp, t).strain_derivatives(q, dF, ev);
            return ev;
        };
        auto energy = [&](const SmoothWetParams& pp, double t) { return at(pp, t).value(q); };
        auto gradient = [&](const SmoothWetParams& pp, double t) {
            Eigen::VectorXd r;
            at(pp, t).gradient(q, r);
            return r;
        };
        const EnergyEval w = terms(p, 0), d = terms(p0, 0);
        const double ht = 1e-6;
        const double Et = (energy(p, ht) - energy(p, -ht)) / (2 * ht), Et0 = (energy(p0, ht) - energy(p0, -ht)) / (2 * ht);
        const Eigen::VectorXd b = (gradient(p, ht) - gradient(p, -ht)) / (2 * ht);
        const Eigen::VectorXd b0 = (gradient(p0, ht) - gradient(p0, -ht)) / (2 * ht);
        const double Ett = (terms(p, ht).dE_dt - terms(p, -ht).dE_dt) / (2 * ht);
        const double Ett0 = (terms(p0, ht).dE_dt - terms(p0, -ht).dE_dt) / (2 * ht);
        INFO("capillary dE/dt " << w.dE_dt - d.dE_dt << " (fd " << Et - Et0 << "), d2E/dt2 " << w.d2E_dt2 - d.d2E_dt2
                                << " (fd " << Ett - Ett0 << ")");
        CHECK(std::abs((w.dE_dt - d.dE_dt) - (Et - Et0)) <= 1e-6 * (1e-3 + std::abs(Et - Et0)));
        CHECK(std::abs((w.d2E_dt2 - d.d2E_dt2) - (Ett - Ett0)) <= 1e-5 * (1e-3 + std::abs(Ett - Ett0)));
        CHECK(fdtest::rel_err(w.d2E_dqdt - d.d2E_dqdt, b - b0, 1e-3) < 1e-5);
        // Comoving: E_tt + 2 v.b + v.H v and b + H v with v = dF F^-1 x (capillary part).
        const Eigen::Matrix2d V = dF * F.inverse();
        const Eigen::VectorXd x = dry.positions(q, F);
        Eigen::VectorXd v(dry.num_dofs());
        for (int i = 0; i < m.num_nodes(); ++i)
            if (dry.dof(i, 0) >= 0) v.segment<2>(dry.dof(i, 0)) = V * x.segment<2>(2 * i);
        EnergyEval cw, cd;
        W.strain_derivatives(q, dF, cw, true);
        D.strain_derivatives(q, dF, cd, true);
        const double a1 = w.d2E_dt2 - d.d2E_dt2, a2 = 2 * v.dot(w.d2E_dqdt - d.d2E_dqdt), a3 = v.dot(Hcap * v);
        const double Ecm = a1 + a2 + a3;
        // Two paths to one number: equal to round-off of the summands, which can cancel by orders of magnitude.
        CHECK(std::abs((cw.d2E_dt2 - cd.d2E_dt2) - Ecm) <=
              1e-9 * (1 + std::abs(a1) + std::abs(a2) + std::abs(a3)));
        CHECK(fdtest::rel_err(cw.d2E_dqdt - cd.d2E_dqdt, Eigen::VectorXd(w.d2E_dqdt - d.d2E_dqdt + Hcap * v), 1e-6) <
              1e-8);
        if (strained) CHECK(std::abs(w.d2E_dt2 - d.d2E_dt2) > 1e-4);
    }
}

std::vector<Line> moved_by(std::vector<Line> lines, double dx, double dy) {
    for (Line& l : lines) l.x += dx, l.y += dy;
    return lines;
}

}  // namespace

TEST_CASE("smooth wet energy: gradient, Hessian and strain derivatives match finite differences",
          "[wet][smooth][gradient][hessian]") {
    const CapillaryLaw def, tab = tabulated_law();
    Eigen::Matrix2d sheared;
    sheared << 1, 0.3, 0, 1.1;
    SECTION("crossing near a node of one fiber, and of both") {
        for (const double s_at : {0.45, 0.41}) {
            const std::vector<Line> lines = {{1.5, 1.5, 0, 1, 0.5}, {1.31, 1.5, 60, 1, s_at}};
            const Model m = model_of(network_of(lines, 3));
            check_derivatives(m, Eigen::Matrix2d::Identity(), 0.003, 11, def, 2);
            check_derivatives(m, Eigen::Matrix2d::Identity(), 0.003, 12, tab, 2);
            const Model e = model_of(network_of(moved_by(lines, -1.33, -1.49), 3));
            check_derivatives(e, sheared, 0.003, 13, def, 2, true);
        }
    }
    SECTION("crossing near a fiber end") {
        const std::vector<Line> lines = {{1.5, 1.5, 0, 1, 0.5}, {1.005, 1.5, 50, 1, 0.5}};
        check_derivatives(model_of(network_of(lines, 3)), Eigen::Matrix2d::Identity(), 0.002, 21, def, 1);
        check_derivatives(model_of(network_of(moved_by(lines, -1.03, -1.49), 3)), sheared, 0.002, 22, def, 1, true);
    }
    SECTION("aligned fibers in contact, through the angle blend and the distance cutoff") {
        // Fiber 2 at 3 deg and at 14 deg to fiber 1, 0.01 (one fiber diameter / 2) off it, wrapped over the box edge.
        for (const double deg : {3.0, 14.0}) {
            const std::vector<Line> lines = {{1.0, 1.5, 0, 1, 0.5}, {1.2, 1.51, deg, 1, 0.5}};
            check_derivatives(model_of(network_of(lines, 3)), Eigen::Matrix2d::Identity(), 0.004, 31, def, 3);
            check_derivatives(model_of(network_of(moved_by(lines, -1.0, -1.5), 3)), sheared, 0.004, 32, tab, 3, true);
        }
    }
    SECTION("stacks of aligned fibers under the partner cap (segments in the saturation blend)") {
        // Three fibers at 0, 3 and -2 deg within 0.01 of each other: the middle overlaps hold n ~ 2 partners, in the
        // blend of a cap of 2; two fibers under a cap of 1 (n ~ 1, in its blend).
        const std::vector<Line> three = {{1.0, 1.5, 0, 1, 0.5}, {1.1, 1.505, 3, 1, 0.5}, {1.2, 1.51, -2, 1, 0.5}};
        const std::vector<Line> two = {{1.0, 1.5, 0, 1, 0.5}, {1.2, 1.505, 4, 1, 0.5}};
        check_derivatives(model_of(network_of(three, 3)), Eigen::Matrix2d::Identity(), 0.004, 51, def, 6, false, 2);
        check_derivatives(model_of(network_of(moved_by(three, -1.0, -1.5), 3)), sheared, 0.004, 52, tab, 6, true, 2);
        check_derivatives(model_of(network_of(two, 3)), Eigen::Matrix2d::Identity(), 0.004, 53, def, 3, false, 1);
    }
    SECTION("a random Mikado network, seed scheme, fixed nodes in a sheared box") {
        check_derivatives(model_of(mikado(2.5, 4, 0.5, 7), 4), Eigen::Matrix2d::Identity(), 0.002, 41, def, 5);
        check_derivatives(clamped_network(), clamped_box(), 0.002, 42, def, 5);
    }
}

TEST_CASE("smooth wet energy: beta = 0 is the dry energy bit for bit", "[wet][smooth]") {
    const Model m = model_of(mikado(2.5, 4, 0.5, 3), 4);
    NetworkEnergy dry(m);
    const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.01, 5);
    SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(0), {}, q);
    StrainedEnergy S(dry, Eigen::Matrix2d::Identity());
    Eigen::VectorXd gw, gs;
    Eigen::SparseMatrix<double> Hw = W.hessian_pattern(), Hs = S.hessian_pattern();
    const double ew = W.hessian(q, gw, Hw, false), es = S.hessian(q, gs, Hs, false);
    CHECK(ew == es);
    CHECK((gw.array() == gs.array()).all());
    REQUIRE(Hw.nonZeros() == Hs.nonZeros());
    CHECK(std::equal(Hw.valuePtr(), Hw.valuePtr() + Hw.nonZeros(), Hs.valuePtr()));
}

TEST_CASE("smooth wet energy: bit for bit the same on any number of threads", "[wet][smooth][parallel]") {
    const Model m = model_of(mikado(8, 10, 0.5, 4), 10);
    NetworkEnergy dry(m);
    const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.01, 9);
    for (const int partners : {0, 1}) {  // without and with the partner cap (a cap of 1 saturates many segments)
        SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(0.3, {}, partners), {}, q);
        REQUIRE(W.bridges(q).size() > 1000);
        INFO("partners " << partners);
        check_same_on_threads(W, q);
    }
}

TEST_CASE("smooth wet energy: no energy change as a straight fiber slides along itself, in a bundle or across a crossing",
          "[wet][smooth][physics]") {
    // Fiber 2 is moved rigidly along its own axis (its nodes only, so the dry energy stays zero). Across a crossing
    // at 50 deg, and lying 0.05 beside fiber 1 (a bundle): the capillary energy is constant while no end is near.
    for (const double deg : {50.0, 0.0}) {
        const double off = deg == 0 ? 0.005 : 0;
        const Model m = model_of(network_of({{1.5, 1.5, 0, 1, 0.5}, {1.5, 1.5 + off, deg, 0.6, 0.5}}, 3, true), 7);
        NetworkEnergy dry(m);
        const Eigen::VectorXd q0 = dry.dofs(m.x);
        const Eigen::Vector2d u(std::cos(deg * M_PI / 180), std::sin(deg * M_PI / 180));
        std::vector<double> E;
        for (double t = -0.15; t <= 0.15; t += 0.0123) {  // seed units: up to 1.5 segments of fiber 1 either way
            Eigen::VectorXd q = q0;
            for (int n : m.chains[1].nodes) q.segment<2>(dry.dof(n, 0)) += 10 * t * u;
            SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(0.4), {}, q);
            E.push_back(W.value(q));
        }
        INFO("angle " << deg);
        CHECK(E.front() < -0.1);
        for (double e : E) CHECK(e == Approx(E.front()).epsilon(1e-12));
    }
}

TEST_CASE("smooth wet energy: continuous along a drag across nodes and off a fiber end", "[wet][smooth][physics]") {
    // Fiber 2 (60 deg) dragged along x across all of fiber 1's nodes and off its end: energy and gradient change by
    // no more than their Lipschitz bound per step (no jump), and the energy ends at zero.
    const Model m = model_of(network_of({{1.5, 1.5, 0, 1, 0.5}, {1.2, 1.5, 60, 0.6, 0.5}}, 3), 5);
    NetworkEnergy dry(m);
    const Eigen::VectorXd q0 = dry.dofs(m.x);
    const double step = 0.002;  // seed units
    double E_prev = NAN, max_dE = 0;
    Eigen::VectorXd g_prev;
    double max_dg = 0;
    for (double t = 0; t <= 9.0; t += step) {
        Eigen::VectorXd q = q0;
        for (int n : m.chains[1].nodes) q[dry.dof(n, 0)] += t;
        SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(1.0), {}, q);
        Eigen::VectorXd g;
        const double E = W.gradient(q, g);
        if (!std::isnan(E_prev)) {
            max_dE = std::max(max_dE, std::abs(E - E_prev));
            max_dg = std::max(max_dg, (g - g_prev).lpNorm<Eigen::Infinity>());
        }
        E_prev = E, g_prev = g;
    }
    CHECK(E_prev == 0);
    // |dE/dx| <= beta l |dW/dx| ~ beta l / (2 eps / sin alpha) * 15/8: a jump of a bridge's worth (beta l ~ 2) fails.
    CHECK(max_dE < 0.1);
    CHECK(max_dg < 2.0);
}

TEST_CASE("smooth wet energy: a two-fiber bundle adheres with -beta per unit overlap", "[wet][smooth][physics]") {
    // Two parallel fibers 0.05 apart (within the contact distance 0.2), of different discretizations, overlapping by
    // 0.8 fiber lengths = 8 seed units.
    for (const int n_seg : {5, 10, 40}) {
        Network net = network_of({{1.0, 1.5, 0, 1, 0.5}, {1.2, 1.505, 0, 1, 0.5}}, 3);
        Model m = model_of(net, n_seg);
        NetworkEnergy dry(m);
        const Eigen::VectorXd q = dry.dofs(m.x);
        const double beta = 0.25;
        SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(beta), {}, q);
        const SmoothWetSplit s = W.split(q);
        INFO("n_seg " << n_seg << ": contact energy " << s.contact);
        CHECK(s.crossing == 0);
        CHECK(s.contact == Approx(-beta * 8).epsilon(0.05));
    }
}

TEST_CASE("smooth wet energy: the partner cap bounds a stack's adhesion and leaves a two-fiber bundle alone",
          "[wet][smooth][physics]") {
    // Four parallel fibers, 0.005 apart (all within the contact distance of each other), overlapping along their
    // whole length of 10 seed units: 6 adhering pairs without a cap (-60 beta); each segment has n = 3 partners, so a
    // cap of 2 gives -(beta / 2) 4 x 10 x S(3) = -40 beta, a cap of 6 (n below it) the pair sum.
    const double beta = 0.3;
    std::vector<Line> stack;
    for (int k = 0; k < 4; ++k) stack.push_back({1.5, 1.5 + 0.005 * k, 0, 1, 0.5});
    const Model m = model_of(network_of(stack, 3), 10);
    NetworkEnergy dry(m);
    const Eigen::VectorXd q = dry.dofs(m.x);
    auto contact = [&](int partners) {
        return SmoothWetEnergy(dry, Eigen::Matrix2d::Identity(), smooth(beta, {}, partners), {}, q).split(q).contact;
    };
    const double none = contact(0);
    CHECK(none == Approx(-60 * beta).epsilon(0.02));
    CHECK(contact(2) == Approx(-40 * beta).epsilon(0.02));
    CHECK(contact(6) == Approx(none).epsilon(1e-12));
    CHECK(SmoothWetEnergy(dry, Eigen::Matrix2d::Identity(), smooth(beta, {}, 2), {}, q).value(q) ==
          Approx(contact(2)).epsilon(1e-12));  // the value is the split's (no dry energy at rest)
    // Two of them: n = 1, below a cap of 2.
    const Model m2 = model_of(network_of({stack[0], stack[1]}, 3), 10);
    NetworkEnergy dry2(m2);
    const Eigen::VectorXd q2 = dry2.dofs(m2.x);
    const double two = SmoothWetEnergy(dry2, Eigen::Matrix2d::Identity(), smooth(beta), {}, q2).value(q2);
    CHECK(two == Approx(-10 * beta).epsilon(0.02));
    CHECK(SmoothWetEnergy(dry2, Eigen::Matrix2d::Identity(), smooth(beta, {}, 2), {}, q2).value(q2) ==
          Approx(two).epsilon(1e-12));
}

TEST_CASE("smooth wet energy: a Hessian that follows the pattern covers pairs that came into range",
          "[wet][smooth]") {
    // A stack of three fibers (in the partner cap's blend with a cap of 2), the third built a fiber length (10 seed
    // units) above the others (beyond the pattern distance and the skin) and then moved onto them: its new pairs lie outside the pattern of the
    // build. A fixed pattern leaves their blocks out and says so (pattern_stale); a followed one is rebuilt at the
    // Hessian that needs it (pattern_version changes), which then equals that of an energy built at the new state.
    const std::vector<Line> three = {{1.0, 1.5, 0, 1, 0.5}, {1.1, 1.505, 3, 1, 0.5}, {1.2, 2.51, -2, 1, 0.5}};
    const Model m = model_of(network_of(three, 3));
    NetworkEnergy dry(m);
    const Eigen::VectorXd q0 = perturb(dry.dofs(m.x), 0.004, 61);
    Eigen::VectorXd q1 = q0;
    for (int n : m.chains[2].nodes)
        if (dry.dof(n, 1) >= 0) q1[dry.dof(n, 1)] -= 10.0;
    for (const int partners : {0, 2}) {
        INFO("partners " << partners);
        const SmoothWetParams p = smooth(2.5, {}, partners);
        SmoothWetEnergy fresh(dry, Eigen::Matrix2d::Identity(), p, {}, q1);
        REQUIRE(fresh.bridges(q1).size() > fresh.bridges(q0).size());
        Eigen::VectorXd g1, g;
        Eigen::SparseMatrix<double> H1 = fresh.hessian_pattern();
        fresh.hessian(q1, g1, H1, false);
        REQUIRE(!fresh.pattern_stale());
        {  // fixed
            SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), p, {}, q0);
            Eigen::SparseMatrix<double> H = W.hessian_pattern();
            W.hessian(q1, g, H, false);
            CHECK(W.pattern_version() == 0);
            CHECK(W.pattern_stale());
            CHECK((g - g1).lpNorm<Eigen::Infinity>() <= 1e-12 * (1 + g1.lpNorm<Eigen::Infinity>()));
        }
        SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), p, {}, q0);
        W.follow_pattern(true);
        const long v0 = W.pattern_version();
        CHECK(v0 != 0);
        Eigen::SparseMatrix<double> H = W.hessian_pattern();
        W.hessian(q1, g, H, false);
        CHECK(W.pattern_version() != v0);
        CHECK(!W.pattern_stale());
        REQUIRE(same_pattern(H, W.hessian_pattern()));
        REQUIRE(same_pattern(H, H1));
        const double scale = 1 + Eigen::Map<const Eigen::VectorXd>(H1.valuePtr(), H1.nonZeros()).lpNorm<Eigen::Infinity>();
        CHECK((Eigen::Map<const Eigen::VectorXd>(H.valuePtr(), H.nonZeros()) -
               Eigen::Map<const Eigen::VectorXd>(H1.valuePtr(), H1.nonZeros()))
                  .lpNorm<Eigen::Infinity>() <= 1e-12 * scale);
        CHECK((g - g1).lpNorm<Eigen::Infinity>() <= 1e-12 * (1 + g1.lpNorm<Eigen::Infinity>()));
        // At the same state again: the pattern stays.
        const long v1 = W.pattern_version();
        W.hessian(q1, g, H, false);
        CHECK(W.pattern_version() == v1);
    }
}
