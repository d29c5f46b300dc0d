#pragma once
// A thin CHOLMOD wrapper for the symmetric positive definite systems of Newton and the linear moduli:
// symbolic analysis (fill-reducing ordering, supernodal structure) once per Hessian pattern, then a numeric
// supernodal LL^T of H + shift I per call (CHOLMOD's beta argument, so no copy of H is made).
// CHOLMOD's supernodal factorization is LL^T only: an indefinite or numerically singular matrix makes
// factorize() return false (CHOLMOD_NOT_POSDEF), and the caller steps down its ladder (docs/moduli.md).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

#include "fibernet/solve/linear_solver.hpp"

namespace fibernet {

class CholmodLLT : public LinearSolver {
public:
    CholmodLLT();
    ~CholmodLLT();
    CholmodLLT(const CholmodLLT&) = delete;
    CholmodLLT& operator=(const CholmodLLT&) = delete;
    std::string name() const override { return "cholmod-llt"; }
    bool definite() const override { return true; }

    // Symbolic analysis of an upper-triangular CSC pattern (values ignored). Called once per model.
    void analyze(const Eigen::SparseMatrix<double>& upper) override;
    bool analyzed() const override;
    void forget() override;
    // Numeric factorization of H + shift I (H: upper triangle with the analyzed pattern; a matrix of another size
    // or number of entries is analyzed first). False if not positive definite (or non-finite); the previous
    // factor is then unusable.
    bool factorize(const Eigen::SparseMatrix<double>& upper, double shift = 0.0) override;
    // x = (H + shift I)^{-1} b with the last successful factor.
    Eigen::VectorXd solve(const Eigen::VectorXd& b) const override;
    // The same for several right-hand sides at once (columns of B).
    Eigen::MatrixXd solve_many(const Eigen::MatrixXd& B) const override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fibernet
