#pragma once
// What a solver sees of an energy: value, gradient and a sparse Hessian (upper triangle, fixed pattern)
// of a function of n unknowns. Nothing else of the model reaches a solver.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

namespace fibernet {

class Objective {
public:
    virtual ~Objective() = default;
    virtual int size() const = 0;
    // Value; +inf where q lies outside the domain (a collapsed segment).
    virtual double value(const Eigen::VectorXd& q) = 0;
    // Value and gradient.
    virtual double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) = 0;
    // Value, gradient and Hessian. H must have hessian_pattern()'s pattern; its values are overwritten.
    // project_psd: per-element projection of the Hessian to positive semidefinite (a Newton safeguard).
    // An objective whose pattern follows the state (pattern_version() != 0) may first replace its pattern by one that
    // holds every non-zero element at q, and then gives H that pattern.
    virtual double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                           bool project_psd) = 0;
    // Upper-triangular CSC pattern, values zero; fixed for the lifetime of the objective, unless it follows the
    // state (below).
    virtual const Eigen::SparseMatrix<double>& hessian_pattern() const = 0;
    // 0: the pattern is fixed. Otherwise the pattern follows the state (the smooth wet energy, whose pairs come into
    // range as fibers move): hessian() may replace it, and this number changes with every replacement, so that a
    // solver that analyzed the old pattern (a sparse factorization's ordering, elimination's coupling graph) analyzes
    // the new one. Only solvers with SolverCapabilities::follows_pattern are handed such an objective.
    virtual long pattern_version() const { return 0; }
    // Optional, for nonlinear elimination (solve/nonlinear_elimination.hpp): the energy as a function of the
    // coordinates `coords` (sorted, distinct) alone, every other coordinate held where q has it. Its value may differ
    // from value() by a constant (the elements that touch no coordinate of the set are left out); its gradient and
    // Hessian are this objective's restricted to the set. Evaluated at a cost proportional to the set's elements, not
    // the network's. nullptr: not offered (the solver then restricts through value/gradient/Hessian, SubsetObjective).
    // The result refers to this objective and must not outlive it.
    virtual std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) {
        (void)q, (void)coords;
        return nullptr;
    }
};

// An objective whose value, gradient and Hessian come from one evaluation (the regions of nonlinear elimination).
class EvaluatedObjective : public Objective {
public:
    double value(const Eigen::VectorXd& q) override { return eval(q, nullptr, nullptr, false); }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override { return eval(q, &g, nullptr, false); }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        return eval(q, &g, &H, psd);
    }

protected:
    // The value, and the gradient and the Hessian where asked for (non-null).
    virtual double eval(const Eigen::VectorXd& q, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) = 0;
};

}  // namespace fibernet
