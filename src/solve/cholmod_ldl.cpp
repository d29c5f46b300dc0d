#include "fibernet/solve/cholmod_ldl.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "cholmod_view.hpp"
#include "split_ldl.hpp"
#include "fibernet/util/parallel.hpp"

namespace fibernet {

struct CholmodLDL::Impl {
    cholmod_common c;
    int split_min = kSplitMin;
    int a = 0, b = 0;        // independent row ranges [0, a) and [a, b) of the analyzed order (0, 0: none)
    detail::SplitLDL split;  // the numeric factorization in that order (b > 0)
    cholmod_factor* L = nullptr;  // of S = P A P^T in its natural order (L->Perm is the identity)
    // The fill-reducing P (perm[k]: the row of A eliminated k-th) and the upper triangle of S, which
    // cholmod_factorize_p takes as is (cholmod_view.hpp), without transposing it twice per call.
    std::vector<int> perm;
    detail::PermutedTriangle S;  // as many entries as the analyzed A
    bool ok = false;
    int negative = 0;
    double min_pivot = 0;
    double shift = 0;  // of the last factorize(): solve()'s floor

    Impl() {
        cholmod_start(&c);
        c.supernodal = CHOLMOD_SIMPLICIAL;  // CHOLMOD's supernodal factorization is LL^T only
        c.final_ll = 0;
        c.print = 0;
        c.error_handler = nullptr;
    }
    ~Impl() {
        if (L) cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
    }
};

namespace {
cholmod_sparse ldl_view(const Eigen::SparseMatrix<double>& A) { return detail::cholmod_upper_view(A, "CholmodLDL"); }

cholmod_dense dense_view(Eigen::VectorXd& v) {
    cholmod_dense d{};
    d.nrow = d.d = d.nzmax = static_cast<size_t>(v.size());
    d.ncol = 1;
    d.x = v.data();
    d.xtype = CHOLMOD_REAL;
    d.dtype = CHOLMOD_DOUBLE;
    return d;
}

// The pattern of the rows and columns r of the upper triangle `upper` with set[r] == which, renumbered in order
// (`rows`: their indices in `upper`), as a pattern-only upper triangle for cholmod_bisect.
struct SubPattern {
    std::vector<int> p, i, rows;
    SubPattern(const Eigen::SparseMatrix<double>& upper, const std::vector<int>& set, int which) {
        const int n = static_cast<int>(upper.rows());
        std::vector<int> local(n, -1);
        for (int r = 0; r < n; ++r)
            if (set[r] == which) local[r] = static_cast<int>(rows.size()), rows.push_back(r);
        p.assign(rows.size() + 1, 0);
        for (size_t c = 0; c < rows.size(); ++c) {
            const int j = rows[c];
            for (int k = upper.outerIndexPtr()[j]; k < upper.outerIndexPtr()[j + 1]; ++k)
                if (local[upper.innerIndexPtr()[k]] >= 0) i.push_back(local[upper.innerIndexPtr()[k]]);
            p[c + 1] = static_cast<int>(i.size());
        }
    }
    cholmod_sparse view() {
        cholmod_sparse s{};
        s.nrow = s.ncol = rows.size();
        s.nzmax = i.size();
        s.p = p.data(), s.i = i.data();
        s.stype = 1, s.itype = CHOLMOD_INT, s.xtype = CHOLMOD_PATTERN, s.dtype = CHOLMOD_DOUBLE;
        s.sorted = 1, s.packed = 1;
        return s;
    }
};

// The two-thread order of CholmodLDL (see the header): perm, and the ends a <= b of A's and B's rows in it. False
// (nothing usable) if CHOLMOD cannot bisect (built without METIS, or a graph it cannot split) or the result is not an
// order with independent parts (checked here, since the factorization's threads rely on it).
bool order_for_two(const Eigen::SparseMatrix<double>& upper, cholmod_common& c, std::vector<int>& perm, int& a, int& b) {
    const int n = static_cast<int>(upper.rows());
    cholmod_sparse A = ldl_view(upper);
    std::vector<int> part(n);
    if (cholmod_bisect(&A, nullptr, 0, 1, part.data(), &c) < 0 || c.status != CHOLMOD_OK) {
        c.status = CHOLMOD_OK;
        return false;
    }
    // Constraint sets for CAMD: A's parts 0-2, B's 3-5 (each bisected once more: two parts and their separator),
    // S 6.
    std::vector<int> member(n);
    int count[2] = {0, 0};
    for (int r = 0; r < n; ++r) {
        member[r] = part[r] == 2 ? 6 : 3 * part[r];
        if (part[r] < 2) ++count[part[r]];
    }
    if (count[0] == 0 || count[1] == 0) return false;
    for (int h = 0; h < 2; ++h) {
        SubPattern sub(upper, part, h);
        cholmod_sparse As = sub.view();
        std::vector<int> half(sub.rows.size());
        if (cholmod_bisect(&As, nullptr, 0, 1, half.data(), &c) < 0 || c.status != CHOLMOD_OK) {
            c.status = CHOLMOD_OK;  // this half stays one set
            continue;
        }
        for (size_t k = 0; k < sub.rows.size(); ++k) member[sub.rows[k]] = 3 * h + half[k];
    }
    perm.resize(n);
    if (!cholmod_camd(&A, nullptr, 0, member.data(), perm.data(), &c) || c.status != CHOLMOD_OK) {
        c.status = CHOLMOD_OK;
        return false;
    }
    auto side = [&](int r) { return member[r] < 3 ? 0 : member[r] < 6 ? 1 : 2; };
    for (int k = 1; k < n; ++k)
        if (member[perm[k]] < member[perm[k - 1]]) return false;
    for (int j = 0; j < n; ++j)
        for (int k = upper.outerIndexPtr()[j]; k < upper.outerIndexPtr()[j + 1]; ++k)
            if (side(upper.innerIndexPtr()[k]) + side(j) == 1) return false;  // an entry between A and B
    a = count[0], b = count[0] + count[1];
    return true;
}
}  // namespace

CholmodLDL::CholmodLDL(int split_min) : impl_(std::make_unique<Impl>()) { impl_->split_min = split_min; }
CholmodLDL::~CholmodLDL() = default;

bool CholmodLDL::analyzed() const { return impl_->L != nullptr; }

void CholmodLDL::forget() {
    Impl& m = *impl_;
    if (m.L) cholmod_free_factor(&m.L, &m.c);
    m.ok = false, m.a = m.b = 0;
}

void CholmodLDL::analyze(const Eigen::SparseMatrix<double>& upper) {
    Impl& m = *impl_;
    if (m.L) cholmod_free_factor(&m.L, &m.c);
    m.ok = false;
    const int n = static_cast<int>(upper.rows());
    m.a = m.b = 0;
    if (n < m.split_min || !order_for_two(upper, m.c, m.perm, m.a, m.b)) {
        m.a = m.b = 0;
        // CHOLMOD's choice of fill-reducing order (its default methods, then the postorder of the elimination tree).
        cholmod_sparse A = ldl_view(upper);
        cholmod_factor* L0 = cholmod_analyze(&A, &m.c);
        if (!L0) throw std::runtime_error("CHOLMOD symbolic analysis failed (status " + std::to_string(m.c.status) + ")");
        m.perm.assign(static_cast<const int*>(L0->Perm), static_cast<const int*>(L0->Perm) + n);
        cholmod_free_factor(&L0, &m.c);
    }
    m.S = detail::PermutedTriangle(upper, m.perm);
    cholmod_sparse S = m.S.view();
    m.L = detail::analyze_natural(S, m.c);
    if (!m.L) throw std::runtime_error("CHOLMOD symbolic analysis failed (status " + std::to_string(m.c.status) + ")");
    if (m.b > 0) {
        std::vector<int> parent(n);
        if (!cholmod_etree(&S, parent.data(), &m.c)) {
            cholmod_free_factor(&m.L, &m.c);  // not analyzed: the next factorize() analyzes again
            m.a = m.b = 0;
            throw std::runtime_error("CHOLMOD elimination tree failed (status " + std::to_string(m.c.status) + ")");
        }
        m.split.setup(n, m.a, m.b, std::move(parent));
    }
}

bool CholmodLDL::factorize(const Eigen::SparseMatrix<double>& upper, double shift) {
    // A matrix of another size is analyzed first; one of the same size is taken to have the analyzed pattern.
    if (!impl_->L || impl_->L->n != static_cast<size_t>(upper.rows())) analyze(upper);
    Impl& m = *impl_;
    if (!upper.isCompressed() || upper.nonZeros() != m.S.nonzeros())
        throw std::logic_error("CholmodLDL::factorize: the matrix is not compressed or not of the analyzed pattern");
    m.S.gather(upper);
    cholmod_sparse S = m.S.view();
    m.shift = shift;
    double beta[2] = {shift, 0.0};
    m.c.status = CHOLMOD_OK;
    m.ok = false, m.negative = 0, m.min_pivot = std::numeric_limits<double>::infinity();  // until this one succeeds
    int r = 0;
    if (m.b > 0) {
        // The parts' rows on two threads, then the separator's (split_ldl.hpp), into CHOLMOD's numeric factor.
        cholmod_factor* L = m.L;
        if (L->xtype == CHOLMOD_PATTERN && !cholmod_change_factor(CHOLMOD_REAL, false, false, false, true, L, &m.c))
            return m.ok = false;
        L->minor = L->n;
        r = m.split.factorize(S, shift, *L, thread_count());
    } else {
        r = cholmod_factorize_p(&S, beta, nullptr, 0, m.L, &m.c);
    }
    const cholmod_factor* L = m.L;
    m.ok = r && m.c.status == CHOLMOD_OK && L->minor == L->n && !L->is_ll && !L->is_super;
    if (!m.ok) return false;
    const double* x = static_cast<const double*>(L->x);
    const int* p = static_cast<const int*>(L->p);
    for (size_t j = 0; j < L->n; ++j) {
        const double d = x[p[j]];  // simplicial LDL^T: D_j is the first entry of column j
        if (!std::isfinite(d) || d == 0) return m.ok = false;
        m.negative += d < 0;
        m.min_pivot = std::min(m.min_pivot, d);
    }
    return true;
}

int CholmodLDL::split_a() const { return impl_->a; }
int CholmodLDL::split_b() const { return impl_->b; }
const std::vector<int>& CholmodLDL::order() const { return impl_->perm; }

Eigen::VectorXd CholmodLDL::pivots() const {
    if (!impl_->ok) throw std::logic_error("CholmodLDL::pivots without a successful factorization");
    const cholmod_factor* L = impl_->L;
    Eigen::VectorXd d(static_cast<Eigen::Index>(L->n));
    for (size_t j = 0; j < L->n; ++j) d[j] = static_cast<const double*>(L->x)[static_cast<const int*>(L->p)[j]];
    return d;
}

int CholmodLDL::negative_pivots() const { return impl_->negative; }
double CholmodLDL::min_pivot() const { return impl_->min_pivot; }

Eigen::VectorXd CholmodLDL::solve(const Eigen::VectorXd& b) const {
    return solve_modified(b, impl_->shift > 0 ? impl_->shift : std::numeric_limits<double>::min());
}

Eigen::VectorXd CholmodLDL::solve_modified(const Eigen::VectorXd& b, double floor) const {
    if (!impl_->ok) throw std::logic_error("CholmodLDL::solve_modified without a successful factorization");
    const cholmod_factor* L = impl_->L;
    const std::vector<int>& perm = impl_->perm;
    const Eigen::Index n = b.size();
    if (n != static_cast<Eigen::Index>(perm.size())) throw std::logic_error("CholmodLDL::solve_modified: wrong size");
    Eigen::VectorXd v(n);
    for (Eigen::Index k = 0; k < n; ++k) v[k] = b[perm[k]];  // P b
    auto apply = [&](int sys) {
        cholmod_dense B = dense_view(v);
        cholmod_dense* X = cholmod_solve(sys, const_cast<cholmod_factor*>(L), &B, &impl_->c);
        if (!X) throw std::runtime_error("CHOLMOD solve failed (status " + std::to_string(impl_->c.status) + ")");
        std::copy(static_cast<double*>(X->x), static_cast<double*>(X->x) + v.size(), v.data());
        cholmod_free_dense(&X, &impl_->c);
    };
    apply(CHOLMOD_L);
    const double* x = static_cast<const double*>(L->x);
    const int* p = static_cast<const int*>(L->p);
    for (size_t j = 0; j < L->n; ++j) v[j] /= std::max(std::abs(x[p[j]]), floor);
    apply(CHOLMOD_Lt);
    Eigen::VectorXd out(n);
    for (Eigen::Index k = 0; k < n; ++k) out[perm[k]] = v[k];  // P^T
    return out;
}

}  // namespace fibernet
