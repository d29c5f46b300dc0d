#pragma once
// What a solver sees of an energy: value, gradient and a sparse Hessian (upper triangle, fixed pattern)
// of a function of n unknowns. Nothing else of the model reaches a solver.
#include <Eigen/Core>
#include <Eigen/SparseCore>

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
    virtual double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                           bool project_psd) = 0;
    // Upper-triangular CSC pattern, values zero; fixed for the lifetime of the objective.
    virtual const Eigen::SparseMatrix<double>& hessian_pattern() const = 0;
};

}  // namespace fibernet
