// CholmodLLT (solve/cholmod_llt.hpp): supernodal LL^T of H + shift I for positive definite H, and its solves.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "cholmod_fixtures.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/util/blas_threads.hpp"
#include "fibernet/util/parallel.hpp"

extern "C" void openblas_set_num_threads(int);

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

TEST_CASE("cholmod_llt: below the threaded size, the same solution bit for bit on one thread and on two",
          "[cholmod_llt]") {
    // OpenBLAS's threaded kernels round differently from its serial ones; BlasThreads (util/blas_threads.hpp) keeps a
    // factorization of fewer than kThreadedFlops operations on one thread whatever fibernet's or OpenBLAS's count.
    const Eigen::SparseMatrix<double> U = grid(60, 4.1, 0.0);
    Eigen::VectorXd b(U.rows());
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = std::sin(0.37 * static_cast<double>(i)) + 0.5;
    std::vector<Eigen::VectorXd> x;
    for (int threads : {1, 2}) {
        set_thread_count(threads);
        openblas_set_num_threads(BlasThreads::own());  // OpenBLAS's default, as a process starts
        CholmodLLT llt;
        REQUIRE(llt.factorize(U, 0.0));
        x.push_back(llt.solve(b));
    }
    set_thread_count(0);
    CHECK((x[0].array() == x[1].array()).all());
}
