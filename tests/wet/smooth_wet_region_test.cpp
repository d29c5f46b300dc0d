// SmoothWetRegion (smooth_wet_region.hpp): the smooth wet energy of a set of coordinates alone is the whole energy's
// restricted to them (gradient, Hessian, value changes), with and without the partner cap, in a sheared periodic box,
// also after the set has moved beyond the neighbour list's skin; and Newton with nonlinear elimination on it ends at
// an equilibrium of the whole energy.
#include <catch2/catch.hpp>
#include <cmath>

#include "fibernet/solve/newton.hpp"
#include "fibernet/wet/smooth_wet_energy.hpp"
#include "fibernet/wet/smooth_wet_region.hpp"
#include "fibernet/wet/smooth_wet_relax.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {

SmoothWetParams smooth(double beta, int partners) {
    SmoothWetParams p;
    p.pair.beta = beta, p.bundle_partners = partners;
    return p;
}

// The coordinates of the free nodes within `radius` of (cx, cy) (periodic images ignored: a patch of the box).
std::vector<int> patch(const NetworkEnergy& dry, const Eigen::VectorXd& x, double cx, double cy, double radius) {
    std::vector<int> c;
    for (int v = 0; v < dry.model().num_nodes(); ++v) {
        if (std::hypot(x[2 * v] - cx, x[2 * v + 1] - cy) > radius) continue;
        for (int k = 0; k < 2; ++k)
            if (dry.dof(v, k) >= 0) c.push_back(dry.dof(v, k));
    }
    std::sort(c.begin(), c.end());
    return c;
}

// The region's gradient, Hessian and value change against the whole energy's on the set, at q and at q moved on the
// set by `move` (which may leave the list's skin).
// far: the move leaves the list, so new pairs come in whose Hessian blocks the region's pattern (built at q) may
// lack; the region then says so (pattern_stale) and only its value and gradient are compared.
void check_region(SmoothWetEnergy& W, const Eigen::VectorXd& q, const std::vector<int>& coords,
                  const Eigen::VectorXd& move, bool far = false) {
    std::unique_ptr<Objective> R = W.restriction(q, coords);
    REQUIRE(R);
    REQUIRE(R->size() == static_cast<int>(coords.size()));
    Eigen::VectorXd qa(coords.size());
    for (size_t k = 0; k < coords.size(); ++k) qa[k] = q[coords[k]];
    for (const bool moved : {false, true}) {
        const Eigen::VectorXd qa_at = moved ? Eigen::VectorXd(qa + move) : qa;
        Eigen::VectorXd qw = q;
        for (size_t k = 0; k < coords.size(); ++k) qw[coords[k]] = qa_at[k];
        // The region first (so that it meets the list as its own moves left it), then the whole energy with its
        // pattern rebuilt at this state (so that its Hessian is complete).
        Eigen::VectorXd g, ga;
        Eigen::SparseMatrix<double> Ha = R->hessian_pattern();
        const int builds = W.list_builds();
        R->hessian(qa_at, ga, Ha, false);
        if (far && moved) CHECK(W.list_builds() > builds);  // the region itself updated the list
        const double dE_region = R->value(qa_at) - R->value(qa);
        W.rebuild(qw);
        Eigen::SparseMatrix<double> H = W.hessian_pattern();
        W.hessian(qw, g, H, false);
        REQUIRE(!W.pattern_stale());
        const Eigen::MatrixXd Hf = dense(H), Hr = dense(Ha);
        double dg = 0, dH = 0, gmax = 0, Hmax = 0;
        for (size_t i = 0; i < coords.size(); ++i) {
            dg = std::max(dg, std::abs(ga[i] - g[coords[i]])), gmax = std::max(gmax, std::abs(g[coords[i]]));
            for (size_t j = 0; j < coords.size(); ++j) {
                // Hf holds the upper triangle: (i, j) and (j, i) from the one entry
                const int a = std::min(coords[i], coords[j]), b = std::max(coords[i], coords[j]);
                const double whole = Hf(a, b);
                const double region = Hr(std::min(i, j), std::max(i, j));
                dH = std::max(dH, std::abs(region - whole)), Hmax = std::max(Hmax, std::abs(whole));
            }
        }
        INFO("max|g| on the set " << gmax << ", gradient error " << dg << "; max|H| " << Hmax << ", error " << dH);
        CHECK(gmax > 1e-3);
        CHECK(dg <= 1e-11 * (1 + gmax));
        const bool stale = dynamic_cast<const SmoothWetRegion&>(*R).pattern_stale();
        if (!far) REQUIRE(!stale);
        if (!stale) CHECK(dH <= 1e-11 * (1 + Hmax));
        CHECK(dE_region == Approx(W.value(qw) - W.value(q)).epsilon(1e-11).margin(1e-10));
    }
}

}  // namespace

TEST_CASE("smooth wet region: the whole energy's gradient, Hessian and value changes on the set",
          "[wet][smooth][region]") {
    Eigen::Matrix2d F;
    F << 1.02, 0.08, 0.0, 0.99;  // sheared, across periodic images
    for (const int partners : {0, 2}) {
        SECTION("a random network, beta = 0.7, cap " + std::to_string(partners)) {
            const Model m = model_of(mikado(2.5, 6, 0.5, 5), 8);
            NetworkEnergy dry(m);
            const Eigen::VectorXd q = perturb(dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F), 0.02, 3);
            SmoothWetEnergy W(dry, F, smooth(0.7, partners), {}, q);
            const Eigen::VectorXd x = dry.positions(q, F);
            const int mid = m.num_nodes() / 2;  // a patch around a node in the box's middle (model units: lf = 10)
            const std::vector<int> coords = patch(dry, x, x[2 * mid], x[2 * mid + 1], 6);
            REQUIRE(coords.size() > 20);
            const Eigen::VectorXd small = perturb(Eigen::VectorXd::Zero(coords.size()), 0.01, 9);
            check_region(W, q, coords, small);
            // Moved by 2.5 along x, beyond the skin: the region rebuilds the list (and its pattern may go stale)
            std::vector<char> is_x(dry.num_dofs(), 0);
            for (int v = 0; v < m.num_nodes(); ++v)
                if (dry.dof(v, 0) >= 0) is_x[dry.dof(v, 0)] = 1;
            Eigen::VectorXd far = small;
            for (size_t k = 0; k < coords.size(); ++k)
                if (is_x[coords[k]]) far[k] += 2.5;
            check_region(W, q, coords, far, true);
        }
    }
    SECTION("a free fiber moved from far off onto another: the region rebuilds the list and takes the crossing") {
        // Fiber 2 vertical at x = 1.5 from y = 1.8 to 2.8, 0.3 fiber lengths (3 model units) above fiber 1, beyond
        // the pair terms' support plus the skin; the region is fiber 2, moved down by 0.8 onto fiber 1.
        const std::vector<Line> lines = {{1.5, 1.5, 0, 1, 0.5}, {1.5, 2.3, 90, 1, 0.5}};
        const Model m = model_of(network_of(lines, 3));
        NetworkEnergy dry(m);
        const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.002, 17);
        for (const int partners : {0, 2}) {
            SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(1.0, partners), {}, q);
            REQUIRE(W.bridges(q).empty());
            const std::vector<int> coords = patch(dry, dry.positions(q, Eigen::Matrix2d::Identity()), 15, 23, 5.5);
            REQUIRE(coords.size() == 2 * 11);
            Eigen::VectorXd down = Eigen::VectorXd::Zero(coords.size());
            for (int k = 1; k < down.size(); k += 2) down[k] = -8.0;  // coords: (x, y) of each node in turn
            check_region(W, q, coords, down, true);
            Eigen::VectorXd qd = q;
            for (size_t k = 0; k < coords.size(); ++k) qd[coords[k]] += down[k];
            CHECK(!W.bridges(qd).empty());  // the crossing is there, and the region found it
        }
    }
    SECTION("a stack of three fibers under a cap of 2 (segments in the saturation blend), one coordinate of a node") {
        const std::vector<Line> three = {{1.0, 1.5, 0, 1, 0.5}, {1.1, 1.505, 3, 1, 0.5}, {1.2, 1.51, -2, 1, 0.5}};
        const Model m = model_of(network_of(three, 3));
        NetworkEnergy dry(m);
        const Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.004, 51);
        SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(2.5, 2), {}, q);
        SmoothWetEnergy U(dry, Eigen::Matrix2d::Identity(), smooth(2.5, 0), {}, q);
        REQUIRE(std::abs(W.value(q) - U.value(q)) > 1e-3);  // the cap acts
        // The nodes of the middle fiber's first half, and the x coordinate alone of one node of the first fiber.
        std::vector<int> coords = patch(dry, dry.positions(q, Eigen::Matrix2d::Identity()), 13, 15.05, 3);
        REQUIRE(coords.size() > 6);
        coords.pop_back();
        check_region(W, q, coords, perturb(Eigen::VectorXd::Zero(coords.size()), 0.003, 7));
    }
}

TEST_CASE("smooth wet region: Newton with elimination ends at an equilibrium of the whole energy",
          "[wet][smooth][region][relax]") {
    for (const int partners : {0, 2}) {
        const Model m = model_of(mikado(2.2, 5, 0.8, 5), 6);
        NetworkEnergy dry(m);
        Eigen::VectorXd q = perturb(dry.dofs(m.x), 0.02, 3);
        SmoothWetEnergy W(dry, Eigen::Matrix2d::Identity(), smooth(0.05, partners), {}, q);
        const double e0 = W.value(q);
        SolverOptions o;
        o.tol = 1e-9, o.max_iter = 500, o.eliminate = true;
        o.elimination.hops = 1, o.elimination.max_fraction = 0.5;  // places small enough for this small network
        NewtonSolver newton(o);
        SmoothRelaxOptions ro;
        ro.round_iterations = 10, ro.max_rounds = 100;
        const SmoothRelaxResult r = relax_smooth_wet(W, newton, q, ro);
        INFO("cap " << partners << ": " << r.message << ", " << r.iterations << " iterations, " << r.local_solves
                    << " local solves");
        REQUIRE(r.converged);
        CHECK(r.local_solves > 0);
        Eigen::VectorXd g;
        W.gradient(q, g);
        CHECK(g.lpNorm<Eigen::Infinity>() <= std::max(1e-9, r.last.grad_floor));
        CHECK(r.energy < e0);
    }
}
