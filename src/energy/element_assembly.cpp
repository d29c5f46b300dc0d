#include "fibernet/energy/element_assembly.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/parallel.hpp"

namespace fibernet {

namespace {
int upper_count(int m) { return m * (m + 1) / 2; }

// Below this many elements one thread assembles (starting threads would cost more than it saves).
constexpr std::size_t kParallelElements = 4096;

// Counting sort of (target, source) pairs into compressed lists that keep the sources' given order per target.
void compress(std::size_t targets, const std::vector<std::pair<std::size_t, std::size_t>>& pairs,
              std::vector<std::size_t>& ptr, std::vector<std::uint32_t>& src) {
    ptr.assign(targets + 1, 0);
    for (const auto& p : pairs) ++ptr[p.first + 1];
    for (std::size_t t = 0; t < targets; ++t) ptr[t + 1] += ptr[t];
    src.resize(pairs.size());
    std::vector<std::size_t> fill(ptr.begin(), ptr.end() - 1);
    for (const auto& p : pairs) src[fill[p.first]++] = static_cast<std::uint32_t>(p.second);
}

// The upper pattern: node adjacency over elements (each node with itself), then coordinate level column by column.
Eigen::SparseMatrix<double> element_pattern(const std::vector<const ElementTerm*>& terms, const std::vector<int>& dof,
                                            int ndof) {
    const int n = static_cast<int>(dof.size() / 2);
    std::vector<std::vector<int>> adj(n);
    for (int i = 0; i < n; ++i) adj[i].push_back(i);
    int nodes[kMaxElementCoords / 2];
    for (const ElementTerm* t : terms)
        for (std::size_t e = 0; e < t->size(); ++e) {
            t->nodes(e, nodes);
            for (int a = 0; a < t->valence(); ++a)
                for (int b = a + 1; b < t->valence(); ++b)
                    adj[std::max(nodes[a], nodes[b])].push_back(std::min(nodes[a], nodes[b]));
        }
    std::vector<int> outer(ndof + 1, 0), inner;
    for (int J = 0; J < n; ++J) {
        auto& a = adj[J];
        std::sort(a.begin(), a.end());
        a.erase(std::unique(a.begin(), a.end()), a.end());
        for (int cj = 0; cj < 2; ++cj) {
            const int col = dof[2 * J + cj];
            if (col < 0) continue;
            for (int I : a)
                for (int ci = 0; ci < 2; ++ci) {
                    const int row = dof[2 * I + ci];
                    if (row >= 0 && row <= col) inner.push_back(row);
                }
            outer[col + 1] = static_cast<int>(inner.size());
        }
    }
    std::vector<double> zeros(inner.size(), 0.0);
    Eigen::SparseMatrix<double> P = Eigen::Map<const Eigen::SparseMatrix<double>>(
        ndof, ndof, static_cast<Eigen::Index>(inner.size()), outer.data(), inner.data(), zeros.data());
    P.makeCompressed();
    return P;
}

// Per-element results of one evaluation, kept per calling thread between evaluations (a large network's Hessian
// buffer is ~1e8 bytes: allocating it anew each time costs its page faults).
struct Buffers {
    std::vector<double> energy, gradient, upper, dE_dt, d2E_dt2, d2E_dqdt;
};
Buffers& buffers() {
    thread_local Buffers b;
    return b;
}
}  // namespace

ElementAssembly::ElementAssembly(std::vector<const ElementTerm*> terms, const std::vector<int>& dof, int ndof)
    : terms_(std::move(terms)), ndof_(ndof) {
    first_ = {0}, coord_offset_ = {0}, upper_offset_ = {0};
    for (const ElementTerm* t : terms_) {
        if (t->valence() < 1 || 2 * t->valence() > kMaxElementCoords)
            throw std::logic_error(std::string("element term ") + t->name() + ": unsupported valence");
        first_.push_back(first_.back() + t->size());
        coord_offset_.push_back(coord_offset_.back() + t->size() * 2 * t->valence());
        upper_offset_.push_back(upper_offset_.back() + t->size() * upper_count(2 * t->valence()));
    }
    if (upper_offset_.back() > UINT32_MAX) throw std::length_error("element assembly: more than 2^32 Hessian entries");
    pattern_ = element_pattern(terms_, dof, ndof);
    std::vector<std::pair<std::size_t, std::size_t>> grad, hess;
    int nodes[kMaxElementCoords / 2];
    for (std::size_t k = 0; k < terms_.size(); ++k) {
        const ElementTerm* t = terms_[k];
        const int M = 2 * t->valence();
        for (std::size_t e = 0; e < t->size(); ++e) {
            t->nodes(e, nodes);
            for (int a = 0; a < t->valence(); ++a)
                for (int b = a + 1; b < t->valence(); ++b)
                    if (nodes[a] == nodes[b]) throw std::logic_error("an element uses one node twice");
            const std::size_t g0 = coord_offset_[k] + e * M, h0 = upper_offset_[k] + e * upper_count(M);
            std::size_t s = 0;
            for (int a = 0; a < M; ++a) {
                const int r = dof[2 * nodes[a / 2] + a % 2];
                coord_index_.push_back(r);
                if (r >= 0) grad.push_back({static_cast<std::size_t>(r), g0 + a});
                for (int b = a; b < M; ++b, ++s) {
                    const int c = dof[2 * nodes[b / 2] + b % 2];
                    const int slot = r < 0 || c < 0 ? -1 : pattern_slot(pattern_, std::min(r, c), std::max(r, c));
                    upper_slot_.push_back(slot);
                    if (slot >= 0) hess.push_back({static_cast<std::size_t>(slot), h0 + s});
                }
            }
        }
    }
    compress(ndof, grad, grad_ptr_, grad_src_);
    compress(pattern_.nonZeros(), hess, hess_ptr_, hess_src_);
}

// One thread: each element's results added where they go as it is evaluated (the loop the dry energy had), which
// makes every sum in the same order as the gathers below.
void ElementAssembly::scatter_serially(const ElementFrame& frame, const ElementWant& want, Sums& sums,
                                       Eigen::VectorXd* gradient, Eigen::VectorXd* d2E_dqdt,
                                       double* hessian_values) const {
    const bool wg = want.gradient && gradient, wh = want.hessian && hessian_values, ws = want.strain;
    const bool wt = ws && d2E_dqdt;
    if (wg) gradient->setZero(ndof_);
    if (wt) d2E_dqdt->setZero(ndof_);
    if (wh) std::fill(hessian_values, hessian_values + pattern_.nonZeros(), 0.0);
    ElementWant w = want;
    w.gradient = wg, w.hessian = wh;
    sums.energy.assign(terms_.size(), 0.0);
    sums.dE_dt = sums.d2E_dt2 = sums.d2E_dt2_size = 0;
    ElementResult r;
    for (std::size_t k = 0; k < terms_.size(); ++k) {
        const ElementTerm* t = terms_[k];
        const int M = 2 * t->valence(), U = upper_count(M);
        // data() + offset, not &v[offset]: a term with no elements may end the arrays (or leave them empty), and
        // operator[] one past the end is undefined even when nothing is read through it.
        const int* idx = coord_index_.data() + coord_offset_[k];
        const int* slot = upper_slot_.data() + upper_offset_[k];
        for (std::size_t e = 0; e < t->size(); ++e, idx += M, slot += U) {
            t->evaluate(e, frame, w, r);
            sums.energy[k] += r.energy;
            if (ws) {
                sums.dE_dt += r.dE_dt;
                sums.d2E_dt2 += r.d2E_dt2;
                sums.d2E_dt2_size += std::abs(r.d2E_dt2);
            }
            for (int a = 0; a < M; ++a) {
                if (idx[a] < 0) continue;
                if (wg) (*gradient)[idx[a]] += r.gradient[a];
                if (wt) (*d2E_dqdt)[idx[a]] += r.d2E_dqdt[a];
            }
            if (!wh) continue;
            int s = 0;
            for (int a = 0; a < M; ++a)
                for (int b = a; b < M; ++b, ++s)
                    if (slot[s] >= 0) hessian_values[slot[s]] += r.hessian(a, b);
        }
    }
}

void ElementAssembly::assemble(const ElementFrame& frame, const ElementWant& want, Sums& sums,
                               Eigen::VectorXd* gradient, Eigen::VectorXd* d2E_dqdt, double* hessian_values) const {
    const std::size_t n = first_.back();
    const int threads = n >= kParallelElements ? thread_count() : 1;
    if (threads <= 1) {
        scatter_serially(frame, want, sums, gradient, d2E_dqdt, hessian_values);
        return;
    }
    const bool wg = want.gradient && gradient, wh = want.hessian && hessian_values, ws = want.strain;
    Buffers& buf = buffers();
    buf.energy.resize(n);
    if (wg) buf.gradient.resize(coord_offset_.back());
    if (wh) buf.upper.resize(upper_offset_.back());
    if (ws) buf.dE_dt.resize(n), buf.d2E_dt2.resize(n), buf.d2E_dqdt.resize(coord_offset_.back());
    ElementWant w = want;
    w.gradient = wg, w.hessian = wh;
    parallel_ranges(n, threads, [&](std::size_t lo, std::size_t hi) {
        std::size_t k = std::upper_bound(first_.begin(), first_.end(), lo) - first_.begin() - 1;
        ElementResult r;
        for (std::size_t i = lo; i < hi; ++i) {
            while (i >= first_[k + 1]) ++k;
            const ElementTerm* t = terms_[k];
            const std::size_t e = i - first_[k];
            const int M = 2 * t->valence();
            t->evaluate(e, frame, w, r);
            buf.energy[i] = r.energy;
            if (wg) std::copy(r.gradient.data(), r.gradient.data() + M, &buf.gradient[coord_offset_[k] + e * M]);
            if (ws) {
                buf.dE_dt[i] = r.dE_dt, buf.d2E_dt2[i] = r.d2E_dt2;
                std::copy(r.d2E_dqdt.data(), r.d2E_dqdt.data() + M, &buf.d2E_dqdt[coord_offset_[k] + e * M]);
            }
            if (wh) {
                double* u = &buf.upper[upper_offset_[k] + e * upper_count(M)];
                for (int a = 0; a < M; ++a)
                    for (int b = a; b < M; ++b) *u++ = r.hessian(a, b);
            }
        }
    });
    // Gathers: each target sums its contributions in order, starting from 0 as a scatter into zeros would.
    const std::size_t ng = wg ? ndof_ : 0, nt = ws && d2E_dqdt ? ndof_ : 0,
                      nh = wh ? static_cast<std::size_t>(pattern_.nonZeros()) : 0;
    if (wg) gradient->resize(ndof_);
    if (nt) d2E_dqdt->resize(ndof_);
    parallel_ranges(ng + nt + nh, threads, [&](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) {
            const bool g = i < ng, t = !g && i < ng + nt;
            const std::size_t r = g ? i : t ? i - ng : i - ng - nt;
            const std::vector<std::size_t>& ptr = g || t ? grad_ptr_ : hess_ptr_;
            const std::vector<std::uint32_t>& src = g || t ? grad_src_ : hess_src_;
            const std::vector<double>& from = g ? buf.gradient : t ? buf.d2E_dqdt : buf.upper;
            double s = 0.0;
            for (std::size_t j = ptr[r]; j < ptr[r + 1]; ++j) s += from[src[j]];
            if (g) (*gradient)[r] = s;
            else if (t) (*d2E_dqdt)[r] = s;
            else hessian_values[r] = s;
        }
    });
    sums.energy.assign(terms_.size(), 0.0);
    sums.dE_dt = sums.d2E_dt2 = sums.d2E_dt2_size = 0;
    for (std::size_t k = 0; k < terms_.size(); ++k)
        for (std::size_t i = first_[k]; i < first_[k + 1]; ++i) {
            sums.energy[k] += buf.energy[i];
            if (!ws) continue;
            sums.dE_dt += buf.dE_dt[i];
            sums.d2E_dt2 += buf.d2E_dt2[i];
            sums.d2E_dt2_size += std::abs(buf.d2E_dt2[i]);
        }
}

}  // namespace fibernet
