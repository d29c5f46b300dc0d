#pragma once
// The one interface Newton's ladder (newton_ladder.hpp), the Hessian-preconditioned L-BFGS and the linear moduli
// factor and solve through: a sparse symmetric matrix H given as its upper triangle (CSC), analyzed once per pattern
// and factored as H + shift I, then solved for one or several right-hand sides. The strategies that use it ask it
// what it can do (definite(), negative_pivots()) rather than which one it is.
//   cholmod-llt   CHOLMOD supernodal LL^T (cholmod_llt.hpp): fails on a matrix that is not positive definite.
//   cholmod-ldl   CHOLMOD simplicial LDL^T with the pivots replaced by max(|D_j|, shift) (cholmod_ldl.hpp): factors
//                 an indefinite matrix and solves the nearest positive definite one of its kind.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

namespace fibernet {

class LinearSolver {
public:
    virtual ~LinearSolver() = default;
    virtual std::string name() const = 0;
    // Symbolic analysis of an upper-triangular CSC pattern (values ignored).
    virtual void analyze(const Eigen::SparseMatrix<double>& upper) = 0;
    virtual bool analyzed() const = 0;
    // Forgets the analysis: the next factorize() analyzes the matrix it is given (its pattern changed: a pattern that
    // follows the state, Objective::pattern_version).
    virtual void forget() = 0;
    // Numeric factorization of H + shift I (H with the analyzed pattern). False if it failed (for a definite() solver:
    // the matrix is not positive definite); the previous factor is then unusable.
    virtual bool factorize(const Eigen::SparseMatrix<double>& upper, double shift) = 0;
    // x = M^-1 b with M the last successful factorization's matrix (for a solver that is not definite(): the modified,
    // positive definite one).
    virtual Eigen::VectorXd solve(const Eigen::VectorXd& b) const = 0;
    // The same for the columns of B.
    virtual Eigen::MatrixXd solve_many(const Eigen::MatrixXd& B) const;
    // True if solve() is exactly (H + shift I)^-1 whenever factorize() succeeds, and factorize() fails on a matrix that
    // is not positive definite: what a modulus or a certificate of a minimum needs.
    virtual bool definite() const = 0;
    // Negative pivots of the last factorization that solve() replaced (0 for a definite() solver): 0 means H + shift I
    // is positive definite (Sylvester's law of inertia) and solve() its exact inverse.
    virtual int negative_pivots() const { return 0; }
};

// The linear solvers by name (above); throws InputError naming an unknown one.
std::unique_ptr<LinearSolver> make_linear_solver(const std::string& name);
const std::vector<std::string>& linear_solver_names();

}  // namespace fibernet
