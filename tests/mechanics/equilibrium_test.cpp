// relax(): the reference state at F = I is returned as the exact minimum it is, without iterations; a prestrained
// reference is solved.
#include <catch2/catch.hpp>

#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"

using namespace fibernet;

TEST_CASE("relax at F = I: the rest state is returned as an exact minimum, a prestrained one is solved", "[mechanics]") {
    MikadoParams mp;
    mp.L = 4, mp.q = 8, mp.pl = 1, mp.seed = 2;
    DiscretizationParams dp;
    dp.scheme = Scheme::Even;
    Model m = discretize(generate_mikado(mp), dp);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    SolverOptions so;
    NewtonSolver newton(so);
    {
        const NetworkEnergy e(m);
        const Equilibrium eq = relax(e, I, newton);
        REQUIRE(eq.converged());
        CHECK(eq.result.iterations == 0);
        CHECK(eq.result.message.find("rest state") != std::string::npos);
        CHECK(eq.energy <= 1e-20);
        CHECK((eq.q - e.dofs(m.x)).norm() == 0);  // not moved along floppy modes
    }
    // A prestrained model (every other rest length 1% longer than its reference segment): E > 0 at the start, so
    // Newton runs.
    for (size_t k = 0; k < m.segments.size(); k += 2) m.segments[k].l0 *= 1.01;
    const NetworkEnergy e(m);
    const Equilibrium eq = relax(e, I, newton);
    REQUIRE(eq.converged());
    CHECK(eq.result.iterations > 0);
    CHECK(eq.result.message.find("rest state") == std::string::npos);
}
