#include "fibernet/solve/cholmod_llt.hpp"

#include <cholmod.h>

#include <cmath>
#include <stdexcept>

#include "cholmod_view.hpp"
#include "fibernet/util/blas_threads.hpp"
#include "fibernet/util/inline_openmp.hpp"

namespace fibernet {

struct CholmodLLT::Impl {
    cholmod_common c;
    cholmod_factor* L = nullptr;
    int n = -1;
    long nnz = -1;
    double flops = 0;  // of a numeric factorization, from the analysis
    bool ok = false;

    Impl() {
        cholmod_start(&c);
        c.supernodal = CHOLMOD_SUPERNODAL;
        c.print = 0;           // a non-PD matrix is an expected event of the Newton ladder, not a message
        c.quick_return_if_not_posdef = 1;
        c.error_handler = nullptr;
    }
    ~Impl() {
        if (L) cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
    }
};

namespace {
cholmod_sparse llt_view(const Eigen::SparseMatrix<double>& A) { return detail::cholmod_upper_view(A, "CholmodLLT"); }
}  // namespace

CholmodLLT::CholmodLLT() : impl_(std::make_unique<Impl>()) {}
CholmodLLT::~CholmodLLT() = default;

bool CholmodLLT::analyzed() const { return impl_->L != nullptr; }

void CholmodLLT::forget() {
    if (impl_->L) cholmod_free_factor(&impl_->L, &impl_->c);
    impl_->n = -1, impl_->nnz = -1, impl_->ok = false;
}

void CholmodLLT::analyze(const Eigen::SparseMatrix<double>& upper) {
    if (impl_->L) cholmod_free_factor(&impl_->L, &impl_->c);
    cholmod_sparse A = llt_view(upper);
    const InlineOpenMP on_this_thread;
    impl_->L = cholmod_analyze(&A, &impl_->c);
    if (!impl_->L) throw std::runtime_error("CHOLMOD symbolic analysis failed (status " + std::to_string(impl_->c.status) + ")");
    impl_->n = static_cast<int>(upper.rows());
    impl_->nnz = static_cast<long>(upper.nonZeros());
    impl_->flops = impl_->c.fl;
    impl_->ok = false;
}

bool CholmodLLT::factorize(const Eigen::SparseMatrix<double>& upper, double shift) {
    // A matrix of another size or fill than the analyzed one gets its own analysis (a caller reusing a wrapper
    // across models); same size and fill is taken as the same pattern.
    if (!impl_->L || upper.rows() != impl_->n || static_cast<long>(upper.nonZeros()) != impl_->nnz) analyze(upper);
    cholmod_sparse A = llt_view(upper);
    double beta[2] = {shift, 0.0};
    impl_->c.status = CHOLMOD_OK;
    const InlineOpenMP on_this_thread;  // its supernodal memory passes (inline_openmp.hpp)
    const BlasThreads blas(impl_->flops);
    const int r = cholmod_factorize_p(&A, beta, nullptr, 0, impl_->L, &impl_->c);
    impl_->ok = r && impl_->c.status == CHOLMOD_OK && impl_->L->minor == impl_->L->n;
    return impl_->ok;
}

Eigen::VectorXd CholmodLLT::solve(const Eigen::VectorXd& b) const {
    const Eigen::MatrixXd B = b;
    return solve_many(B).col(0);
}

Eigen::MatrixXd CholmodLLT::solve_many(const Eigen::MatrixXd& b) const {
    if (!impl_->ok) throw std::logic_error("CholmodLLT::solve without a successful factorization");
    Eigen::MatrixXd x(b.rows(), b.cols());
    if (b.size() == 0) return x;
    cholmod_dense B{};
    B.nrow = B.d = static_cast<size_t>(b.rows());
    B.ncol = static_cast<size_t>(b.cols());
    B.nzmax = B.nrow * B.ncol;
    B.x = const_cast<double*>(b.data());
    B.xtype = CHOLMOD_REAL;
    B.dtype = CHOLMOD_DOUBLE;
    const InlineOpenMP on_this_thread;
    const BlasThreads blas(impl_->flops);
    cholmod_dense* X = cholmod_solve(CHOLMOD_A, impl_->L, &B, &impl_->c);
    if (!X) throw std::runtime_error("CHOLMOD solve failed (status " + std::to_string(impl_->c.status) + ")");
    std::copy(static_cast<double*>(X->x), static_cast<double*>(X->x) + b.size(), x.data());
    cholmod_free_dense(&X, &impl_->c);
    return x;
}

}  // namespace fibernet
