// CholmodLDL (solve/cholmod_ldl.hpp): simplicial LDL^T of possibly indefinite matrices and the solve with the pivots
// replaced by max(|D_j|, floor).
#include <catch2/catch.hpp>

#include <cholmod.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "cholmod_fixtures.hpp"
#include "fibernet/solve/cholmod_ldl.hpp"
#include "fibernet/util/parallel.hpp"

using namespace fibernet;

namespace {
// Upper triangle of a symmetric matrix given densely.
Eigen::SparseMatrix<double> upper(const Eigen::MatrixXd& A) {
    std::vector<Eigen::Triplet<double>> t;
    for (int c = 0; c < A.cols(); ++c)
        for (int r = 0; r <= c; ++r)
            if (A(r, c) != 0 || r == c) t.emplace_back(r, c, A(r, c));
    Eigen::SparseMatrix<double> U(A.rows(), A.cols());
    U.setFromTriplets(t.begin(), t.end());
    U.makeCompressed();
    return U;
}
}  // namespace

TEST_CASE("cholmod_ldl: a positive definite matrix is solved exactly", "[cholmod_ldl]") {
    const int n = 40;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        A(i, i) = 2.5;
        if (i + 1 < n) A(i, i + 1) = A(i + 1, i) = -1;
        if (i + 7 < n) A(i, i + 7) = A(i + 7, i) = 0.3;
    }
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) b[i] = std::sin(1.3 * i + 0.2);
    CholmodLDL ldl;
    REQUIRE(ldl.factorize(upper(A), 0.0));
    CHECK(ldl.negative_pivots() == 0);
    const Eigen::VectorXd x = ldl.solve_modified(b, 1e-300);
    CHECK((A * x - b).norm() < 1e-12 * b.norm());
    // The shift argument factors A + shift I.
    REQUIRE(ldl.factorize(upper(A), 0.7));
    const Eigen::VectorXd y = ldl.solve_modified(b, 1e-300);
    CHECK(((A + 0.7 * Eigen::MatrixXd::Identity(n, n)) * y - b).norm() < 1e-12 * b.norm());
}

TEST_CASE("cholmod_ldl: negative pivots are replaced by their magnitudes", "[cholmod_ldl]") {
    // Diagonal: x_i = b_i / max(|d_i|, floor).
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(4, 4);
    D.diagonal() << 2, -3, 4, -1e-9;
    CholmodLDL ldl;
    REQUIRE(ldl.factorize(upper(D), 0.0));
    CHECK(ldl.negative_pivots() == 2);
    CHECK(ldl.min_pivot() == -3);
    const Eigen::Vector4d b(1, 1, 1, 1);
    const Eigen::VectorXd x = ldl.solve_modified(b, 1e-3);
    CHECK(x[0] == Approx(0.5));
    CHECK(x[1] == Approx(1.0 / 3));
    CHECK(x[2] == Approx(0.25));
    CHECK(x[3] == Approx(1e3));  // |d| below the floor
    // Coupled and indefinite: the modified matrix L |D| L^T is positive definite, so x.b > 0 for every b != 0, and it
    // equals the matrix itself on a positive definite block (here the result is checked against L |D| L^T built from
    // the 2 x 2 elimination by hand: A = [[2, 1], [1, -3]] -> d = (2, -3.5), l = 0.5).
    Eigen::MatrixXd A(2, 2);
    A << 2, 1, 1, -3;
    REQUIRE(ldl.factorize(upper(A), 0.0));
    CHECK(ldl.negative_pivots() == 1);
    const Eigen::Vector2d b2(0.3, -1.1);
    const Eigen::VectorXd x2 = ldl.solve_modified(b2, 1e-12);
    CHECK(x2.dot(b2) > 0);
    // Either elimination order gives a symmetric positive definite M with M x2 = b2; the order CHOLMOD chose is not
    // fixed, so check both candidates and require one to match.
    auto modified = [](const Eigen::MatrixXd& a, int first) {
        const int s = 1 - first;
        const double d0 = a(first, first), l = a(s, first) / d0, d1 = a(s, s) - l * l * d0;
        Eigen::MatrixXd L = Eigen::MatrixXd::Identity(2, 2), Dm = Eigen::MatrixXd::Zero(2, 2);
        L(s, first) = l;
        Dm(first, first) = std::abs(d0), Dm(s, s) = std::abs(d1);
        return Eigen::MatrixXd(L * Dm * L.transpose());
    };
    const double r0 = (modified(A, 0) * x2 - b2).norm(), r1 = (modified(A, 1) * x2 - b2).norm();
    CHECK(std::min(r0, r1) < 1e-12);
    for (int k = 0; k < 20; ++k) {
        const Eigen::Vector2d c(std::cos(0.7 * k), std::sin(1.9 * k + 0.1));
        CHECK(ldl.solve_modified(c, 1e-12).dot(c) > 0);
    }
}

TEST_CASE("cholmod_ldl: a zero pivot fails the factorization", "[cholmod_ldl]") {
    Eigen::MatrixXd A(2, 2);
    A << 1, 1, 1, 1;  // singular: the second pivot is exactly 0
    CholmodLDL ldl;
    CHECK_FALSE(ldl.factorize(upper(A), 0.0));
    CHECK_THROWS(ldl.solve_modified(Eigen::Vector2d(1, 0), 1.0));
    CHECK(ldl.factorize(upper(A), 1e-3));  // shifted: positive definite
}

TEST_CASE("cholmod_ldl: inertia and descent on a sparse indefinite matrix", "[cholmod_ldl]") {
    // A 2D grid Laplacian-like matrix with some negative diagonal entries: a fill-reducing permutation that is not the
    // identity, and coupled negative curvature. The number of negative pivots is the number of negative eigenvalues
    // (Sylvester's law of inertia), and the modified solve is a positive definite operator (x.b > 0).
    const int m = 8, n = m * m;
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const int k = i * m + j;
            A(k, k) = 4.2 - ((i * 7 + j * 3) % 11 == 0 ? 6.0 : 0.0);
            if (j + 1 < m) A(k, k + 1) = A(k + 1, k) = -1;
            if (i + 1 < m) A(k, k + m) = A(k + m, k) = -1;
        }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
    int negative = 0;
    for (int i = 0; i < n; ++i) negative += es.eigenvalues()[i] < 0;
    REQUIRE(negative > 0);
    REQUIRE(es.eigenvalues().cwiseAbs().minCoeff() > 1e-6);
    CholmodLDL ldl;
    REQUIRE(ldl.factorize(upper(A), 0.0));
    CHECK(ldl.negative_pivots() == negative);
    for (int t = 0; t < 10; ++t) {
        Eigen::VectorXd b(n);
        for (int i = 0; i < n; ++i) b[i] = std::sin(0.37 * i * (t + 1) + t);
        const Eigen::VectorXd x = ldl.solve_modified(b, 1e-12);
        CHECK(x.allFinite());
        CHECK(x.dot(b) > 0);
    }
}

TEST_CASE("cholmod_ldl: the pre-permuted factorization equals CHOLMOD's own bit for bit", "[cholmod_ldl]") {
    // CholmodLDL hands CHOLMOD S = P A P^T in its natural order instead of A with the order P (which CHOLMOD
    // transposes twice per factorization). Same order, same S: the same pivots and solves, exactly. Reference: CHOLMOD
    // on A itself, with its default analysis, and the modified solve written out with its permutation solves.
    const Eigen::SparseMatrix<double> U = test::grid(12, 4.1, 6.0);
    const int n = static_cast<int>(U.rows());
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) b[i] = std::sin(0.61 * i + 0.3);
    const double shift = 1e-3, floor = 1e-6;
    const test::CholmodReference ref(U, false, shift, floor, b);
    REQUIRE_FALSE(ref.identity_order);  // a fill-reducing order: the case the pre-permutation is for
    const int negative = ref.negative;
    const Eigen::VectorXd& v = ref.x;
    REQUIRE(negative > 0);

    CholmodLDL ldl;
    REQUIRE(ldl.factorize(U, shift));
    CHECK(ldl.negative_pivots() == negative);
    const Eigen::VectorXd x = ldl.solve_modified(b, floor);
    int differ = 0;
    for (int i = 0; i < n; ++i) differ += x[i] != v[i];
    CHECK(differ == 0);
    // New values on the analyzed pattern reuse the analysis (1.5 (A + shift I): the same pivots x 1.5); a matrix of the
    // same size with another number of entries is refused, as is a right-hand side of another size.
    Eigen::SparseMatrix<double> U2 = U;
    for (int k = 0; k < U2.nonZeros(); ++k) U2.valuePtr()[k] *= 1.5;
    REQUIRE(ldl.factorize(U2, 1.5 * shift));
    CHECK(ldl.negative_pivots() == negative);
    CHECK((1.5 * ldl.solve_modified(b, 1.5 * floor) - x).norm() < 1e-12 * x.norm());
    Eigen::SparseMatrix<double> D(n, n);
    D.setIdentity();
    D.makeCompressed();
    CHECK_THROWS_AS(ldl.factorize(D, 0.0), std::logic_error);
    CHECK_THROWS_AS(ldl.solve_modified(Eigen::VectorXd::Ones(n + 1), floor), std::logic_error);
}

TEST_CASE("cholmod_ldl: the two-thread order factors as CHOLMOD would in that order, on any thread count",
          "[cholmod_ldl][slow]") {
    // A grid with indefinite spots and longer couplings, large enough for a separator; split_min 100 forces the
    // two-thread order (bisection, CAMD within [A][B][S]) that large Hessians get. Reference: CHOLMOD factoring
    // S = P (A + shift I) P^T in one call, in its natural order, with the same P; the modified solve written out.
    // The parts' pivots are CHOLMOD's bit for bit, the separator's to round-off (summed in another order), and the
    // factor does not depend on the thread count.
    const Eigen::SparseMatrix<double> U = test::grid(40, 4.1, 6.0, 17);
    const int n = static_cast<int>(U.rows());
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) b[i] = std::sin(0.61 * i + 0.3);
    const double shift = 1e-3, floor = 1e-6;

    CholmodLDL ldl(100);
    struct RestoreThreads {
        ~RestoreThreads() { set_thread_count(0); }
    } restore_threads;
    set_thread_count(1);
    REQUIRE(ldl.factorize(U, shift));
    const Eigen::VectorXd x1 = ldl.solve_modified(b, floor);
    const Eigen::VectorXd d1 = ldl.pivots();
    const int negative = ldl.negative_pivots();
    set_thread_count(2);
    REQUIRE(ldl.factorize(U, shift));
    const Eigen::VectorXd x2 = ldl.solve_modified(b, floor);
    const Eigen::VectorXd d2 = ldl.pivots();
    const int a = ldl.split_a(), s = ldl.split_b();
    REQUIRE(a > n / 4);
    REQUIRE(s - a > n / 4);
    REQUIRE(s < n);
    // The parts are independent: no entry of U between a row eliminated in [0, a) and one in [a, s).
    const std::vector<int>& P = ldl.order();
    std::vector<int> pinv(n);
    for (int k = 0; k < n; ++k) pinv[P[k]] = k;
    int coupled = 0;
    for (int c = 0; c < n; ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(U, c); it; ++it) {
            const int u = pinv[it.row()], v = pinv[c];
            coupled += (u < a && v >= a && v < s) || (v < a && u >= a && u < s);
        }
    CHECK(coupled == 0);

    // Reference: S = P U P^T (upper), CHOLMOD in its natural order, one call.
    std::vector<Eigen::Triplet<double>> ts;
    for (int c = 0; c < n; ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(U, c); it; ++it) {
            const int u = pinv[it.row()], v = pinv[c];
            ts.emplace_back(std::min(u, v), std::max(u, v), it.value());
        }
    Eigen::SparseMatrix<double> S(n, n);
    S.setFromTriplets(ts.begin(), ts.end());
    S.makeCompressed();
    Eigen::VectorXd bp(n);
    for (int k = 0; k < n; ++k) bp[k] = b[P[k]];
    const test::CholmodReference ref(S, true, shift, floor, bp);
    const int ref_negative = ref.negative;
    int part_differ = 0;
    double sep_error = 0;
    for (int j = 0; j < n; ++j) {
        if (j < s) part_differ += d1[j] != ref.pivots[j];
        else sep_error = std::max(sep_error, std::abs(d1[j] - ref.pivots[j]) / std::abs(ref.pivots[j]));
    }
    Eigen::VectorXd xr(n);
    for (int k = 0; k < n; ++k) xr[P[k]] = ref.x[k];
    REQUIRE(ref_negative > 0);
    CHECK(negative == ref_negative);
    CHECK(part_differ == 0);
    CHECK(sep_error < 1e-12);
    CHECK((x1 - xr).norm() <= 1e-10 * xr.norm());
    int threads_differ = 0;
    for (int i = 0; i < n; ++i) threads_differ += (x1[i] != x2[i]) + (d1[i] != d2[i]);
    CHECK(threads_differ == 0);
    // Inertia (Sylvester): as many negative pivots as negative eigenvalues of U + shift I.
    Eigen::MatrixXd dense = Eigen::MatrixXd(U);
    dense.triangularView<Eigen::StrictlyLower>() = dense.transpose();
    dense.diagonal().array() += shift;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(dense, Eigen::EigenvaluesOnly);
    CHECK(negative == (es.eigenvalues().array() < 0).count());

    // A zero pivot in either part (a coordinate with zero couplings and diagonal -shift: D = 0 exactly) fails the
    // factorization, on both thread counts; the next factorization of U is the same as before, bit for bit.
    for (const int pos : {a / 2, a + (s - a) / 2})
        for (const int threads : {1, 2}) {
            set_thread_count(threads);
            const int z = P[pos];
            Eigen::SparseMatrix<double> Z = U;
            for (int c = 0; c < n; ++c)
                for (Eigen::SparseMatrix<double>::InnerIterator it(Z, c); it; ++it)
                    if (it.row() == z || c == z) it.valueRef() = it.row() == c ? -shift : 0.0;
            CHECK_FALSE(ldl.factorize(Z, shift));
            REQUIRE(ldl.factorize(U, shift));
            const Eigen::VectorXd d3 = ldl.pivots(), x3 = ldl.solve_modified(b, floor);
            int again = 0;
            for (int i = 0; i < n; ++i) again += (x3[i] != x1[i]) + (d3[i] != d1[i]);
            CHECK(again == 0);
        }
}
