#include "fibernet/solve/cholmod_ldl.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "cholmod_view.hpp"

namespace fibernet {

struct CholmodLDL::Impl {
    cholmod_common c;
    cholmod_factor* L = nullptr;  // of S = P A P^T in its natural order (L->Perm is the identity)
    // The fill-reducing P (perm[k]: the row of A eliminated k-th) and the upper triangle of S, which
    // cholmod_factorize_p takes as is (cholmod_view.hpp), without transposing it twice per call.
    std::vector<int> perm;
    detail::PermutedTriangle S;  // as many entries as the analyzed A
    bool ok = false;
    int negative = 0;
    double min_pivot = 0;

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
cholmod_sparse view(const Eigen::SparseMatrix<double>& A) { return detail::cholmod_upper_view(A, "CholmodLDL"); }

cholmod_dense dense_view(Eigen::VectorXd& v) {
    cholmod_dense d{};
    d.nrow = d.d = d.nzmax = static_cast<size_t>(v.size());
    d.ncol = 1;
    d.x = v.data();
    d.xtype = CHOLMOD_REAL;
    d.dtype = CHOLMOD_DOUBLE;
    return d;
}
}  // namespace

CholmodLDL::CholmodLDL() : impl_(std::make_unique<Impl>()) {}
CholmodLDL::~CholmodLDL() = default;

bool CholmodLDL::analyzed() const { return impl_->L != nullptr; }

void CholmodLDL::analyze(const Eigen::SparseMatrix<double>& upper) {
    Impl& m = *impl_;
    if (m.L) cholmod_free_factor(&m.L, &m.c);
    m.ok = false;
    // CHOLMOD's choice of fill-reducing order (its default methods, then the postorder of the elimination tree).
    cholmod_sparse A = view(upper);
    cholmod_factor* L0 = cholmod_analyze(&A, &m.c);
    if (!L0) throw std::runtime_error("CHOLMOD symbolic analysis failed (status " + std::to_string(m.c.status) + ")");
    const int n = static_cast<int>(upper.rows());
    m.perm.assign(static_cast<const int*>(L0->Perm), static_cast<const int*>(L0->Perm) + n);
    cholmod_free_factor(&L0, &m.c);
    m.S = detail::PermutedTriangle(upper, m.perm);
    cholmod_sparse S = m.S.view();
    m.L = detail::analyze_natural(S, m.c);
    if (!m.L) throw std::runtime_error("CHOLMOD symbolic analysis failed (status " + std::to_string(m.c.status) + ")");
}

bool CholmodLDL::factorize(const Eigen::SparseMatrix<double>& upper, double shift) {
    // A matrix of another size is analyzed first; one of the same size is taken to have the analyzed pattern.
    if (!impl_->L || impl_->L->n != static_cast<size_t>(upper.rows())) analyze(upper);
    Impl& m = *impl_;
    if (!upper.isCompressed() || upper.nonZeros() != m.S.nonzeros())
        throw std::logic_error("CholmodLDL::factorize: the matrix is not compressed or not of the analyzed pattern");
    m.S.gather(upper);
    cholmod_sparse S = m.S.view();
    double beta[2] = {shift, 0.0};
    m.c.status = CHOLMOD_OK;
    const int r = cholmod_factorize_p(&S, beta, nullptr, 0, m.L, &m.c);
    const cholmod_factor* L = impl_->L;
    impl_->ok = r && impl_->c.status == CHOLMOD_OK && L->minor == L->n && !L->is_ll && !L->is_super;
    impl_->negative = 0;
    impl_->min_pivot = std::numeric_limits<double>::infinity();
    if (!impl_->ok) return false;
    const double* x = static_cast<const double*>(L->x);
    const int* p = static_cast<const int*>(L->p);
    for (size_t j = 0; j < L->n; ++j) {
        const double d = x[p[j]];  // simplicial LDL^T: D_j is the first entry of column j
        if (!std::isfinite(d) || d == 0) return impl_->ok = false;
        impl_->negative += d < 0;
        impl_->min_pivot = std::min(impl_->min_pivot, d);
    }
    return true;
}

int CholmodLDL::negative_pivots() const { return impl_->negative; }
double CholmodLDL::min_pivot() const { return impl_->min_pivot; }

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
