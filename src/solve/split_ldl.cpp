#include "split_ldl.hpp"

#include <algorithm>
#include <cmath>

#include "fibernet/util/parallel.hpp"

namespace fibernet::detail {

void SplitLDL::setup(int n, int a, int b, std::vector<int> parent) {
    n_ = n, a_ = a, b_ = b;
    parent_ = std::move(parent);
    for (Part& p : part_) {
        p.w.assign(n, 0.0);
        p.flag.assign(n, -1);
        p.stack.assign(n, 0);
        p.mark.assign(n - b, -1);
    }
    ws_.assign(n, 0.0);
    fs_.assign(n, -1);
    ss_.assign(n, 0);
}

namespace {
// The arrays of CHOLMOD's simplicial numeric factor and of the upper triangle S that the rows below read and write.
struct Arrays {
    const int *Sp, *Si;
    const double* Sx;
    const int* Lp;
    int *Li, *Lnz;
    double* Lx;
    Arrays(const cholmod_sparse& S, cholmod_factor& L)
        : Sp(static_cast<const int*>(S.p)), Si(static_cast<const int*>(S.i)), Sx(static_cast<const double*>(S.x)),
          Lp(static_cast<const int*>(L.p)), Li(static_cast<int*>(L.i)), Lnz(static_cast<int*>(L.nz)),
          Lx(static_cast<double*>(L.x)) {}
};

// Puts the elimination-tree path from i up to (not including) the first node >= limit or already marked with `mark`
// onto the reach stack[top..n), as t_cholmod_rowfac.c's SUBTREE does: the reach stays in topological order.
inline void push_path(int i, int limit, int mark, const int* parent, int* flag, int* stack, int& top) {
    int len = 0;
    for (int j = i; j >= 0 && j < limit && flag[j] != mark; j = parent[j]) stack[len++] = j, flag[j] = mark;
    while (len > 0) stack[--top] = stack[--len];
}

// Row k's triangular solve over the reach stack[top..n) (t_cholmod_rowfac.c's LDL' loop): each column i sends its
// updates to W (touch(r) sees every row r first), L(k, i) = y / D_i is appended to column i, and dk falls by
// L(k, i) y. Returns dk.
template <class Touch>
inline double solve_row(int k, int top, int n, const int* stack, double* W, double dk, const Arrays& a, Touch touch) {
    for (int s = top; s < n; ++s) {
        const int i = stack[s];
        const double y = W[i];
        W[i] = 0;
        int p = a.Lp[i];
        const int pend = p + a.Lnz[i];
        const double di = a.Lx[p];
        for (++p; p < pend; ++p) {
            const int r = a.Li[p];
            touch(r);
            W[r] -= a.Lx[p] * y;
        }
        const double lx = y / di;
        dk -= lx * y;
        a.Li[pend] = k, a.Lx[pend] = lx, ++a.Lnz[i];
    }
    return dk;
}
}  // namespace

void SplitLDL::part_rows(int t, const cholmod_sparse& S, double beta, cholmod_factor& L) {
    Part& w = part_[t];
    const int r0 = t == 0 ? 0 : a_, r1 = t == 0 ? a_ : b_, n = n_, b = b_;
    const Arrays a(S, L);
    const int* parent = parent_.data();
    double* W = w.w.data();
    int* flag = w.flag.data();
    int* stack = w.stack.data();
    // Fresh workspace each time (O(n), against the factorization's O(flops)): a call that stopped early, at a zero
    // pivot or an exception, leaves entries behind.
    std::fill(w.w.begin(), w.w.end(), 0.0);
    std::fill(flag + r0, flag + r1, -1);
    std::fill(w.mark.begin(), w.mark.end(), -1);
    w.touched.clear();
    w.u_start.assign(1, 0);
    w.u_row.clear(), w.u_val.clear(), w.dk.clear();
    w.ok = true;
    // Rows of the part: t_cholmod_rowfac.c's loop for a symmetric upper S, LDL^T, with the elimination tree given.
    for (int k = r0; k < r1; ++k) {
        int top = n;
        flag[k] = k;
        for (int p = a.Sp[k]; p < a.Sp[k + 1]; ++p) {
            const int i = a.Si[p];
            if (i > k) break;
            W[i] = a.Sx[p];
            push_path(i, k, k, parent, flag, stack, top);
        }
        const double dk = W[k] + beta;
        W[k] = 0;
        const double d = solve_row(k, top, n, stack, W, dk, a, [](int) {});
        a.Li[a.Lp[k]] = k, a.Lx[a.Lp[k]] = d;
        if (d == 0) {
            w.ok = false;
            return;
        }
    }
    // The part's share of each separator row: the solve over its own columns, from column k's entries in its rows.
    // Updates that reach separator rows (all below k) are kept per row for separator_rows().
    for (int k = b; k < n; ++k) {
        int top = n;
        for (int p = a.Sp[k]; p < a.Sp[k + 1]; ++p) {
            const int i = a.Si[p];
            if (i < r0) continue;
            if (i >= r1) break;
            W[i] = a.Sx[p];
            push_path(i, r1, k, parent, flag, stack, top);
        }
        const double dk = solve_row(k, top, n, stack, W, 0.0, a, [&](int r) {
            if (r >= b && w.mark[r - b] != k) w.mark[r - b] = k, w.touched.push_back(r);
        });
        for (const int r : w.touched) w.u_row.push_back(r), w.u_val.push_back(W[r]), W[r] = 0;
        w.touched.clear();
        w.u_start.push_back(static_cast<int>(w.u_row.size()));
        w.dk.push_back(dk);
    }
}

bool SplitLDL::separator_rows(const cholmod_sparse& S, double beta, cholmod_factor& L) {
    const int n = n_, b = b_;
    const Arrays a(S, L);
    const int* parent = parent_.data();
    double* W = ws_.data();
    int* flag = fs_.data();
    int* stack = ss_.data();
    std::fill(ws_.begin(), ws_.end(), 0.0);
    std::fill(flag + b, flag + n, -1);
    for (int k = b; k < n; ++k) {
        int top = n;
        // The reach in S from the row's start nodes: column k's entries in S and the separator rows the parts updated
        // (the first separator ancestor of every part node in the row's reach is among those).
        for (int p = a.Sp[k]; p < a.Sp[k + 1]; ++p) {
            const int i = a.Si[p];
            if (i < b) continue;
            if (i > k) break;
            W[i] = a.Sx[p];
            push_path(i, k, k, parent, flag, stack, top);
        }
        for (const Part& w : part_)
            for (int u = w.u_start[k - b]; u < w.u_start[k - b + 1]; ++u) {
                W[w.u_row[u]] += w.u_val[u];
                push_path(w.u_row[u], k, k, parent, flag, stack, top);
            }
        double dk = W[k] + beta;
        W[k] = 0;
        dk += part_[0].dk[k - b];
        dk += part_[1].dk[k - b];
        dk = solve_row(k, top, n, stack, W, dk, a, [](int) {});
        a.Li[a.Lp[k]] = k, a.Lx[a.Lp[k]] = dk;
        if (dk == 0) return false;
    }
    return true;
}

bool SplitLDL::factorize(const cholmod_sparse& S, double beta, cholmod_factor& L, int threads) {
    std::fill(static_cast<int*>(L.nz), static_cast<int*>(L.nz) + n_, 1);  // every column holds its pivot only
    parallel_ranges(2, std::min(2, threads), [&](size_t lo, size_t hi) {
        for (size_t t = lo; t < hi; ++t) part_rows(static_cast<int>(t), S, beta, L);
    });
    return part_[0].ok && part_[1].ok && separator_rows(S, beta, L);
}

}  // namespace fibernet::detail
