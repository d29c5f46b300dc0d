#include "fibernet/solve/subset_objective.hpp"

#include <algorithm>
#include <stdexcept>

namespace fibernet {

SubsetObjective::SubsetObjective(Objective& f, const Eigen::VectorXd& q, const std::vector<int>& coords)
    : f_(f), coords_(coords), q_(q), H_(f.hessian_pattern()), version_(f.pattern_version()) {
    const int n = f.size();
    std::vector<int> local(n, -1);
    for (size_t k = 0; k < coords_.size(); ++k) {
        if (coords_[k] < 0 || coords_[k] >= n || (k > 0 && coords_[k] <= coords_[k - 1]))
            throw std::logic_error("SubsetObjective: coordinates must be sorted, distinct and in range");
        local[coords_[k]] = static_cast<int>(k);
    }
    // The full pattern's entries between kept coordinates; sorted coordinates keep it upper triangular and sorted.
    std::vector<Eigen::Triplet<double>> t;
    const Eigen::SparseMatrix<double>& P = f.hessian_pattern();
    std::vector<int> col_start(coords_.size() + 1, 0);
    for (size_t k = 0; k < coords_.size(); ++k) {
        const int j = coords_[k];
        for (int p = P.outerIndexPtr()[j]; p < P.outerIndexPtr()[j + 1]; ++p)
            if (local[P.innerIndexPtr()[p]] >= 0) {
                t.emplace_back(local[P.innerIndexPtr()[p]], static_cast<int>(k), 0.0);
                slot_.push_back(p);
            }
    }
    pattern_.resize(size(), size());
    pattern_.setFromTriplets(t.begin(), t.end());
    pattern_.makeCompressed();
    if (pattern_.nonZeros() != static_cast<Eigen::Index>(slot_.size()))
        throw std::logic_error("SubsetObjective: the objective's pattern has duplicate entries");
}

void SubsetObjective::embed(const Eigen::VectorXd& qa) {
    for (int i = 0; i < size(); ++i) q_[coords_[i]] = qa[i];
}

double SubsetObjective::value(const Eigen::VectorXd& qa) {
    embed(qa);
    return f_.value(q_);
}

double SubsetObjective::gradient(const Eigen::VectorXd& qa, Eigen::VectorXd& g) {
    embed(qa);
    const double E = f_.gradient(q_, g_);
    g.resize(size());
    for (int i = 0; i < size(); ++i) g[i] = g_[coords_[i]];
    return E;
}

double SubsetObjective::hessian(const Eigen::VectorXd& qa, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) {
    embed(qa);
    const double E = f_.hessian(q_, g_, H_, psd);
    // The slots index the pattern of construction.
    if (f_.pattern_version() != version_)
        throw std::logic_error("SubsetObjective: the objective's Hessian pattern changed (restrict it instead)");
    g.resize(size());
    for (int i = 0; i < size(); ++i) g[i] = g_[coords_[i]];
    if (H.nonZeros() != pattern_.nonZeros()) throw std::logic_error("SubsetObjective: Hessian lacks the subset's pattern");
    for (size_t k = 0; k < slot_.size(); ++k) H.valuePtr()[k] = H_.valuePtr()[slot_[k]];
    return E;
}

}  // namespace fibernet
