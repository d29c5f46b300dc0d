#include <catch2/catch.hpp>

#include "fd.hpp"
#include "fibernet/energy/stretch.hpp"

using namespace fibernet;

namespace {
void check_segment(const Eigen::Vector2d& d, double l0, double k) {
    StretchLaw law;
    Eigen::Vector2d g;
    Eigen::Matrix2d H;
    stretch_energy(d, l0, k, law, &g, &H);
    auto f = [&](const Eigen::VectorXd& v) { return stretch_energy(v, l0, k, law, nullptr, nullptr); };
    auto gf = [&](const Eigen::VectorXd& v) {
        Eigen::Vector2d gg;
        stretch_energy(v, l0, k, law, &gg, nullptr);
        return Eigen::VectorXd(gg);
    };
    const double h = 1e-7 * d.norm();
    INFO("d = " << d.transpose() << ", l0 = " << l0 << ", eps = " << d.norm() / l0 - 1);
    CHECK(fdtest::rel_err(g, fdtest::fd_gradient(f, d, h)) < 1e-6);
    CHECK(fdtest::rel_err(H, fdtest::fd_jacobian(gf, d, h)) < 1e-6);
}
}  // namespace

TEST_CASE("stretch: gradient and Hessian match finite differences on both branches", "[energy][gradient][hessian]") {
    const double k = 4 * 10 * 10;
    const Eigen::Vector2d dir = Eigen::Vector2d(0.6, -0.8);
    for (double eps : {0.3, 0.01, -0.2, -0.9, -0.94, -0.96, -0.98, -0.995}) check_segment((1 + eps) * 0.7 * dir, 0.7, k);
    check_segment(Eigen::Vector2d(1e-3, 2e-3), 2.2e-3, k);  // very short segment
}

TEST_CASE("stretch: softcore joins the harmonic branch C2 at eps* and diverges at eps -> -1", "[energy]") {
    StretchLaw law;
    double f0, df0, d2f0, f1, df1, d2f1;
    const double e = 1e-9;
    law.eval(law.eps_star + e, f0, df0, d2f0);
    law.eval(law.eps_star - e, f1, df1, d2f1);
    CHECK(f1 == Approx(f0).epsilon(1e-7));
    CHECK(df1 == Approx(df0).epsilon(1e-7));
    CHECK(d2f1 == Approx(d2f0).epsilon(1e-6));
    double f, df, d2f;
    law.eval(-1 + 1e-6, f, df, d2f);
    CHECK(f > 100);  // k_sc / u = 0.05^3 / 1e-6 = 125
    CHECK(df < -1e6);  // strong restoring force
    law.eval(-1, f, df, d2f);
    CHECK(std::isinf(f));
    // Inside the softcore the energy exceeds the harmonic continuation (it only ever adds repulsion).
    law.eval(-0.97, f, df, d2f);
    CHECK(f > 0.97 * 0.97);
    // Zero at rest.
    law.eval(0, f, df, d2f);
    CHECK(f == 0);
    CHECK(df == 0);
}
