#pragma once
// Internal: a cholmod_sparse view (no copy) of an upper-triangular Eigen CSC matrix with int indices, shared by the
// CHOLMOD wrappers (cholmod_llt.cpp, cholmod_ldl.cpp).
#include <cholmod.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace fibernet::detail {

inline cholmod_sparse cholmod_upper_view(const Eigen::SparseMatrix<double>& A, const char* who) {
    if (!A.isCompressed()) throw std::logic_error(std::string(who) + ": matrix must be compressed");
    cholmod_sparse s{};
    s.nrow = s.ncol = static_cast<size_t>(A.rows());
    s.nzmax = static_cast<size_t>(A.nonZeros());
    s.p = const_cast<int*>(A.outerIndexPtr());
    s.i = const_cast<int*>(A.innerIndexPtr());
    s.x = const_cast<double*>(A.valuePtr());
    s.stype = 1;  // upper triangle stored
    s.itype = CHOLMOD_INT;
    s.xtype = CHOLMOD_REAL;
    s.dtype = CHOLMOD_DOUBLE;
    s.sorted = 1;
    s.packed = 1;
    return s;
}

// The upper triangle of S = P A P^T for the upper triangle of a symmetric A (entries r <= c only) and a
// fill-reducing order perm (perm[k]: the row of A eliminated k-th), with rows sorted in each column. CHOLMOD factors a
// matrix analyzed in its natural order as given, where with an order of its own it first permutes and transposes the
// input on every factorization (cholmod_factorize.c: twice for a simplicial LDL^T of an upper triangle, 13 % of a
// factorization of a 1e4-fiber wet Hessian in its first round; once for a supernodal LL^T, about 5 % there and not
// worth the second analysis: CholmodLLT does not use this). Built once per pattern; gather() then moves new values
// of A into place.
struct PermutedTriangle {
    std::vector<int> p, i, from;  // CSC pattern of S's upper triangle; from[k]: the entry of A that S's entry k is
    std::vector<double> x;

    PermutedTriangle() = default;
    PermutedTriangle(const Eigen::SparseMatrix<double>& upper, const std::vector<int>& perm) {
        const int n = static_cast<int>(upper.rows());
        std::vector<int> pinv(n);
        for (int k = 0; k < n; ++k) pinv[perm[k]] = k;
        const long nz = upper.nonZeros();
        // Bucketed by row and then, stably, by column: each column's rows come out sorted, as CHOLMOD's transposes
        // leave them.
        std::vector<int> row(nz), col(nz), by_row(nz), count(n + 1, 0);
        for (int j = 0; j < n; ++j)
            for (int k = upper.outerIndexPtr()[j]; k < upper.outerIndexPtr()[j + 1]; ++k) {
                const int a = pinv[upper.innerIndexPtr()[k]], b = pinv[j];
                row[k] = std::min(a, b), col[k] = std::max(a, b);
                ++count[row[k] + 1];
            }
        for (int r = 0; r < n; ++r) count[r + 1] += count[r];
        for (long k = 0; k < nz; ++k) by_row[count[row[k]]++] = static_cast<int>(k);
        p.assign(n + 1, 0);
        for (long k = 0; k < nz; ++k) ++p[col[k] + 1];
        for (int c = 0; c < n; ++c) p[c + 1] += p[c];
        std::vector<int> next(p.begin(), p.end() - 1);
        i.resize(nz), from.resize(nz), x.assign(nz, 0.0);
        for (const int k : by_row) {
            const int at = next[col[k]]++;
            i[at] = row[k], from[at] = k;
        }
    }
    long nonzeros() const { return static_cast<long>(i.size()); }
    void gather(const Eigen::SparseMatrix<double>& upper) {
        const double* a = upper.valuePtr();
        for (size_t k = 0; k < from.size(); ++k) x[k] = a[from[k]];
    }
    cholmod_sparse view() {
        cholmod_sparse S{};
        S.nrow = S.ncol = p.empty() ? 0 : p.size() - 1;
        S.nzmax = i.size();
        S.p = p.data(), S.i = i.data(), S.x = x.data();
        S.stype = 1, S.itype = CHOLMOD_INT, S.xtype = CHOLMOD_REAL, S.dtype = CHOLMOD_DOUBLE;
        S.sorted = 1, S.packed = 1;
        return S;
    }
};

// Analysis of S (a PermutedTriangle) in its natural order without a postorder: perm, taken from CHOLMOD's own
// analysis of A (ordering and postorder), already is the order, so the elimination tree, column counts
// and factor are those of that analysis, bit for bit (tests/solve/cholmod_ldl_test.cpp).
inline cholmod_factor* analyze_natural(cholmod_sparse& S, cholmod_common& c) {
    const int nmethods = c.nmethods, method0 = c.method[0].ordering, postorder = c.postorder;
    c.nmethods = 1, c.method[0].ordering = CHOLMOD_NATURAL, c.postorder = 0;
    cholmod_factor* L = cholmod_analyze(&S, &c);
    c.nmethods = nmethods, c.method[0].ordering = method0, c.postorder = postorder;
    return L;
}

}  // namespace fibernet::detail
