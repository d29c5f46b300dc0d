#include <catch2/catch.hpp>
#include <Eigen/Geometry>
#include <cmath>

#include "fd.hpp"
#include "fibernet/energy/bend.hpp"

using namespace fibernet;

TEST_CASE("bend: gradient and Hessian match finite differences at small and large angles", "[energy][gradient][hessian]") {
    const double lt0 = 0.8;
    for (double phi : {0.0, 1e-3, 0.3, 1.5, 2.5, 3.1, M_PI}) {
        for (double len2 : {1.0, 0.05, 3.0}) {
            const Eigen::Vector2d d1(0.9, 0.2);
            const double t = std::atan2(d1.y(), d1.x()) + phi;
            const Eigen::Vector2d d2 = len2 * Eigen::Vector2d(std::cos(t), std::sin(t));
            Eigen::Vector4d x;
            x << d1, d2;
            auto f = [&](const Eigen::VectorXd& v) { return bend_energy(v.head<2>(), v.tail<2>(), lt0, nullptr, nullptr); };
            auto gf = [&](const Eigen::VectorXd& v) {
                Eigen::Vector4d g;
                bend_energy(v.head<2>(), v.tail<2>(), lt0, &g, nullptr);
                return Eigen::VectorXd(g);
            };
            Eigen::Vector4d g;
            Eigen::Matrix4d H;
            const double E = bend_energy(d1, d2, lt0, &g, &H);
            INFO("phi = " << phi << ", |d2| = " << len2);
            CHECK(E == Approx(2 / lt0 * (1 - std::cos(phi))).margin(1e-12));
            CHECK(fdtest::rel_err(g, fdtest::fd_gradient(f, x, 1e-7), 1.0) < 1e-6);
            CHECK(fdtest::rel_err(H, fdtest::fd_jacobian(gf, x, 1e-7)) < 1e-6);
            CHECK((H - H.transpose()).norm() < 1e-12 * H.norm() + 1e-14);
        }
    }
}

TEST_CASE("bend: small-angle limit is phi^2 / lt0 (seed eq. 4.15)", "[energy]") {
    const double phi = 1e-3, lt0 = 1.3;
    const Eigen::Vector2d d1(1, 0), d2(std::cos(phi), std::sin(phi));
    CHECK(bend_energy(d1, d2, lt0, nullptr, nullptr) == Approx(phi * phi / lt0).epsilon(1e-6));
}

TEST_CASE("bend: the energy is exact and non-negative at tiny angles", "[energy]") {
    for (double phi : {1e-12, 1e-9, 1e-6}) {
        const Eigen::Vector2d d1(3.7, 1.3), d2 = Eigen::Rotation2Dd(phi).toRotationMatrix() * Eigen::Vector2d(0.37, 0.13);
        const double E = bend_energy(d1, d2, 1.0, nullptr, nullptr);
        CHECK(E >= 0);
        CHECK(E == Approx(phi * phi).epsilon(1e-3));  // 2 (1 - cos phi) = phi^2 + O(phi^4); the naive form gives 0 at 1e-12
    }
}
