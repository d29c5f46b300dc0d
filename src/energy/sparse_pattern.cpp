#include "fibernet/energy/sparse_pattern.hpp"

#include <algorithm>
#include <stdexcept>

namespace fibernet {

Eigen::SparseMatrix<double> PatternBuilder::build() const {
    // visit(r, c) for every entry of every source (r <= c).
    auto each = [&](auto visit) {
        for (const auto* P : patterns_)
            for (int c = 0; c < P->outerSize(); ++c)
                for (int k = P->outerIndexPtr()[c]; k < P->outerIndexPtr()[c + 1]; ++k) visit(P->innerIndexPtr()[k], c);
        for (const Elements& el : elements_) {
            const std::vector<int>& idx = *el.idx;
            const int M = el.M;
            for (size_t e = 0; e < idx.size(); e += M)
                for (int b = 0; b < M; ++b) {
                    const int c = idx[e + b];
                    if (c < 0) continue;
                    for (int a = 0; a < M; ++a) {
                        const int r = idx[e + a];
                        if (r >= 0 && r <= c) visit(r, c);
                    }
                }
        }
        if (diagonal_)
            for (int c = 0; c < n_; ++c) visit(c, c);
    };
    std::vector<long> start(static_cast<size_t>(n_) + 1, 0);
    each([&](int, int c) { ++start[c + 1]; });
    for (int c = 0; c < n_; ++c) start[c + 1] += start[c];
    std::vector<int> rows(static_cast<size_t>(start[n_]));
    {
        std::vector<long> next(start.begin(), start.end() - 1);
        each([&](int r, int c) { rows[next[c]++] = r; });
    }
    std::vector<int> outer(static_cast<size_t>(n_) + 1, 0), inner;
    inner.reserve(rows.size() / 2);
    // Repeats dropped before the sort (elements that share coordinates repeat entries many times over).
    std::vector<int> seen(static_cast<size_t>(n_), -1);
    for (int c = 0; c < n_; ++c) {
        const size_t b = inner.size();
        for (long k = start[c]; k < start[c + 1]; ++k)
            if (seen[rows[k]] != c) seen[rows[k]] = c, inner.push_back(rows[k]);
        std::sort(inner.begin() + static_cast<long>(b), inner.end());
        outer[c + 1] = static_cast<int>(inner.size());
    }
    std::vector<double> zeros(inner.size(), 0.0);
    Eigen::SparseMatrix<double> P = Eigen::Map<const Eigen::SparseMatrix<double>>(
        n_, n_, static_cast<Eigen::Index>(inner.size()), outer.data(), inner.data(), zeros.data());
    P.makeCompressed();
    return P;
}

bool same_pattern(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& B) {
    return A.rows() == B.rows() && A.cols() == B.cols() && A.nonZeros() == B.nonZeros() &&
           A.isCompressed() && B.isCompressed() &&
           std::equal(A.outerIndexPtr(), A.outerIndexPtr() + A.cols() + 1, B.outerIndexPtr()) &&
           std::equal(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), B.innerIndexPtr());
}

int pattern_slot(const Eigen::SparseMatrix<double>& P, int r, int c) {
    const int* in = P.innerIndexPtr();
    const int b = P.outerIndexPtr()[c], e = P.outerIndexPtr()[c + 1];
    const int* it = std::lower_bound(in + b, in + e, r);
    if (it == in + e || *it != r) throw std::logic_error("hessian pattern lacks an entry");
    return static_cast<int>(it - in);
}

int find_slot(const Eigen::SparseMatrix<double>& P, int r, int c) {
    if (r > c) std::swap(r, c);
    const int* in = P.innerIndexPtr();
    const int b = P.outerIndexPtr()[c], e = P.outerIndexPtr()[c + 1];
    const int* it = std::lower_bound(in + b, in + e, r);
    return it != in + e && *it == r ? static_cast<int>(it - in) : -1;
}

bool add_outer_product(const Eigen::SparseMatrix<double>& P, std::vector<std::pair<int, double>>& G, double kappa,
                       double* hv) {
    std::sort(G.begin(), G.end(), [](const auto& u, const auto& v) { return u.first < v.first; });
    size_t w = 0;
    for (size_t r = 0; r < G.size(); ++r) {
        if (w > 0 && G[w - 1].first == G[r].first) G[w - 1].second += G[r].second;
        else G[w++] = G[r];
    }
    G.resize(w);
    bool complete = true;
    for (size_t v = 0; v < G.size(); ++v)
        for (size_t u = 0; u <= v; ++u) {
            const int slot = find_slot(P, G[u].first, G[v].first);
            if (slot < 0) {
                complete = false;
                continue;
            }
            hv[slot] += kappa * G[u].second * G[v].second;
        }
    return complete;
}

void element_slots(const Eigen::SparseMatrix<double>& P, const std::vector<int>& idx, int M, std::vector<int>& out,
                   std::vector<char>* lacking) {
    const int n = static_cast<int>(P.cols());
    const size_t ne = idx.size() / M;
    out.assign(ne * M * M, -1);
    if (lacking) lacking->assign(ne, 0);
    // The (element, b) pairs of each column, by counting sort.
    std::vector<int> start(n + 1, 0);
    for (int c : idx)
        if (c >= 0) {
            if (c >= n) throw std::logic_error("hessian pattern lacks an entry");
            ++start[c + 1];
        }
    for (int c = 0; c < n; ++c) start[c + 1] += start[c];
    std::vector<int> at(start.begin(), start.end() - 1), list(start[n]);
    for (size_t k = 0; k < idx.size(); ++k)
        if (idx[k] >= 0) list[at[idx[k]]++] = static_cast<int>(k);
    // Column by column: each row's slot scattered into pos, read by every element entry of the column.
    std::vector<int> pos(n, -1);
    const int* outer = P.outerIndexPtr();
    const int* inner = P.innerIndexPtr();
    for (int c = 0; c < n; ++c) {
        for (int k = outer[c]; k < outer[c + 1]; ++k) pos[inner[k]] = k;
        for (int j = start[c]; j < start[c + 1]; ++j) {
            const size_t e = static_cast<size_t>(list[j]) / M;
            const int b = list[j] % M;
            for (int a = 0; a < M; ++a) {
                const int r = idx[e * M + a];
                if (r < 0 || r > c) continue;
                if (pos[r] < 0) {
                    if (!lacking) throw std::logic_error("hessian pattern lacks an entry");
                    (*lacking)[e] = 1;
                    continue;
                }
                out[e * M * M + a * M + b] = pos[r];
            }
        }
        for (int k = outer[c]; k < outer[c + 1]; ++k) pos[inner[k]] = -1;
    }
}

std::vector<int> subpattern_slots(const Eigen::SparseMatrix<double>& P, const Eigen::SparseMatrix<double>& S) {
    const int n = static_cast<int>(P.cols());
    if (S.cols() != n || S.rows() != P.rows()) throw std::logic_error("hessian pattern lacks an entry");
    std::vector<int> out;
    out.reserve(S.nonZeros());
    std::vector<int> pos(n, -1);
    const int *po = P.outerIndexPtr(), *pi = P.innerIndexPtr(), *so = S.outerIndexPtr(), *si = S.innerIndexPtr();
    for (int c = 0; c < n; ++c) {
        for (int k = po[c]; k < po[c + 1]; ++k) pos[pi[k]] = k;
        for (int k = so[c]; k < so[c + 1]; ++k) {
            if (pos[si[k]] < 0) throw std::logic_error("hessian pattern lacks an entry");
            out.push_back(pos[si[k]]);
        }
        for (int k = po[c]; k < po[c + 1]; ++k) pos[pi[k]] = -1;
    }
    return out;
}

}  // namespace fibernet
