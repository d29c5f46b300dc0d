#pragma once
// Internal: a reusable sparse Cholesky factorization of (H + shift I), H the element-wise PSD-projected Hessian
// (upper triangle), for the Hessian-preconditioned L-BFGS. Uses the shared CHOLMOD wrapper (symbolic analysis
// once); the shift starts at rel_shift * max(diag H, 1) and grows x100 while CHOLMOD reports a non-positive pivot.
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>

#include "fibernet/solve/cholmod_llt.hpp"

namespace fibernet::detail {

class HessianFactor {
public:
    // False if H + shift I could not be factorized for any shift up to rel_shift * 1e10 * max(diag H, 1).
    bool factorize(const Eigen::SparseMatrix<double>& H, double rel_shift) {
        if (!llt_.analyzed()) llt_.analyze(H);
        double dmax = 1;
        for (int j = 0; j < H.outerSize(); ++j)
            for (Eigen::SparseMatrix<double>::InnerIterator it(H, j); it; ++it)
                if (it.row() == it.col()) dmax = std::max(dmax, std::abs(it.value()));
        double s = rel_shift * dmax;
        for (int k = 0; k < 6; ++k, s *= 100) {
            if (llt_.factorize(H, s)) {
                shift_ = s;
                return true;
            }
        }
        return false;
    }
    Eigen::VectorXd solve(const Eigen::VectorXd& b) const { return llt_.solve(b); }
    double shift() const { return shift_; }

private:
    CholmodLLT llt_;
    double shift_ = 0;
};

}  // namespace fibernet::detail
