// Newton (issue 3): a clamped cantilever against Euler-Bernoulli beam theory, refinement, a large load against a
// fine discretization, and machine-precision equilibria with quadratic convergence on sheared periodic networks.
//
// Units (seed §4.1.2, DESIGN.md §2): a hinge stores (2/lt0)(1 - cos phi) ~ phi^2 / lt0. A continuous beam with
// bending stiffness kappa stores (kappa/2) c^2 ds; a hinge's curvature is c = phi / lt0 over the length lt0, so
// (kappa/2)(phi/lt0)^2 lt0 = kappa phi^2 / (2 lt0), and matching gives kappa = 2 in seed units (the bending energy
// of unit length at unit curvature, kappa/2, is 1). Euler-Bernoulli tip deflection: delta = P Lc^3 / (3 kappa).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {

// Energy minus the work of a vertical tip force P: E(q) - P y_tip.
class TipLoaded : public Objective {
public:
    TipLoaded(Objective& base, int tip_dof, double P) : b_(base), tip_(tip_dof), P_(P) {}
    int size() const override { return b_.size(); }
    double value(const Eigen::VectorXd& q) override { return b_.value(q) - P_ * q[tip_]; }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        const double f = b_.gradient(q, g);
        g[tip_] -= P_;
        return f - P_ * q[tip_];
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        const double f = b_.hessian(q, g, H, psd);
        g[tip_] -= P_;
        return f - P_ * q[tip_];
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return b_.hessian_pattern(); }

private:
    Objective& b_;
    int tip_;
    double P_;
};

struct Cantilever {
    double deflection = 0;   // tip y displacement
    double Lc = 0;           // free length (clamp node 1 to the tip)
    SolveResult result;
};

// One straight fiber (lf = 10 seed units) along x in an open box, n_seg equal segments (even scheme, h = lf/n),
// nodes 0 and 1 fixed (a clamp with zero slope), tip force P along y.
Cantilever cantilever(int n_seg, double P, double a = 10) {
    Network net;
    net.L = 2;
    net.periodic = false;
    Fiber f;
    f.start = {0.5, 1.0};
    f.theta = 0;
    f.length = 1;
    net.fibers.push_back(f);
    DiscretizationParams dp;
    dp.scheme = Scheme::Even;
    dp.h = 10.0 / n_seg;
    dp.aspect_ratio = a;
    Model m = discretize(net, dp);
    const auto& nodes = m.chains.at(0).nodes;
    REQUIRE(static_cast<int>(nodes.size()) == n_seg + 1);
    m.fixed.assign(m.num_nodes(), 0);
    m.fixed[nodes[0]] = m.fixed[nodes[1]] = 1;
    NetworkEnergy e(m);
    StrainedEnergy se(e, Eigen::Matrix2d::Identity());
    const int tip = e.dof(nodes.back(), 1);
    TipLoaded obj(se, tip, P);
    Eigen::VectorXd q = e.dofs(m.x);
    const double y0 = q[tip];
    SolverOptions opt;
    opt.max_iter = 200;
    NewtonSolver newton(opt);
    Cantilever c;
    c.result = newton.minimize(obj, q);
    c.deflection = q[tip] - y0;
    c.Lc = m.chains[0].s.back() - m.chains[0].s[1];
    return c;
}

}  // namespace

TEST_CASE("cantilever: small tip load against Euler-Bernoulli, first-order convergence", "[newton][cantilever]") {
    const double kappa = 2;  // seed units (header comment)
    const double P = 1e-6;   // delta / Lc ~ 1e-4: geometric nonlinearity ~1e-8, far below the discretization error
    std::vector<double> err;
    for (int n : {10, 20, 40, 80, 160}) {
        const Cantilever c = cantilever(n, P);
        REQUIRE(c.result.converged());
        CHECK(c.result.grad_max <= 1e-10);
        const double eb = P * std::pow(c.Lc, 3) / (3 * kappa);
        err.push_back(std::abs(c.deflection - eb) / eb);
        // The discrete sum over hinges is a left Riemann sum of int (Lc - s)^2 ds: relative error 3/(2n') + 1/(2n'^2)
        // with n' = n - 1 free segments, exactly, in the linear limit.
        const double np = n - 1;
        CHECK(err.back() == Approx(3 / (2 * np) + 1 / (2 * np * np)).epsilon(2e-3));
    }
    // Observed order log2(err_n / err_2n) -> 1.
    for (size_t i = 0; i + 1 < err.size(); ++i) {
        const double order = std::log2(err[i] / err[i + 1]);
        CHECK(order > 0.9);
        CHECK(order < 1.15);
    }
    CHECK(err.back() < 0.01);
}

TEST_CASE("cantilever: large load converges under refinement to a fine discretization", "[newton][cantilever]") {
    // P Lc^2 / kappa ~ 1: tip deflection ~ 0.3 Lc, far outside linear theory (the elastica regime).
    const double P = 0.02;
    const Cantilever fine = cantilever(640, P);
    REQUIRE(fine.result.converged());
    const double eb = P * std::pow(fine.Lc, 3) / 6;
    CHECK(fine.deflection < 0.95 * eb);  // the elastica is stiffer than linear theory at this load
    CHECK(fine.deflection / fine.Lc > 0.2);
    double prev = 1e300;
    for (int n : {20, 40, 80, 160}) {
        const Cantilever c = cantilever(n, P);
        REQUIRE(c.result.converged());
        // Different n clamp at a slightly different node: compare the deflection normalised by the free length.
        const double e = std::abs(c.deflection / c.Lc - fine.deflection / fine.Lc);
        CHECK(e < 0.6 * prev);  // falls roughly like 1/n
        prev = e;
    }
    CHECK(prev < 2e-3);
}

namespace {
struct NetCase {
    double L, q, pl, a;
    Scheme scheme;
    std::uint64_t seed;
    bool strict;  // 1e-10 is above this network's round-off floor
};

Model mikado_model(double L, double q, double pl, std::uint64_t seed, Scheme scheme, double a) {
    MikadoParams mp;
    mp.L = L, mp.q = q, mp.pl = pl, mp.seed = seed;
    DiscretizationParams dp;
    dp.scheme = scheme, dp.aspect_ratio = a;
    return discretize(generate_mikado(mp), dp);
}
}  // namespace

// max|g| <= 1e-10 is reachable only where the round-off floor of the coordinates is lower: a segment of length l
// gives a hinge stiffness ~ 1 / (lt0 l^2), so coordinates rounded to ulp(30) = 3.6e-15 leave forces of
// ~1e-10 for l ~ 5e-3 and ~1e-5 for l ~ 1e-4 (docs/moduli.md, "Round-off floor"). The strict cases reach 1e-10;
// the others must reach their floor, with Newton's stalled-at-floor test.
// With the shift's floor at either scale: the mean or the median diagonal (SolverOptions::median_floor).
TEST_CASE("newton: machine-precision equilibrium on sheared periodic networks, quadratic at the end", "[newton][network]") {
    const bool median_floor = GENERATE(false, true);
    CAPTURE(median_floor);
    const std::vector<NetCase> cases = {
        {3, 6, 1.0, 3, Scheme::Even, 7, true},    {3, 6, 1.0, 3, Scheme::Even, 8, true},
        {3, 6, 0.8, 1, Scheme::Even, 7, true},    {4, 6, 1.0, 3, Scheme::Even, 7, true},
        {3, 8, 1.0, 10, Scheme::Even, 7, false},  {3, 8, 1.0, 10, Scheme::Seed, 7, false},
        {4, 8, 0.7, 10, Scheme::Even, 7, false}};
    for (const auto& c : cases) {
        const Model m = mikado_model(c.L, c.q, c.pl, c.seed, c.scheme, c.a);
        NetworkEnergy e(m);
        const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.01);
        StrainedEnergy obj(e, F);
        Eigen::VectorXd q = e.affine_map(e.dofs(m.x), Eigen::Matrix2d::Identity(), F);
        SolverOptions opt;
        opt.max_iter = 300;
        opt.median_floor = median_floor;
        NewtonSolver newton(opt);
        const SolveResult r = newton.minimize(obj, q);
        INFO("L " << c.L << " q " << c.q << " pl " << c.pl << " a " << c.a << " scheme " << to_string(c.scheme)
                  << " seed " << c.seed << ": " << r.message << ", iterations " << r.iterations << ", max|g| "
                  << r.grad_max << ", floor bound " << r.grad_floor);
        REQUIRE(r.converged());
        if (c.strict) CHECK(r.grad_max <= 1e-10);
        else CHECK(r.grad_max <= std::max(1e-10, r.grad_floor));
        // Quadratic convergence, from the last two steps above the round-off plateau (1e-9 here) that start below
        // 1e-3: with r_k = g_{k+1} / g_k and C_k = g_{k+1} / g_k^2, a quadratic tail has r falling (superlinear)
        // and C bounded; a linear tail has r constant and C growing like 1 / g.
        const auto& h = newton.history();
        std::vector<size_t> ks;
        for (size_t k = 0; k + 1 < h.size(); ++k)
            if (h[k] <= 1e-3 && h[k + 1] >= 1e-9) ks.push_back(k);
        // Only where the plateau is below 1e-9 (the strict cases) is the tail long enough to read.
        if (c.strict) {
            REQUIRE(!ks.empty());
            const size_t k2 = ks.back();
            const double r2 = h[k2 + 1] / h[k2], C2 = r2 / h[k2];
            INFO("last step " << h[k2] << " -> " << h[k2 + 1]);
            CHECK(r2 < 0.05);
            CHECK(C2 < 1e5);
            if (ks.size() >= 2) {
                const size_t k1 = ks[ks.size() - 2];
                INFO("step before " << h[k1] << " -> " << h[k1 + 1]);
                CHECK(r2 < h[k1 + 1] / h[k1]);
            }
        }
    }
}

TEST_CASE("newton: projected Newton reaches the same equilibrium, quadratically once it is exact", "[newton][network]") {
    // A sheared Mikado network (compressed segments make element blocks indefinite, so the projected Hessian differs
    // from the exact one): projected Newton (SolverOptions::projected) must end where the default ladder does, and its
    // tail must be quadratic, which only the switch to the exact Hessian after full steps gives.
    const Model m = mikado_model(3, 8, 1.0, 10, Scheme::Even, 7);
    NetworkEnergy e(m);
    const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.05);
    StrainedEnergy obj(e, F);
    auto solve = [&](bool projected, std::vector<double>* history) {
        Eigen::VectorXd q = e.affine_map(e.dofs(m.x), Eigen::Matrix2d::Identity(), F);
        SolverOptions opt;
        opt.max_iter = 300;
        opt.projected = projected;
        NewtonSolver newton(opt);
        const SolveResult r = newton.minimize(obj, q);
        INFO((projected ? "projected: " : "default: ") << r.message << ", " << r.iterations << " iterations");
        REQUIRE(r.converged());
        CHECK(r.grad_max <= std::max(1e-10, r.grad_floor));
        if (history) *history = newton.history();
        return r.energy;
    };
    std::vector<double> h;
    const double E0 = solve(false, nullptr), E1 = solve(true, &h);
    INFO("E " << E0 << " and " << E1);
    REQUIRE(E0 > 1e-3);  // a rigid network: one equilibrium energy
    CHECK(std::abs(E1 - E0) <= 1e-9 * E0);
    // The step that took max|g| below 1e-6 cut it by more than 20x: quadratic, not the linear rate of a projected
    // Hessian (about 1/2 per step on this network with the switch to the exact Hessian disabled).
    size_t k = 0;
    while (k + 1 < h.size() && h[k + 1] >= 1e-6) ++k;
    REQUIRE(k + 1 < h.size());
    INFO("step " << h[k] << " -> " << h[k + 1]);
    CHECK(h[k + 1] / h[k] < 0.05);
    SolverOptions both;
    both.ldl = both.projected = true;
    CHECK_THROWS_WITH(NewtonSolver(both), Catch::Contains("ldl and projected"));
}

TEST_CASE("newton: empty objective, unknown solver, non-finite start", "[newton]") {
    Network net;
    net.L = 2;
    const Model m = discretize(net, DiscretizationParams{});
    NetworkEnergy e(m);
    StrainedEnergy obj(e, Eigen::Matrix2d::Identity());
    Eigen::VectorXd q(0);
    auto s = make_solver("newton", SolverOptions{});
    const SolveResult r = s->minimize(obj, q);
    CHECK(r.converged());
    CHECK(r.energy == 0);
    CHECK_THROWS_AS(make_solver("no-such-solver", SolverOptions{}), InputError);
}

TEST_CASE("newton: a collapsed start is reported as non-finite, not hidden", "[newton]") {
    const Cantilever ok = cantilever(10, 1e-6);
    REQUIRE(ok.result.converged());
    MikadoParams mp;
    mp.L = 3, mp.q = 8, mp.seed = 3;
    DiscretizationParams dp;
    dp.scheme = Scheme::Even;
    const Model m = discretize(generate_mikado(mp), dp);
    NetworkEnergy e(m);
    StrainedEnergy obj(e, Eigen::Matrix2d::Identity());
    // Every node at the origin: collapsed segments, energy +inf.
    Eigen::VectorXd q = e.dofs(Eigen::VectorXd::Zero(m.x.size()));
    NewtonSolver newton(SolverOptions{});
    const SolveResult r = newton.minimize(obj, q);
    CHECK(r.status == SolveStatus::NonFinite);
    CHECK_FALSE(r.converged());
}

namespace {
// Uncoupled double wells with stiff partners, f = sum_i x_i^4 / 4 - x_i^2 / 2 + 50 y_i^2: near x = 0 the exact Hessian
// is indefinite (f'' = 3 x^2 - 1 < 0) while its projection (x block clamped to 0) is singular. As in the networks,
// the negative curvature is soft against the stiff terms (the escalation stops at 0.2 mean |diag H|).
class DoubleWells : public fibernet::Objective {
public:
    explicit DoubleWells(int n) : n_(n), P_(2 * n, 2 * n) {
        std::vector<Eigen::Triplet<double>> t;
        for (int i = 0; i < 2 * n; ++i) t.emplace_back(i, i, 0.0);
        P_.setFromTriplets(t.begin(), t.end());
        P_.makeCompressed();
    }
    int size() const override { return 2 * n_; }
    double value(const Eigen::VectorXd& q) override {
        double f = 0;
        for (int i = 0; i < n_; ++i) f += std::pow(q[2 * i], 4) / 4 - q[2 * i] * q[2 * i] / 2 + 50 * q[2 * i + 1] * q[2 * i + 1];
        return f;
    }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        g.resize(2 * n_);
        for (int i = 0; i < n_; ++i) g[2 * i] = std::pow(q[2 * i], 3) - q[2 * i], g[2 * i + 1] = 100 * q[2 * i + 1];
        return value(q);
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool project) override {
        H = P_;
        for (int i = 0; i < n_; ++i) {
            const double hxx = 3 * q[2 * i] * q[2 * i] - 1;
            H.coeffRef(2 * i, 2 * i) = project ? std::max(hxx, 0.0) : hxx;
            H.coeffRef(2 * i + 1, 2 * i + 1) = 100;
        }
        return gradient(q, g);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return P_; }

private:
    int n_;
    Eigen::SparseMatrix<double> P_;
};
}  // namespace

TEST_CASE("newton: an indefinite Hessian gets an escalated shift on the exact Hessian before projection", "[newton]") {
    // Rung 0 raises the shift on the exact H (x4) until it factors (docs/moduli.md, "Newton ladder"); the projected
    // rung would drop the negative curvature that drives x away from the saddle at 0.
    DoubleWells f(3);
    Eigen::VectorXd q(6);
    q << 0.1, 0.5, -0.2, -0.3, 0.05, 1.0;
    fibernet::SolverOptions o;
    o.tol = 1e-12;
    fibernet::NewtonSolver newton(o);
    const fibernet::SolveResult r = newton.minimize(f, q);
    REQUIRE(r.converged());
    for (int i = 0; i < 3; ++i) {
        CHECK(std::abs(std::abs(q[2 * i]) - 1) < 1e-10);  // a minimum, not the saddle x = 0
        CHECK(std::abs(q[2 * i + 1]) < 1e-10);
    }
    REQUIRE(!newton.rungs().empty());
    CHECK(newton.rungs()[0] == 0);  // the first step, at an indefinite H, stayed on the exact Hessian
    int projected = 0;
    for (int rung : newton.rungs()) projected += rung >= 1;
    CHECK(projected == 0);
}

namespace {
// f = sum_i cosh(x_i - c_i) + (x_i - x_{i+1})^2 / 2: smooth and strictly convex, so Newton's steps from afar are full
// and well predicted.
class Convex : public Objective {
public:
    explicit Convex(int n) : n_(n) {
        Eigen::VectorXd g;
        hessian(Eigen::VectorXd::Zero(n), g, pattern_, false);
        pattern_.coeffs().setZero();
    }
    int size() const override { return n_; }
    double value(const Eigen::VectorXd& q) override {
        Eigen::VectorXd g;
        return gradient(q, g);
    }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        g.setZero(n_);
        double f = 0;
        for (int i = 0; i < n_; ++i) {
            f += std::cosh(q[i] - c(i)), g[i] += std::sinh(q[i] - c(i));
            if (i + 1 < n_) {
                const double d = q[i] - q[i + 1];
                f += 0.5 * d * d, g[i] += d, g[i + 1] -= d;
            }
        }
        return f;
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool) override {
        const double f = gradient(q, g);
        std::vector<Eigen::Triplet<double>> t;
        for (int i = 0; i < n_; ++i) {
            t.emplace_back(i, i, std::cosh(q[i] - c(i)) + (i > 0) + (i + 1 < n_));
            if (i + 1 < n_) t.emplace_back(i, i + 1, -1.0);
        }
        H.resize(n_, n_);
        H.setFromTriplets(t.begin(), t.end());
        H.makeCompressed();
        return f;
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return pattern_; }

private:
    static double c(int i) { return std::sin(1.0 + i); }
    int n_;
    Eigen::SparseMatrix<double> pattern_;  // upper triangle
};
}  // namespace

TEST_CASE("newton: warm_start resumes with the shift the previous solve adapted", "[newton]") {
    // Full, well-predicted steps cut the shift 10x each, so after a few iterations it is far below the cold start
    // (1e-8 x mean diag). A warm-started resume begins there; a cold one begins at 1e-8 x mean diag again.
    Convex obj(20);
    const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(20, 3.0);
    SolverOptions opt;
    opt.max_iter = 3;
    NewtonSolver cold(opt), warm(opt);
    Eigen::VectorXd qc = q0, qw = q0;
    REQUIRE(cold.minimize(obj, qc).status == SolveStatus::IterationLimit);
    REQUIRE(warm.minimize(obj, qw).status == SolveStatus::IterationLimit);
    REQUIRE(cold.rungs()[0] == 0);
    const double first = cold.shifts()[0];
    REQUIRE(cold.shifts().back() < 1e-1 * first);  // the shift fell while the steps were good
    REQUIRE((qc.array() == qw.array()).all());
    Eigen::VectorXd g;
    Eigen::SparseMatrix<double> H = obj.hessian_pattern();
    obj.hessian(qc, g, H, false);
    const double cold_start = 1e-8 * H.diagonal().cwiseAbs().mean();
    warm.options().warm_start = true;
    cold.minimize(obj, qc);
    warm.minimize(obj, qw);
    INFO("cold restart " << cold.shifts()[0] << ", warm " << warm.shifts()[0] << ", cold start " << cold_start);
    CHECK(cold.shifts()[0] == Approx(cold_start).epsilon(1e-12));
    CHECK(warm.shifts()[0] < 1e-2 * cold_start);
}

TEST_CASE("newton: with ldl, negative curvature is handled where it occurs", "[newton][ldl]") {
    // DoubleWells at x near the saddle: the x pivots are negative, the stiff y pivots positive. Flipping the negative
    // pivots (SolverOptions::ldl) leaves the y part an exact Newton step, so one iteration takes y to 0 (up to the
    // shift mu ~ 1e-8 mean diag); the escalated shift instead damps every y by lambda / (100 + lambda), lambda ~ 1.
    auto first_step = [](bool ldl) {
        DoubleWells f(3);
        Eigen::VectorXd q(6);
        q << 0.1, 0.5, -0.2, -0.3, 0.05, 1.0;
        fibernet::SolverOptions o;
        o.max_iter = 1;
        o.ldl = ldl;
        fibernet::NewtonSolver newton(o);
        const fibernet::SolveResult r = newton.minimize(f, q);
        CHECK(r.status == fibernet::SolveStatus::IterationLimit);
        if (ldl) CHECK(r.factorizations == 1);
        return q;
    };
    const Eigen::VectorXd q_ldl = first_step(true), q_shift = first_step(false);
    const double x0[3] = {0.1, -0.2, 0.05};
    for (int i = 0; i < 3; ++i) {
        CHECK(std::abs(q_ldl[2 * i + 1]) < 1e-6);
        CHECK(std::abs(q_shift[2 * i + 1]) > 1e-3);  // the escalated shift, for contrast
        // x moved away from the saddle at 0 by the flipped-curvature step (x - x^3) / (1 - 3 x^2), about x.
        CHECK(q_ldl[2 * i] == Approx(x0[i] + (x0[i] - std::pow(x0[i], 3)) / (1 - 3 * x0[i] * x0[i])).epsilon(1e-6));
    }
    // And it converges to the minima, quadratically at the end, with one factorization per iteration.
    DoubleWells f(3);
    Eigen::VectorXd q(6);
    q << 0.1, 0.5, -0.2, -0.3, 0.05, 1.0;
    fibernet::SolverOptions o;
    o.tol = 1e-12;
    o.ldl = true;
    fibernet::NewtonSolver newton(o);
    const fibernet::SolveResult r = newton.minimize(f, q);
    REQUIRE(r.converged());
    CHECK(r.factorizations == r.iterations);
    for (int i = 0; i < 3; ++i) {
        CHECK(std::abs(std::abs(q[2 * i]) - 1) < 1e-10);
        CHECK(std::abs(q[2 * i + 1]) < 1e-10);
    }
}

namespace {
// f = q^T H q / 2 + b^T q with H = [[-1, 0.5], [0.5, 2]] (indefinite), and +inf below the line y = x / 4 for x < 0 (a
// wall, like a collapsed segment). From q = 0 the LDL^T direction with flipped pivots is along (-2, -1), into the wall,
// as is steepest descent; the projected rung (Hp = diag(0.1, 2)) points along (-20, -1), which is open.
class Walled : public Objective {
public:
    Walled() : P_(2, 2) {
        P_.insert(0, 0) = 0, P_.insert(0, 1) = 0, P_.insert(1, 1) = 0;
        P_.makeCompressed();
    }
    int size() const override { return 2; }
    double value(const Eigen::VectorXd& q) override {
        if (q[0] < 0 && q[1] < q[0] / 4) return HUGE_VAL;
        return 0.5 * q.dot(H() * q) + q.sum();
    }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        g = H() * q + Eigen::Vector2d(1, 1);
        return value(q);
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool project) override {
        H = P_;
        H.coeffRef(0, 0) = project ? 0.1 : -1;
        H.coeffRef(0, 1) = project ? 0 : 0.5;
        H.coeffRef(1, 1) = 2;
        return gradient(q, g);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return P_; }

private:
    static Eigen::Matrix2d H() { return (Eigen::Matrix2d() << -1, 0.5, 0.5, 2).finished(); }
    Eigen::SparseMatrix<double> P_;
};
}  // namespace

TEST_CASE("newton: an LDL^T direction that fails its line search is retried with the shifted ladder", "[newton][ldl]") {
    Walled f;
    fibernet::SolverOptions o;
    o.max_iter = 1;
    o.ldl = true;
    fibernet::NewtonSolver newton(o);
    Eigen::VectorXd q = Eigen::Vector2d::Zero();
    const fibernet::SolveResult r = newton.minimize(f, q);
    INFO(r.message);
    CHECK(r.status == fibernet::SolveStatus::IterationLimit);  // a step was taken
    REQUIRE(newton.rungs().size() == 1);
    CHECK(newton.rungs()[0] == 1);  // by the projected rung, after the LDL^T direction hit the wall
    CHECK(r.ldl_retries == 1);
    CHECK(f.value(q) < 0);
}

namespace {
// f = sum_i (q_i - 1)^2 / 2 + k s(q_0) s(q_1), s(x) = max(0, x - 1/2)^3 (C2): the coupling of q_0 and q_1 is exactly
// zero until both pass 1/2. Its Hessian pattern follows the state (Objective::pattern_version), like the smooth wet
// energy's: the diagonal at first, the (0, 1) entry added by the first Hessian that needs it. With follow = false the
// pattern holds that entry from the start and is fixed.
class Coupling : public Objective {
public:
    Coupling(int n, bool follow) : n_(n), follow_(follow) { pattern_ = pattern(!follow); }
    int size() const override { return n_; }
    double value(const Eigen::VectorXd& q) override {
        Eigen::VectorXd g;
        return gradient(q, g);
    }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        g = q.array() - 1.0;
        const double s0 = s(q[0], 0), s1 = s(q[1], 0);
        g[0] += k * s(q[0], 1) * s1, g[1] += k * s0 * s(q[1], 1);
        return 0.5 * (q.array() - 1.0).square().sum() + k * s0 * s1;
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool) override {
        const double f = gradient(q, g);
        const double h01 = k * s(q[0], 1) * s(q[1], 1);
        if (follow_ && h01 != 0 && pattern_.nonZeros() == n_) pattern_ = pattern(true), ++version_;
        H = pattern_;
        for (int i = 0; i < n_; ++i) H.coeffRef(i, i) = 1;
        H.coeffRef(0, 0) += k * s(q[0], 2) * s(q[1], 0), H.coeffRef(1, 1) += k * s(q[0], 0) * s(q[1], 2);
        if (pattern_.nonZeros() > n_) H.coeffRef(0, 1) = h01;
        return f;
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return pattern_; }
    long pattern_version() const override { return follow_ ? version_ : 0; }

private:
    static constexpr double k = 40;
    // s and its first two derivatives
    static double s(double x, int d) {
        const double u = std::max(0.0, x - 0.5);
        return d == 0 ? u * u * u : d == 1 ? 3 * u * u : 6 * u;
    }
    Eigen::SparseMatrix<double> pattern(bool coupled) const {
        std::vector<Eigen::Triplet<double>> t;
        for (int i = 0; i < n_; ++i) t.emplace_back(i, i, 0.0);
        if (coupled) t.emplace_back(0, 1, 0.0);
        Eigen::SparseMatrix<double> P(n_, n_);
        P.setFromTriplets(t.begin(), t.end());
        P.makeCompressed();
        return P;
    }
    int n_;
    bool follow_;
    long version_ = 1;
    Eigen::SparseMatrix<double> pattern_;
};
}  // namespace

TEST_CASE("newton: follows a Hessian pattern that changes during the solve", "[newton]") {
    // From q = 0 the coupling comes into play on the way to the minimum: the first Hessian past 1/2 brings a new
    // pattern, which Newton's factorizations analyze anew (LL^T, and the LDL^T rung). The solve ends at the same
    // equilibrium as with the whole pattern fixed from the start. The same solver then solves a fresh objective, whose
    // first pattern is the one the last solve started with (not the one it ended with).
    for (const bool ldl : {false, true}) {
        INFO("ldl " << ldl);
        SolverOptions so;
        so.tol = 1e-12, so.ldl = ldl;
        NewtonSolver newton(so);
        REQUIRE(newton.capabilities().follows_pattern);
        Coupling followed(6, true), fixed(6, false);
        Eigen::VectorXd q = Eigen::VectorXd::Zero(6), p = q;
        const SolveResult r = newton.minimize(followed, q);
        Coupling again(6, true);
        Eigen::VectorXd q2 = Eigen::VectorXd::Zero(6);
        const SolveResult r2 = newton.minimize(again, q2);
        const SolveResult s = newton.minimize(fixed, p);
        REQUIRE(r2.converged());
        CHECK((q2 - q).lpNorm<Eigen::Infinity>() < 1e-10);
        REQUIRE(r.converged());
        REQUIRE(s.converged());
        CHECK(followed.pattern_version() == 2);
        CHECK(followed.hessian_pattern().nonZeros() == 7);
        CHECK(q[0] < 0.99);  // the coupling acted
        CHECK((q - p).lpNorm<Eigen::Infinity>() < 1e-10);
    }
}
