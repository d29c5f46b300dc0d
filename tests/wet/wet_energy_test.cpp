// Derivatives of the wet energy (dry + blended bridges) against central differences, on hand-made crossings placed
// inside and outside the blend zones, at fiber ends, across periodic boundaries and in a sheared box.
#include <catch2/catch.hpp>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "../energy/fd.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/util/parallel.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {
// strained: the layout puts the bridges' elements across the box edge, so their strain terms must not vanish (else
// the strain checks below compare 0 with 0).
void check_derivatives(const Model& m, const Eigen::Matrix2d& F, double amp, std::uint64_t seed, const CapillaryLaw& law,
                       int min_bridges, bool strained = false) {
    NetworkEnergy dry(m);
    const Eigen::Matrix2d B = F * m.box.B0();
    Eigen::VectorXd q = dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F);
    q = perturb(q, amp, seed);
    WettingRule all;
    // Network crossings need the network; here every intersecting segment pair gets a bridge.
    std::vector<Bridge> bridges = segment_crossings(m, dry.positions(q, F), B);
    REQUIRE(static_cast<int>(bridges.size()) >= min_bridges);
    WetParams p;
    p.beta = 2.5, p.law = law;
    WetEnergy W(dry, F, bridges, p);
    WetParams p0 = p;
    p0.beta = 0;
    WetEnergy D(dry, F, bridges, p0);
    const auto hessians = check_against_differences(W, D, q);
    const Eigen::MatrixXd &Hf = hessians.first, &Hcap = hessians.second;

    // Strain derivatives at fixed q along F + t dF (WetEnergy::strain_derivatives, for the wet linear moduli): dE/dt
    // and d2E/dq dt against central differences in t of the energy and its gradient, d2E/dt2 against those of dE/dt;
    // the whole energy and the bridges' part alone. Simple shear of the current box and a general direction.
    Eigen::Matrix2d shear = Eigen::Matrix2d::Zero(), general;
    shear(0, 1) = 1;
    general << 0.3, -0.7, 0.4, 0.2;
    for (const Eigen::Matrix2d& dF : {Eigen::Matrix2d(shear * F), general}) {
        auto terms = [&](const WetParams& pp, double t) {
            EnergyEval ev;
            WetEnergy(dry, F + t * dF, bridges, pp).strain_derivatives(q, dF, ev);
            return ev;
        };
        auto energy = [&](const WetParams& pp, double t) { return WetEnergy(dry, F + t * dF, bridges, pp).value(q); };
        auto gradient = [&](const WetParams& pp, double t) {
            Eigen::VectorXd r;
            WetEnergy(dry, F + t * dF, bridges, pp).gradient(q, r);
            return r;
        };
        const EnergyEval w = terms(p, 0), d = terms(p0, 0);
        const double ht = 1e-6;
        const double Et_fd = (energy(p, ht) - energy(p, -ht)) / (2 * ht), Et0_fd = (energy(p0, ht) - energy(p0, -ht)) / (2 * ht);
        const Eigen::VectorXd b_fd = (gradient(p, ht) - gradient(p, -ht)) / (2 * ht);
        const Eigen::VectorXd b0_fd = (gradient(p0, ht) - gradient(p0, -ht)) / (2 * ht);
        const double Ett_fd = (terms(p, ht).dE_dt - terms(p, -ht).dE_dt) / (2 * ht);
        const double Ett0_fd = (terms(p0, ht).dE_dt - terms(p0, -ht).dE_dt) / (2 * ht);
        INFO("dF = " << dF.format(Eigen::IOFormat(4)) << ": dE/dt " << w.dE_dt << " (fd " << Et_fd << "), bridges' "
                     << w.dE_dt - d.dE_dt << " (fd " << Et_fd - Et0_fd << "); d2E/dt2 " << w.d2E_dt2 << " (fd " << Ett_fd
                     << "), bridges' " << w.d2E_dt2 - d.d2E_dt2 << " (fd " << Ett_fd - Ett0_fd << ")");
        CHECK(std::abs((w.dE_dt - d.dE_dt) - (Et_fd - Et0_fd)) <= 1e-6 * (1e-3 + std::abs(Et_fd - Et0_fd)));
        CHECK(std::abs(w.dE_dt - Et_fd) <= 1e-6 * (1e-3 + std::abs(Et_fd)));
        CHECK(std::abs((w.d2E_dt2 - d.d2E_dt2) - (Ett_fd - Ett0_fd)) <= 1e-5 * (1e-3 + std::abs(Ett_fd - Ett0_fd)));
        CHECK(std::abs(w.d2E_dt2 - Ett_fd) <= 1e-5 * (1e-3 + std::abs(Ett_fd)));
        CHECK(fdtest::rel_err(w.d2E_dqdt - d.d2E_dqdt, b_fd - b0_fd, 1e-3) < 1e-5);
        CHECK(fdtest::rel_err(w.d2E_dqdt, b_fd) < 1e-6);
        // Comoving (every node on the affine path, for the wet moduli): the same algebra with v = dF F^-1 x,
        // E_tt + 2 v.b + v.H v and b + H v, the bridges' part alone too (its terms' rounding is far below 1e-10).
        const Eigen::Matrix2d V = dF * F.inverse();
        const Eigen::VectorXd x = dry.positions(q, F);
        Eigen::VectorXd v(dry.num_dofs());
        for (int i = 0; i < m.num_nodes(); ++i)
            if (dry.dof(i, 0) >= 0) v.segment<2>(dry.dof(i, 0)) = V * x.segment<2>(2 * i);
        for (const bool whole : {true, false}) {
            EnergyEval cw, cd;
            W.strain_derivatives(q, dF, cw, true);
            D.strain_derivatives(q, dF, cd, true);
            const Eigen::MatrixXd& Hm = whole ? Hf : Hcap;
            const double Ett = whole ? w.d2E_dt2 + 2 * v.dot(w.d2E_dqdt) + v.dot(Hm * v)
                                     : (w.d2E_dt2 - d.d2E_dt2) + 2 * v.dot(w.d2E_dqdt - d.d2E_dqdt) + v.dot(Hm * v);
            const double got = whole ? cw.d2E_dt2 : cw.d2E_dt2 - cd.d2E_dt2;
            const Eigen::VectorXd Bv = whole ? Eigen::VectorXd(w.d2E_dqdt + Hm * v)
                                             : Eigen::VectorXd(w.d2E_dqdt - d.d2E_dqdt + Hm * v);
            const Eigen::VectorXd Bgot = whole ? cw.d2E_dqdt : Eigen::VectorXd(cw.d2E_dqdt - cd.d2E_dqdt);
            INFO((whole ? "whole" : "bridges") << ": comoving E_tt " << got << " vs " << Ett);
            CHECK(std::abs(got - Ett) <= 1e-9 * (1 + std::abs(Ett)));
            CHECK(fdtest::rel_err(Bgot, Bv, 1e-6) < 1e-8);
            if (strained && !whole) CHECK(std::abs(got) > 1e-4);
        }
        if (strained) {
            CHECK(std::abs(w.dE_dt - d.dE_dt) > 1e-4);
            CHECK(std::abs(w.d2E_dt2 - d.d2E_dt2) > 1e-4);
            CHECK((w.d2E_dqdt - d.d2E_dqdt).norm() > 1e-4);
        }
    }
}

// The layout moved by (dx, dy): in a periodic box, by about -1.33 the home segments of the crossings near x = 1.31
// straddle the box edge, so that their bridges' elements hold periodic shifts and F enters them (strain derivatives
// of an element without shifts or fixed nodes vanish: a check there compares 0 with 0).
std::vector<Line> moved_by(std::vector<Line> lines, double dx, double dy) {
    for (Line& l : lines) l.x += dx, l.y += dy;
    return lines;
}

}  // namespace

TEST_CASE("wet energy: gradient and Hessian match finite differences", "[wet][gradient][hessian]") {
    const CapillaryLaw def, tab = tabulated_law();
    // Fiber 1 along x with nodes every 0.1; fiber 2 crosses it 0.01 (blend zone: |z| < 0.025) past a node.
    Eigen::Matrix2d sheared;
    sheared << 1, 0.3, 0, 1.1;
    SECTION("blend zone on one fiber") {
        const std::vector<Line> lines = {{1.5, 1.5, 0, 1, 0.5}, {1.31, 1.5, 60, 1, 0.45}};
        const Model m = model_of(network_of(lines, 3));
        for (int s = 0; s < 3; ++s) check_derivatives(m, Eigen::Matrix2d::Identity(), 0.003, 11 + s, def, 1);
        check_derivatives(m, Eigen::Matrix2d::Identity(), 0.003, 21, tab, 1);
        // On the box edge, sheared: the blend zone's strain derivatives.
        const Model e = model_of(network_of(moved_by(lines, -1.33, -1.49), 3));
        check_derivatives(e, sheared, 0.003, 22, def, 1, true);
        check_derivatives(e, sheared, 0.003, 23, tab, 1, true);
    }
    SECTION("blend zones on both fibers") {
        const std::vector<Line> lines = {{1.5, 1.5, 0, 1, 0.5}, {1.31, 1.5, 70, 1, 0.41}};
        const Model m = model_of(network_of(lines, 3));
        for (int s = 0; s < 3; ++s) check_derivatives(m, Eigen::Matrix2d::Identity(), 0.003, 31 + s, def, 1);
        const Model e = model_of(network_of(moved_by(lines, -1.33, -1.49), 3));
        check_derivatives(e, sheared, 0.003, 34, def, 1, true);
        check_derivatives(e, sheared, 0.003, 35, tab, 1, true);
    }
    SECTION("crossing near a fiber end (missing neighbour)") {
        const std::vector<Line> lines = {{1.5, 1.5, 0, 1, 0.5}, {1.005, 1.5, 50, 1, 0.5}};
        const Model m = model_of(network_of(lines, 3));
        for (int s = 0; s < 3; ++s) check_derivatives(m, Eigen::Matrix2d::Identity(), 0.002, 41 + s, def, 1);
        const Model e = model_of(network_of(moved_by(lines, -1.03, -1.49), 3));
        check_derivatives(e, sheared, 0.002, 44, def, 1, true);
    }
    SECTION("interior crossings, several fibers") {
        const Model m = model_of(network_of({{1.5, 1.5, 0, 1, 0.5}, {1.55, 1.5, 60, 1, 0.45}, {1.5, 1.55, 100, 1, 0.5}}, 3));
        check_derivatives(m, Eigen::Matrix2d::Identity(), 0.01, 51, def, 3);
        check_derivatives(m, Eigen::Matrix2d::Identity(), 0.01, 52, tab, 3);
    }
    SECTION("crossings across the periodic boundary, sheared box") {
        // Both crossings sit on the box edge x = 0 = L; fiber 1 wraps around it.
        const Model m = model_of(network_of({{0.02, 1.0, 10, 1, 0.5}, {0.01, 1.03, 80, 1, 0.5}}, 2));
        Eigen::Matrix2d F;
        F << 1, 0.3, 0, 1.1;
        check_derivatives(m, F, 0.003, 61, def, 1);
        check_derivatives(m, Eigen::Matrix2d::Identity(), 0.003, 62, tab, 1);
    }
    SECTION("a random Mikado network, seed scheme (short segments)") {
        const Network net = mikado(2.5, 4, 0.5, 7);
        const Model m = model_of(net, 4);
        check_derivatives(m, Eigen::Matrix2d::Identity(), 0.002, 71, def, 5);
    }
    SECTION("fixed nodes (clamps) in a sheared box") {
        // A fixed node sits at F x_ref: a bridge on it moves with F (its strain derivatives' fixed-node term).
        check_derivatives(clamped_network(), clamped_box(), 0.002, 81, def, 5);
    }
}

TEST_CASE("wet energy: beta = 0 is the dry energy bit for bit", "[wet]") {
    const Model m = model_of(mikado(2.5, 4, 0.5, 3), 4);
    NetworkEnergy dry(m);
    const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.01, 5);
    WetParams p;  // beta = 0
    WetEnergy W(dry, Eigen::Matrix2d::Identity(), segment_crossings(m, dry.positions(q, Eigen::Matrix2d::Identity()), m.box.B0()), p);
    REQUIRE(!W.bridges().empty());
    StrainedEnergy S(dry, Eigen::Matrix2d::Identity());
    Eigen::VectorXd gw, gs;
    Eigen::SparseMatrix<double> Hw = W.hessian_pattern(), Hs = S.hessian_pattern();
    const double ew = W.hessian(q, gw, Hw, false), es = S.hessian(q, gs, Hs, false);
    CHECK(ew == es);
    CHECK((gw.array() == gs.array()).all());
    REQUIRE(Hw.nonZeros() == Hs.nonZeros());
    CHECK(std::equal(Hw.valuePtr(), Hw.valuePtr() + Hw.nonZeros(), Hs.valuePtr()));
    CHECK(std::equal(Hw.innerIndexPtr(), Hw.innerIndexPtr() + Hw.nonZeros(), Hs.innerIndexPtr()));
}

TEST_CASE("wet energy: the projected Hessian is positive semidefinite", "[wet][hessian]") {
    // Crossings in and out of blend zones (both Hessian paths), bent by a perturbation.
    const Model m = model_of(network_of({{1.5, 1.5, 0, 1, 0.5}, {1.31, 1.5, 70, 1, 0.41}, {1.55, 1.5, 60, 1, 0.45},
                                         {1.5, 1.55, 100, 1, 0.5}}, 3));
    NetworkEnergy dry(m);
    const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.01, 81);
    WetParams p;
    p.beta = 5;
    WetEnergy W(dry, Eigen::Matrix2d::Identity(), segment_crossings(m, dry.positions(q, Eigen::Matrix2d::Identity()), m.box.B0()), p);
    REQUIRE(W.bridges().size() >= 4);
    Eigen::VectorXd g;
    Eigen::SparseMatrix<double> H = W.hessian_pattern();
    W.hessian(q, g, H, true);
    const Eigen::MatrixXd Hu(H);
    const Eigen::MatrixXd Hf = Eigen::MatrixXd(Hu.selfadjointView<Eigen::Upper>());
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Hf).eigenvalues();
    CHECK(ev.minCoeff() > -1e-9 * ev.maxCoeff());
    // Without projection the bridges make it indefinite here (so the check above can fail).
    W.hessian(q, g, H, false);
    const Eigen::MatrixXd Hu2(H);
    const Eigen::VectorXd ev2 =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Eigen::MatrixXd(Hu2.selfadjointView<Eigen::Upper>())).eigenvalues();
    CHECK(ev2.minCoeff() < -1e-6);
}

TEST_CASE("wet energy: bit for bit the same on any number of threads", "[wet][parallel]") {
    // Enough bridges (>= 1024) for the parallel element loop, and more than two chunks of 1000 (the dry terms run
    // beside the first).
    const Model m = model_of(mikado(12, 10, 0.5, 4), 10);
    NetworkEnergy dry(m);
    const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.01, 9);
    WetParams p;
    p.beta = 0.3;
    WetEnergy W(dry, Eigen::Matrix2d::Identity(), segment_crossings(m, dry.positions(q, Eigen::Matrix2d::Identity()), m.box.B0()), p);
    REQUIRE(W.bridges().size() > 2048);
    W.set_chunk(1000);
    check_same_on_threads(W, q);
}
