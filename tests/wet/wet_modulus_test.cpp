// The wet shear modulus is a second difference of relaxed energies with the bridge set frozen (wet_run.hpp). On a
// dry network the same routine must agree with the exact one-solve linear modulus (mechanics/moduli.hpp).
#include <catch2/catch.hpp>

#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/wet/wet_run.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

TEST_CASE("wet modulus: relaxed second difference equals the exact linear modulus on a dry network", "[wet][moduli]") {
    const Model m = model_of(mikado(2.5, 10, 1.0, 4), 10);
    NetworkEnergy e(m);
    const Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    const Eigen::VectorXd q = e.dofs(m.x);  // the reference state is stress free
    SolverOptions so;
    so.tol = 1e-11;
    auto solver = make_solver("newton", so);
    const double G_fd = relaxed_shear_modulus(e, F, q, {}, WetParams{}, *solver, 1e-4);
    const auto exact = linear_moduli(e, q, F, {shear_mode(F, m.box.area())});
    REQUIRE(exact.front().ok);
    INFO("G exact " << exact.front().value << ", relaxed second difference " << G_fd);
    CHECK(exact.front().value > 1e-3);  // a rigid network, so the comparison means something
    CHECK(G_fd == Approx(exact.front().value).epsilon(1e-4));
}
