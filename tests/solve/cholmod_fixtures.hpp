#pragma once
// Shared by the CHOLMOD wrapper tests (cholmod_ldl_test.cpp, cholmod_llt_test.cpp): a sparse test matrix and CHOLMOD's
// own simplicial LDL^T with the modified solve written out, the reference the wrappers are held to.
#include <catch2/catch.hpp>

#include <cholmod.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <vector>

namespace fibernet::test {

// Upper triangle of a 2D grid operator with a longer coupling (fill, and a fill-reducing order that is not the
// identity); diagonal d0 + a small variation, minus `dip` at the sites with (5 i + 3 j) % period == 0.
inline Eigen::SparseMatrix<double> grid(int m, double d0, double dip, int period = 13) {
    const int n = m * m;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const int k = i * m + j;
            t.emplace_back(k, k, d0 + 0.3 * std::sin(1.7 * k) - ((i * 5 + j * 3) % period == 0 ? dip : 0.0));
            if (j + 1 < m) t.emplace_back(k, k + 1, -1 + 0.1 * std::cos(k));
            if (i + 1 < m) t.emplace_back(k, k + m, -1 + 0.1 * std::sin(2.3 * k));
            if (i + 2 < m && j + 1 < m) t.emplace_back(k, k + 2 * m + 1, 0.2);  // a longer coupling: more fill
        }
    Eigen::SparseMatrix<double> U(n, n);
    U.setFromTriplets(t.begin(), t.end());
    U.makeCompressed();
    return U;
}

// CHOLMOD's simplicial LDL^T of U + shift I (U: an upper triangle), with its default analysis or in the natural
// order, and x = P^T L^-T Dm^-1 L^-1 P b with Dm_j = max(|D_j|, floor), through CHOLMOD's own permutation and
// triangular solves.
struct CholmodReference {
    Eigen::VectorXd x, pivots;      // pivots in CHOLMOD's elimination order
    int negative = 0;
    bool identity_order = true;     // CHOLMOD's fill-reducing order is the identity

    CholmodReference(const Eigen::SparseMatrix<double>& U, bool natural, double shift, double floor,
                     const Eigen::VectorXd& b) {
        const int n = static_cast<int>(U.rows());
        cholmod_common c;
        cholmod_start(&c);
        c.supernodal = CHOLMOD_SIMPLICIAL, c.final_ll = 0, c.print = 0;
        if (natural) c.nmethods = 1, c.method[0].ordering = CHOLMOD_NATURAL, c.postorder = 0;
        cholmod_sparse A{};
        A.nrow = A.ncol = n, A.nzmax = U.nonZeros();
        A.p = const_cast<int*>(U.outerIndexPtr()), A.i = const_cast<int*>(U.innerIndexPtr());
        A.x = const_cast<double*>(U.valuePtr());
        A.stype = 1, A.itype = CHOLMOD_INT, A.xtype = CHOLMOD_REAL, A.dtype = CHOLMOD_DOUBLE, A.sorted = 1, A.packed = 1;
        cholmod_factor* L = cholmod_analyze(&A, &c);
        REQUIRE(L);
        double beta[2] = {shift, 0};
        REQUIRE(cholmod_factorize_p(&A, beta, nullptr, 0, L, &c));
        REQUIRE(L->minor == L->n);
        for (int k = 0; k < n; ++k) identity_order = identity_order && static_cast<int*>(L->Perm)[k] == k;
        x = b;
        auto apply = [&](int sys) {
            cholmod_dense B{};
            B.nrow = B.d = B.nzmax = n, B.ncol = 1, B.x = x.data(), B.xtype = CHOLMOD_REAL, B.dtype = CHOLMOD_DOUBLE;
            cholmod_dense* X = cholmod_solve(sys, L, &B, &c);
            REQUIRE(X);
            std::copy(static_cast<double*>(X->x), static_cast<double*>(X->x) + n, x.data());
            cholmod_free_dense(&X, &c);
        };
        apply(CHOLMOD_P), apply(CHOLMOD_L);
        const double* Lx = static_cast<const double*>(L->x);
        const int* Lp = static_cast<const int*>(L->p);
        pivots.resize(n);
        for (int j = 0; j < n; ++j) {
            pivots[j] = Lx[Lp[j]];
            negative += pivots[j] < 0;
            x[j] /= std::max(std::abs(pivots[j]), floor);
        }
        apply(CHOLMOD_Lt), apply(CHOLMOD_Pt);
        cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
    }
};

}  // namespace fibernet::test
