#pragma once
// Any objective as a function of some of its coordinates, the others held: the restriction a solver can always form
// from value, gradient and Hessian alone (nonlinear_elimination.hpp uses it when an objective offers no cheaper
// Objective::restriction). Each evaluation costs a whole one of the full objective.
#include <vector>

#include "fibernet/energy/objective.hpp"

namespace fibernet {

class SubsetObjective : public Objective {
public:
    // f over coords (sorted, distinct), the others at q. Keeps a reference to f.
    SubsetObjective(Objective& f, const Eigen::VectorXd& q, const std::vector<int>& coords);
    int size() const override { return static_cast<int>(coords_.size()); }
    double value(const Eigen::VectorXd& qa) override;
    double gradient(const Eigen::VectorXd& qa, Eigen::VectorXd& g) override;
    double hessian(const Eigen::VectorXd& qa, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override;
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return pattern_; }

private:
    void embed(const Eigen::VectorXd& qa);
    Objective& f_;
    std::vector<int> coords_;
    Eigen::VectorXd q_, g_;
    Eigen::SparseMatrix<double> H_, pattern_;
    std::vector<int> slot_;  // value index in f's pattern of each entry of pattern_
    long version_ = 0;       // f's pattern_version() that slot_ indexes
};

}  // namespace fibernet
