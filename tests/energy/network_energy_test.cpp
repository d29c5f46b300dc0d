#include <catch2/catch.hpp>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "fd.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/random.hpp"

using namespace fibernet;

namespace {
Model small_model(bool periodic, Scheme scheme, double a = 10, std::uint64_t seed = 3) {
    MikadoParams p;
    p.L = 3.2, p.q = 3, p.pl = 0.7, p.seed = seed, p.periodic = periodic;
    DiscretizationParams d;
    d.scheme = scheme, d.n_seg = 4, d.h = 3.0, d.aspect_ratio = a;
    return discretize(generate_mikado(p), d);
}

Eigen::VectorXd perturbed(const NetworkEnergy& e, double amp, std::uint64_t seed) {
    Rng rng(seed);
    Eigen::VectorXd q = e.dofs(e.model().x);
    for (int i = 0; i < q.size(); ++i) q[i] += amp * (2 * rng.uniform() - 1);
    return q;
}

// The comoving strain derivatives (kComoving): along the affine path of every node, positions (I + t V) x with
// V = dF F^-1 and F + t dF, they are the same algebra as the fixed-q ones with v = V x: E_tt + 2 v.b + v.H v and
// b + H v (to the rounding of those sums), and central differences of E, of dE/dt and of the gradient along that
// path (NetworkEnergy::affine_map). ev, Hfull: the fixed-q evaluation at (q, F) with its dense Hessian.
void check_comoving(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                    const Eigen::Matrix2d& dF, const EnergyEval& ev, const Eigen::MatrixXd& Hfull) {
    EnergyEval c;
    e.evaluate(q, F, dF, kStrain | kComoving, c);
    const Eigen::Matrix2d V = dF * F.inverse();
    const Eigen::VectorXd x = e.positions(q, F);
    Eigen::VectorXd v(e.num_dofs());
    for (int i = 0; i < e.model().num_nodes(); ++i)
        if (e.dof(i, 0) >= 0) v.segment<2>(e.dof(i, 0)) = V * x.segment<2>(2 * i);
    const Eigen::VectorXd Hv = Hfull * v;
    const double Ett = ev.d2E_dt2 + 2 * v.dot(ev.d2E_dqdt) + v.dot(Hv);
    const double size = std::abs(ev.d2E_dt2) + 2 * v.cwiseProduct(ev.d2E_dqdt).cwiseAbs().sum() +
                        v.cwiseProduct(Hv).cwiseAbs().sum();
    INFO("comoving E_tt " << c.d2E_dt2 << " vs E_tt + 2 v.b + v.H v " << Ett << " (terms of size " << size << ")");
    CHECK(std::abs(c.d2E_dt2 - Ett) <= 1e-12 * size);
    CHECK(c.d2E_dt2_size >= std::abs(c.d2E_dt2));
    CHECK(fdtest::rel_err(c.d2E_dqdt, Eigen::VectorXd(ev.d2E_dqdt + Hv), 1e-8) < 1e-9);
    auto along = [&](double t, unsigned want) {
        EnergyEval r;
        const Eigen::Matrix2d Ft = F + t * dF;
        e.evaluate(e.affine_map(q, F, Ft), Ft, dF, want, r);
        return r;
    };
    auto richardson = [](auto d) -> decltype(d(1.0)) { return (4 * d(0.5) - d(1.0)) / 3; };
    // A larger step than at fixed q: along this path every edge scales by (I + t V), so a step changes no element
    // by more than ht relative, while positions of size L round to eps L, which on a segment compressed to 1e-3 of
    // its length is 7e-12 relative (3.6e-6 in the gradient's difference at ht = 1e-6).
    const double ht = 1e-4;
    const double Et_fd = richardson([&](double s) {
        return (along(s * ht, kValue).energy - along(-s * ht, kValue).energy) / (2 * s * ht);
    });
    const double Ett_fd = richardson([&](double s) {
        return (along(s * ht, kStrain | kComoving).dE_dt - along(-s * ht, kStrain | kComoving).dE_dt) / (2 * s * ht);
    });
    const Eigen::VectorXd B_fd = richardson([&](double s) {
        return Eigen::VectorXd((along(s * ht, kGradient).gradient - along(-s * ht, kGradient).gradient) / (2 * s * ht));
    });
    CHECK(c.dE_dt == Approx(Et_fd).epsilon(1e-6).margin(1e-8 * std::abs(c.d2E_dt2)));
    CHECK(c.d2E_dt2 == Approx(Ett_fd).epsilon(1e-6));
    CHECK(fdtest::rel_err(c.d2E_dqdt, B_fd) < 1e-6);
}

// Checks gradient, Hessian and the three strain derivatives of E(q, F + t dF) against central differences, and the
// comoving ones (check_comoving).
void check_all_derivatives(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                           const Eigen::Matrix2d& dF) {
    EnergyEval ev;
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    e.evaluate(q, F, dF, kGradient | kHessian | kStrain, ev, &H);
    const Eigen::MatrixXd Hu(H);
    const Eigen::MatrixXd Hfull = Eigen::MatrixXd(Hu.selfadjointView<Eigen::Upper>());
    auto val = [&](const Eigen::VectorXd& v) {
        EnergyEval t;
        e.evaluate(v, F, dF, kValue, t);
        return t.energy;
    };
    auto grad = [&](const Eigen::VectorXd& v) {
        EnergyEval t;
        e.evaluate(v, F, dF, kGradient, t);
        return t.gradient;
    };
    const double h = 1e-6;
    CHECK(fdtest::rel_err(ev.gradient, fdtest::fd_gradient(val, q, h)) < 1e-6);
    CHECK(fdtest::rel_err(Hfull, fdtest::fd_jacobian(grad, q, h)) < 1e-6);
    // Strain: t enters through F(t) = F + t dF (box vectors and clamped nodes).
    auto at_t = [&](double t, unsigned want) {
        EnergyEval r;
        e.evaluate(q, F + t * dF, dF, want, r);
        return r;
    };
    // Central differences at ht and ht / 2, Richardson-extrapolated (error O(ht^4)): on the softcore branch a strain
    // step moves a segment's ends by about L ht, a large fraction of a segment compressed to 1 % of its length, and
    // the plain central difference is off by 1e-6 there (by 1e-4 at 0.1 %).
    auto richardson = [](auto d) -> decltype(d(1.0)) { return (4 * d(0.5) - d(1.0)) / 3; };  // evaluated, not an expression
    const double ht = 1e-6;
    const double Et_fd = richardson([&](double s) {
        return (at_t(s * ht, kValue).energy - at_t(-s * ht, kValue).energy) / (2 * s * ht);
    });
    const double Ett_fd = richardson([&](double s) {
        return (at_t(s * ht, kStrain).dE_dt - at_t(-s * ht, kStrain).dE_dt) / (2 * s * ht);
    });
    const Eigen::VectorXd Ext_fd = richardson([&](double s) {
        return Eigen::VectorXd((at_t(s * ht, kGradient).gradient - at_t(-s * ht, kGradient).gradient) / (2 * s * ht));
    });
    CHECK(ev.dE_dt == Approx(Et_fd).epsilon(1e-6).margin(1e-8 * std::abs(ev.d2E_dt2)));
    CHECK(ev.d2E_dt2 == Approx(Ett_fd).epsilon(1e-6));
    CHECK(fdtest::rel_err(ev.d2E_dqdt, Ext_fd) < 1e-6);
    check_comoving(e, q, F, dF, ev, Hfull);
}
}  // namespace

TEST_CASE("network energy: zero in the rest state", "[energy]") {
    for (Scheme s : {Scheme::Seed, Scheme::Even}) {
        Model m = small_model(true, s);
        NetworkEnergy e(m);
        EnergyEval ev;
        e.evaluate(e.dofs(m.x), Eigen::Matrix2d::Identity(), strain_direction(StrainKind::Shear), kGradient | kStrain, ev);
        // Round-off only: cos phi of collinear segments is 1 to within 1e-16.
        CHECK(std::abs(ev.energy) < 1e-12);
        CHECK(ev.gradient.cwiseAbs().maxCoeff() < 1e-9);
        CHECK(std::abs(ev.dE_dt) < 1e-9);
    }
}

TEST_CASE("network energy: derivatives match finite differences in a sheared periodic box", "[energy][gradient][hessian]") {
    for (Scheme s : {Scheme::Seed, Scheme::Even}) {
        Model m = small_model(true, s);
        // The test is only meaningful if segments and hinges cross the periodic boundary.
        int crossing = 0;
        for (const auto& seg : m.segments) crossing += seg.shift != Eigen::Vector2i::Zero();
        REQUIRE(crossing > 0);
        NetworkEnergy e(m);
        const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.3);
        INFO("scheme " << to_string(s));
        check_all_derivatives(e, perturbed(e, 0.05, 11), F, strain_direction(StrainKind::Shear));
        check_all_derivatives(e, perturbed(e, 0.05, 12), F, strain_direction(StrainKind::UniaxialX));
        check_all_derivatives(e, perturbed(e, 0.05, 13), F, strain_direction(StrainKind::Isotropic));
    }
}

TEST_CASE("network energy: derivatives at large bending angles", "[energy][gradient][hessian]") {
    Model m = small_model(true, Scheme::Even, 1.0);
    NetworkEnergy e(m);
    // Large random moves of nodes spaced ~1 apart give hinge angles up to ~pi; the softcore keeps E finite.
    const Eigen::VectorXd q = perturbed(e, 0.45, 21);
    check_all_derivatives(e, q, deformation(StrainKind::Shear, -0.2), strain_direction(StrainKind::Shear));
}

TEST_CASE("network energy: derivatives on the softcore branch", "[energy][gradient][hessian]") {
    Model m = small_model(true, Scheme::Even);
    NetworkEnergy e(m);
    const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.1);
    Eigen::VectorXd x = e.positions(perturbed(e, 0.01, 31), F);
    // Compress some segments to eps = -0.97 and -0.99 (below eps* = -0.95): move node j towards node i.
    int compressed = 0;
    for (size_t k = 0; k < m.segments.size() && compressed < 4; k += 7) {
        const Segment& s = m.segments[k];
        const Eigen::Vector2d d = x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i) + F * m.box.B0() * s.shift.cast<double>();
        const double target = (compressed % 2 ? 0.03 : 0.01) * s.l0;
        x.segment<2>(2 * s.j) -= d - target * d.normalized();
        ++compressed;
    }
    const Eigen::VectorXd q = e.dofs(x);
    EnergyEval ev;
    e.evaluate(q, F, F, kValue, ev);
    REQUIRE(std::isfinite(ev.energy));
    check_all_derivatives(e, q, F, strain_direction(StrainKind::Shear));
}

TEST_CASE("network energy: softcore segments and large-angle hinges across the box edge, strain derivatives",
          "[energy][gradient][hessian]") {
    // Strain enters an element of a periodic box only through its periodic shifts (clamps aside): the regimes are
    // placed on elements that cross the box edge, and asserted, so the strain checks do not compare 0 with 0.
    Model m = small_model(true, Scheme::Even);
    NetworkEnergy e(m);
    const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.1), B = F * m.box.B0();
    const Eigen::Vector2d zero(0, 0);
    auto seg_vec = [&](const Eigen::VectorXd& x, const Segment& s) {
        return Eigen::Vector2d(x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i) + B * s.shift.cast<double>());
    };
    SECTION("softcore: shifted segments compressed below eps* = -0.95") {
        Eigen::VectorXd x = e.positions(perturbed(e, 0.01, 33), F);
        std::vector<int> picked;
        for (size_t k = 0; k < m.segments.size() && picked.size() < 3; ++k) {
            const Segment& s = m.segments[k];
            if (s.shift == Eigen::Vector2i::Zero()) continue;
            bool shares = false;  // a node shared with an earlier pick would undo its compression
            for (int p : picked) shares = shares || s.i == m.segments[p].i || s.i == m.segments[p].j ||
                                          s.j == m.segments[p].i || s.j == m.segments[p].j;
            if (shares) continue;
            const Eigen::Vector2d d = seg_vec(x, s);
            const double eps_target[] = {-0.96, -0.99, -0.999};
            x.segment<2>(2 * s.j) -= d - (1 + eps_target[picked.size()]) * s.l0 * d.normalized();
            picked.push_back(static_cast<int>(k));
        }
        REQUIRE(picked.size() == 3);
        for (int k : picked) {
            const double eps = seg_vec(x, m.segments[k]).norm() / m.segments[k].l0 - 1;
            INFO("segment " << k << " eps " << eps);
            REQUIRE(eps < -0.95);
        }
        check_all_derivatives(e, e.dofs(x), F, strain_direction(StrainKind::Shear));
        Eigen::Matrix2d general;
        general << 0.3, -0.7, 0.4, 0.2;
        check_all_derivatives(e, e.dofs(x), F, general);
    }
    SECTION("hinges bent to 3 rad and to pi - 1e-3") {
        for (double phi : {3.0, M_PI - 1e-3}) {
            Eigen::VectorXd x = e.positions(perturbed(e, 0.01, 34), F);
            int bent = -1;
            for (size_t h = 0; h < m.hinges.size() && bent < 0; ++h)
                if (m.hinges[h].shift1 != Eigen::Vector2i::Zero() || m.hinges[h].shift2 != Eigen::Vector2i::Zero())
                    bent = static_cast<int>(h);
            REQUIRE(bent >= 0);
            const Hinge& hg = m.hinges[bent];
            // Turn d2 = x_k - x_j + B shift2 to the angle phi from d1, keeping its length.
            const Eigen::Vector2d d1 = x.segment<2>(2 * hg.j) - x.segment<2>(2 * hg.i) + B * hg.shift1.cast<double>();
            const Eigen::Vector2d d2 = x.segment<2>(2 * hg.k) - x.segment<2>(2 * hg.j) + B * hg.shift2.cast<double>();
            const Eigen::Vector2d u = Eigen::Rotation2Dd(phi).toRotationMatrix() * d1.normalized();
            x.segment<2>(2 * hg.k) = x.segment<2>(2 * hg.j) + d2.norm() * u - B * hg.shift2.cast<double>();
            const Eigen::Vector2d n2 = x.segment<2>(2 * hg.k) - x.segment<2>(2 * hg.j) + B * hg.shift2.cast<double>();
            const double angle = std::acos(std::clamp(d1.dot(n2) / (d1.norm() * n2.norm()), -1.0, 1.0));
            INFO("hinge " << bent << " bent to " << angle << " rad");
            REQUIRE(angle > 2.9);
            check_all_derivatives(e, e.dofs(x), F, strain_direction(StrainKind::Shear));
            check_all_derivatives(e, e.dofs(x), F, strain_direction(StrainKind::Isotropic));
        }
    }
}

TEST_CASE("network energy: open box with clamped nodes, strain moves the clamps", "[energy][gradient][hessian]") {
    Model m = small_model(false, Scheme::Seed);
    for (int i = 0; i < m.num_nodes(); i += 5) m.fixed[i] = 1;
    NetworkEnergy e(m);
    REQUIRE(e.num_dofs() < 2 * m.num_nodes());
    check_all_derivatives(e, perturbed(e, 0.05, 41), deformation(StrainKind::Shear, 0.05),
                          strain_direction(StrainKind::Shear));
}

TEST_CASE("network energy: invariant under rigid motions of an open network", "[energy]") {
    Model m = small_model(false, Scheme::Seed);
    NetworkEnergy e(m);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    const Eigen::VectorXd q = perturbed(e, 0.1, 51);
    EnergyEval ev;
    e.evaluate(q, I, I, kValue, ev);
    const double E0 = ev.energy;
    REQUIRE(E0 > 1e-3);
    const double th = 0.7;
    Eigen::Matrix2d R;
    R << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
    Eigen::VectorXd x = e.positions(q, I);
    for (int i = 0; i < m.num_nodes(); ++i) x.segment<2>(2 * i) = R * x.segment<2>(2 * i).eval() + Eigen::Vector2d(3.3, -1.7);
    e.evaluate(e.dofs(x), I, I, kValue, ev);
    CHECK(ev.energy == Approx(E0).epsilon(1e-10));
}

TEST_CASE("network energy: moving a node through a box vector with its image shifts adjusted changes nothing", "[energy]") {
    Model m = small_model(true, Scheme::Seed);
    const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.2);
    NetworkEnergy e0(m);
    const Eigen::VectorXd q = perturbed(e0, 0.05, 61);
    EnergyEval ev0;
    e0.evaluate(q, F, strain_direction(StrainKind::Shear), kGradient | kStrain, ev0);
    Eigen::VectorXd x = e0.positions(q, F);
    Model moved = m;
    const Eigen::Vector2i n(1, -1);
    for (int p = 0; p < m.num_nodes(); p += 3) {
        x.segment<2>(2 * p) += F * m.box.B0() * n.cast<double>();
        moved.x.segment<2>(2 * p) += m.box.B0() * n.cast<double>();
        for (auto& s : moved.segments) {
            if (s.i == p) s.shift += n;
            if (s.j == p) s.shift -= n;
        }
        for (auto& h : moved.hinges) {
            if (h.i == p) h.shift1 += n;
            if (h.j == p) h.shift1 -= n, h.shift2 += n;
            if (h.k == p) h.shift2 -= n;
        }
    }
    NetworkEnergy e1(moved);
    EnergyEval ev1;
    e1.evaluate(e1.dofs(x), F, strain_direction(StrainKind::Shear), kGradient | kStrain, ev1);
    CHECK(ev1.energy == Approx(ev0.energy).epsilon(1e-10));
    // The strain derivative at fixed positions depends on the image chosen for a node unless the force on it
    // vanishes: dE/dt changes by -g_p . (dF B0 n) for each moved node p (exact identity; zero at equilibrium).
    double expected = ev0.dE_dt;
    const Eigen::Vector2d c = strain_direction(StrainKind::Shear) * m.box.B0() * n.cast<double>();
    for (int p = 0; p < m.num_nodes(); p += 3)
        expected -= ev0.gradient.segment<2>(e0.dof(p, 0)).dot(c);
    CHECK(ev1.dE_dt == Approx(expected).epsilon(1e-8));
    CHECK((ev1.gradient - ev0.gradient).cwiseAbs().maxCoeff() < 1e-8 * ev0.gradient.cwiseAbs().maxCoeff());
}

TEST_CASE("network energy: per-element PSD projection gives a positive semidefinite Hessian", "[energy][hessian]") {
    Model m = small_model(true, Scheme::Even, 10, 5);
    NetworkEnergy e(m);
    const Eigen::VectorXd q = perturbed(e, 0.3, 71);
    EnergyEval ev;
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    e.evaluate(q, deformation(StrainKind::Shear, 0.2), Eigen::Matrix2d::Zero(), kHessian, ev, &H);
    Eigen::MatrixXd Hd = Eigen::MatrixXd(Eigen::MatrixXd(H).selfadjointView<Eigen::Upper>());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> exact(Hd);
    REQUIRE(exact.eigenvalues().minCoeff() < -1e-6);  // the exact Hessian of this state is indefinite
    e.evaluate(q, deformation(StrainKind::Shear, 0.2), Eigen::Matrix2d::Zero(), kHessian | kProjectPSD, ev, &H);
    Hd = Eigen::MatrixXd(Eigen::MatrixXd(H).selfadjointView<Eigen::Upper>());
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> proj(Hd);
    CHECK(proj.eigenvalues().minCoeff() > -1e-9 * proj.eigenvalues().maxCoeff());
}

// The energy keeps references: a temporary Model (or NetworkEnergy for the objectives) would dangle, and the
// library used to accept it silently (a segfault later). Compile-time checks: they fail to compile if the deleted
// overloads go.
static_assert(!std::is_constructible<NetworkEnergy, Model&&>::value, "NetworkEnergy from a temporary Model");
static_assert(std::is_constructible<NetworkEnergy, const Model&>::value, "NetworkEnergy from a Model");
static_assert(!std::is_constructible<StrainedEnergy, NetworkEnergy&&, const Eigen::Matrix2d&>::value,
              "StrainedEnergy from a temporary NetworkEnergy");

TEST_CASE("network energy: coordinates of the wrong size are refused", "[energy]") {
    // Eigen checks no sizes with NDEBUG: q of another model read past its end (NaN or a crash).
    const Model m = small_model(true, Scheme::Seed);
    const NetworkEnergy e(m);
    const Eigen::VectorXd q = e.dofs(m.x);
    const Eigen::VectorXd shorter = q.head(q.size() - 2);
    EnergyEval ev;
    CHECK_THROWS_WITH(e.evaluate(shorter, Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Zero(), kGradient, ev),
                      Catch::Contains("coordinates"));
    CHECK_THROWS(e.positions(shorter, Eigen::Matrix2d::Identity()));
    CHECK_NOTHROW(e.evaluate(q, Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Zero(), kGradient, ev));
}
