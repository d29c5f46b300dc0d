#pragma once
// Internal: a cholmod_sparse view (no copy) of an upper-triangular Eigen CSC matrix with int indices, shared by the
// CHOLMOD wrappers (cholmod_llt.cpp, cholmod_ldl.cpp).
#include <cholmod.h>

#include <Eigen/SparseCore>
#include <stdexcept>
#include <string>

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

}  // namespace fibernet::detail
