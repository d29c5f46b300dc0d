// CholmodLLT (solve/cholmod_llt.hpp): supernodal LL^T of H + shift I for positive definite H, and its solves.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "cholmod_fixtures.hpp"
#include "fibernet/solve/cholmod_llt.hpp"

using namespace fibernet;

using test::grid;

TEST_CASE("cholmod_llt: solves H + shift I, one or several right-hand sides", "[cholmod_llt]") {
    const Eigen::SparseMatrix<double> U = grid(10, 4.6, 0.0);
    const int n = static_cast<int>(U.rows());
    const Eigen::SparseMatrix<double> full = U.selfadjointView<Eigen::Upper>();
    const Eigen::MatrixXd H(full);
    Eigen::MatrixXd B(n, 3);
    for (int i = 0; i < n; ++i) B(i, 0) = std::sin(0.3 * i), B(i, 1) = std::cos(0.7 * i + 1), B(i, 2) = 1.0;
    CholmodLLT llt;
    REQUIRE(llt.factorize(U, 0.25));
    const Eigen::MatrixXd X = llt.solve_many(B);
    CHECK(((H + 0.25 * Eigen::MatrixXd::Identity(n, n)) * X - B).norm() < 1e-12 * B.norm());
    // One column and three are different BLAS kernels (dtrsv against dtrsm): each is backward stable, and on this
    // well-conditioned matrix (kappa ~ 10) they agree to ~kappa eps, not bit for bit.
    for (int c = 0; c < 3; ++c) {
        const Eigen::VectorXd x = llt.solve(B.col(c));
        CHECK(((H + 0.25 * Eigen::MatrixXd::Identity(n, n)) * x - B.col(c)).norm() < 1e-12 * B.col(c).norm());
        CHECK((x - X.col(c)).norm() < 1e-12 * X.col(c).norm());
    }
}

TEST_CASE("cholmod_llt: an indefinite matrix does not factor", "[cholmod_llt]") {
    const Eigen::SparseMatrix<double> U = grid(10, 4.1, 6.0);
    CholmodLLT llt;
    CHECK_FALSE(llt.factorize(U, 0.0));
    CHECK_THROWS_AS(llt.solve(Eigen::VectorXd::Ones(U.rows())), std::logic_error);
    CHECK(llt.factorize(U, 10.0));  // shifted past the most negative eigenvalue
}
