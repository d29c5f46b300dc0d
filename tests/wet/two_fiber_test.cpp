// Two crossing fibers: fiber 1 held fixed, fiber 2 pinned at both ends, a bridge at the crossing (issue 6, tests).
// Small beta: the bridge is a concentrated couple M0 = -dE/dalpha = beta l sin 2 alpha at fiber 2's midspan; a
// simply supported beam rotates there by theta = M0 L / (12 EI) (antisymmetric halves, each a pinned beam of length
// L/2 with end moment M0/2). EI = 2: the hinge energy (2/lt0)(1 - cos phi) ~ (EI/2) (phi/lt0)^2 lt0 (seed eq. 4.15).
// Large beta: fiber 2 aligns with fiber 1 and zips along it.
#include <catch2/catch.hpp>
#include <cmath>

#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/active_set.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {

ActiveSetResult relax(const TwoFiber& t, const NetworkEnergy& e, Eigen::VectorXd& q, double beta) {
    WetParams p;
    p.beta = beta;
    SolverOptions so;
    so.tol = 1e-11;
    so.max_iter = 200;
    auto solver = make_solver("newton", so);
    return relax_wet(e, Eigen::Matrix2d::Identity(), p, wet_crossings(t.net, t.m, t.m.x, t.m.box.B0(), {}), *solver, q);
}
}  // namespace

TEST_CASE("two fibers: small beta rotates fiber 2 like a beam under a concentrated couple", "[wet][physics]") {
    const double alpha = 45, L = 10, EI = 2, beta = 1e-4;
    double previous = 1;
    for (int n : {11, 21, 41, 81}) {
        const TwoFiber t = two_fibers(alpha, n);
        NetworkEnergy e(t.m);
        Eigen::VectorXd q = e.dofs(t.m.x);
        const ActiveSetResult r = relax(t, e, q, beta);
        REQUIRE(r.last.converged());
        CHECK(r.stable);
        REQUIRE(r.bridges.size() == 1);
        const int k = n / 2;  // the middle segment holds the crossing
        CHECK(r.bridges[0].k2 == k);
        const double theta = segment_angle(e, q, 1, k) - alpha * M_PI / 180;
        const double l = L / n;  // mean rest length of the two crossing segments
        const double theory = -beta * l * std::sin(2 * alpha * M_PI / 180) * L / (12 * EI);
        const double err = std::abs(theta / theory - 1);
        INFO("n_seg " << n << ": theta " << theta << ", beam theory " << theory << ", relative error " << err);
        CHECK(err < 0.01);
        CHECK(err < previous);  // falls under refinement
        previous = err;
    }
}

TEST_CASE("two fibers: large beta aligns fiber 2 with fiber 1 and zips them", "[wet][physics]") {
    const TwoFiber t = two_fibers(8, 40);
    NetworkEnergy e(t.m);
    Eigen::VectorXd q = e.dofs(t.m.x);
    const ActiveSetResult r = relax(t, e, q, 50);
    INFO(r.message << "; rounds " << r.rounds << ", moves " << r.events.moves << ", formed " << r.events.formed
                   << ", ruptures " << r.events.ruptures << ", bridges " << r.bridges.size());
    REQUIRE(r.last.converged());
    CHECK((r.stable || r.cycling));
    CHECK(r.events.formed >= 2);  // zipping: new bridges along the overlap
    int aligned = 0;
    for (const Bridge& b : r.bridges) {
        const double a = segment_angle(e, q, 1, b.k2) - segment_angle(e, q, 0, b.k1);
        if (std::abs(std::sin(a)) < std::sin(2 * M_PI / 180)) ++aligned;
    }
    CHECK(aligned >= 3);
}
