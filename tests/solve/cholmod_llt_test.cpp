// CholmodLLT (solve/cholmod_llt.hpp): supernodal LL^T of H + shift I for positive definite H, and its solves.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "fibernet/solve/cholmod_llt.hpp"

using namespace fibernet;

namespace {
// Upper triangle of a 2D grid operator with a longer coupling (fill, and a fill-reducing order that is not the
// identity); diagonal d0 + a small variation, minus `dip` at a few sites.
Eigen::SparseMatrix<double> grid(int m, double d0, double dip) {
    const int n = m * m;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const int k = i * m + j;
            t.emplace_back(k, k, d0 + 0.3 * std::sin(1.7 * k) - ((i * 5 + j * 3) % 13 == 0 ? dip : 0.0));
            if (j + 1 < m) t.emplace_back(k, k + 1, -1 + 0.1 * std::cos(k));
            if (i + 1 < m) t.emplace_back(k, k + m, -1 + 0.1 * std::sin(2.3 * k));
            if (i + 2 < m && j + 1 < m) t.emplace_back(k, k + 2 * m + 1, 0.2);
        }
    Eigen::SparseMatrix<double> U(n, n);
    U.setFromTriplets(t.begin(), t.end());
    U.makeCompressed();
    return U;
}
}  // namespace

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
    for (int c = 0; c < 3; ++c) CHECK((llt.solve(B.col(c)) - X.col(c)).norm() < 1e-14 * X.col(c).norm());
}

TEST_CASE("cholmod_llt: an indefinite matrix does not factor", "[cholmod_llt]") {
    const Eigen::SparseMatrix<double> U = grid(10, 4.1, 6.0);
    CholmodLLT llt;
    CHECK_FALSE(llt.factorize(U, 0.0));
    CHECK_THROWS_AS(llt.solve(Eigen::VectorXd::Ones(U.rows())), std::logic_error);
    CHECK(llt.factorize(U, 10.0));  // shifted past the most negative eigenvalue
}
