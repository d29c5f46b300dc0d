#include "fibernet/energy/sparse_pattern.hpp"

#include <algorithm>
#include <stdexcept>

namespace fibernet {

Eigen::SparseMatrix<double> pattern_from_columns(int n, std::vector<std::vector<int>>& cols) {
    std::vector<int> outer(n + 1, 0), inner;
    for (int c = 0; c < n; ++c) {
        auto& v = cols[c];
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
        inner.insert(inner.end(), v.begin(), v.end());
        outer[c + 1] = static_cast<int>(inner.size());
    }
    std::vector<double> zeros(inner.size(), 0.0);
    Eigen::SparseMatrix<double> P = Eigen::Map<const Eigen::SparseMatrix<double>>(
        n, n, static_cast<Eigen::Index>(inner.size()), outer.data(), inner.data(), zeros.data());
    P.makeCompressed();
    return P;
}

int pattern_slot(const Eigen::SparseMatrix<double>& P, int r, int c) {
    const int* in = P.innerIndexPtr();
    const int b = P.outerIndexPtr()[c], e = P.outerIndexPtr()[c + 1];
    const int* it = std::lower_bound(in + b, in + e, r);
    if (it == in + e || *it != r) throw std::logic_error("hessian pattern lacks an entry");
    return static_cast<int>(it - in);
}

}  // namespace fibernet
