// The linear-solver interface (linear_solver.hpp): the registry of names, and what definite() and negative_pivots()
// promise, on the same matrices for both CHOLMOD solvers.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include "cholmod_fixtures.hpp"
#include "fibernet/solve/linear_solver.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

TEST_CASE("linear solvers: made by name, an unknown name refused listing the known", "[solve][linear]") {
    for (const auto& name : linear_solver_names()) {
        auto s = make_linear_solver(name);
        REQUIRE(s);
        CHECK(s->name() == name);
        CHECK(!s->analyzed());
    }
    CHECK_THROWS_AS(make_linear_solver("umfpack"), InputError);
    CHECK_THROWS_WITH(make_linear_solver("umfpack"),
                      Catch::Matchers::Contains("'umfpack'") && Catch::Matchers::Contains("cholmod-llt"));
}

TEST_CASE("linear solvers: on a positive definite matrix both solve H + shift I to its condition", "[solve][linear]") {
    const Eigen::SparseMatrix<double> U = test::grid(12, 6.0, 0.0);
    const Eigen::MatrixXd A = Eigen::MatrixXd(U).selfadjointView<Eigen::Upper>();
    const int n = static_cast<int>(A.rows());
    Eigen::MatrixXd B(n, 3);
    for (int i = 0; i < n; ++i) B(i, 0) = std::sin(0.7 * i), B(i, 1) = std::cos(1.1 * i), B(i, 2) = 1;
    for (const auto& name : linear_solver_names()) {
        INFO(name);
        auto s = make_linear_solver(name);
        s->analyze(U);
        REQUIRE(s->analyzed());
        for (double shift : {0.0, 0.5}) {
            REQUIRE(s->factorize(U, shift));
            CHECK(s->negative_pivots() == 0);
            const Eigen::MatrixXd M = A + shift * Eigen::MatrixXd::Identity(n, n);
            const Eigen::MatrixXd X = s->solve_many(B);
            // A well-conditioned matrix (diagonally dominant: 6 - 0.3 against at most 4.8 off the diagonal): backward error at round-off.
            CHECK((M * X - B).norm() <= 1e-12 * B.norm());
            // One and several right-hand sides may take different BLAS kernels: equal to the backward error's bound.
            CHECK((X.col(1) - s->solve(B.col(1))).norm() <= 1e-12 * X.col(1).norm());
        }
    }
}

TEST_CASE("linear solvers: an indefinite matrix fails a definite solver and is modified by the other",
          "[solve][linear]") {
    const Eigen::SparseMatrix<double> U = test::grid(12, 6.0, 12.0, 7);  // some diagonal entries pushed negative
    const Eigen::MatrixXd A = Eigen::MatrixXd(U).selfadjointView<Eigen::Upper>();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
    REQUIRE(es.eigenvalues().minCoeff() < -0.1);  // clearly indefinite, not at round-off
    auto llt = make_linear_solver("cholmod-llt");
    CHECK(llt->definite());
    CHECK(!llt->factorize(U, 0.0));
    auto ldl = make_linear_solver("cholmod-ldl");
    CHECK(!ldl->definite());
    REQUIRE(ldl->factorize(U, 1e-3));
    CHECK(ldl->negative_pivots() > 0);
    // The modified solve is of a positive definite matrix: b.x > 0 for every b != 0.
    const int n = static_cast<int>(A.rows());
    for (int k = 0; k < 5; ++k) {
        Eigen::VectorXd b(n);
        for (int i = 0; i < n; ++i) b[i] = std::sin(0.3 * (k + 1) * i + k);
        CHECK(b.dot(ldl->solve(b)) > 0);
    }
}
