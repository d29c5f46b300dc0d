#pragma once
// CHOLMOD's simplicial LDL^T of a symmetric, possibly indefinite matrix H + shift I (no pivoting: P (H + shift I) P^T
// = L D L^T with L unit lower triangular and D diagonal, fill-reducing P), and solves with the pivots modified to
// max(|D_j|, floor): a positive definite L |D| L^T that agrees with H + shift I wherever its pivots are positive.
// Newton's first rung (newton.hpp): negative curvature is handled where it occurs, instead of by one shift of the
// whole Hessian, so that a buckling spot does not shorten the step of every other part of a large network.
// Without pivoting, a near-zero pivot can make entries of L large (the floor bounds only D): Newton checks that the
// direction is finite and one of descent, and falls back to its shifted LL^T ladder when it is not or when its line
// search fails.
// CHOLMOD gets P (H + shift I) P^T already permuted, in its natural order (cholmod_view.hpp, PermutedTriangle): given
// H and the order P it would permute and transpose H twice on every factorization (13 % of a factorization of a
// 1e4-fiber wet Hessian in the first round, 3-5 % late in the run when the bridges have added fill).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "fibernet/solve/linear_solver.hpp"

namespace fibernet {

// Large matrices (at least split_min rows) are ordered for two threads instead (docs/benchmarks.md, "First session
// of 2026-11-25"): a vertex separator S splits the graph of H into parts A and B with no entry between them (METIS's
// bisection through cholmod_bisect), each part is bisected once more, and CAMD orders every part within the
// constraint [A's parts][B's parts][S]. Rows of A and of B then depend only on their own part: two threads compute
// them, and each its part's share of the separator's rows, and one thread finishes the separator (split_ldl.hpp).
// The parts' rows are CHOLMOD's arithmetic exactly, the separator's differ in the last bits (the same terms summed in
// another order), and the factor is the same on any number of threads. Late in a 1e4-fiber wet run it factors in
// 0.37 s against 0.56 s on one thread in CHOLMOD's own order (bench_factor; 0.50 s in this order on one thread).
class CholmodLDL : public LinearSolver {
public:
    static constexpr int kSplitMin = 20000;
    explicit CholmodLDL(int split_min = kSplitMin);
    ~CholmodLDL();
    CholmodLDL(const CholmodLDL&) = delete;
    CholmodLDL& operator=(const CholmodLDL&) = delete;
    std::string name() const override { return "cholmod-ldl"; }
    bool definite() const override { return false; }

    // Symbolic analysis of an upper-triangular CSC pattern (values ignored).
    void analyze(const Eigen::SparseMatrix<double>& upper) override;
    bool analyzed() const override;
    void forget() override;
    // The analyzed order's independent row ranges [0, a) and [a, b) (factored at the same time); a = b = 0: none.
    int split_a() const;
    int split_b() const;
    // The analyzed elimination order (order()[k]: the row of H eliminated k-th), and the last factorization's pivots
    // D in that order.
    const std::vector<int>& order() const;
    Eigen::VectorXd pivots() const;
    // Numeric LDL^T of H + shift I (H with the analyzed pattern). False on a zero or non-finite pivot.
    bool factorize(const Eigen::SparseMatrix<double>& upper, double shift = 0.0) override;
    // Pivots of the last factorization that were negative, and the smallest one.
    int negative_pivots() const override;
    double min_pivot() const;
    // x = P^T L^-T Dm^-1 L^-1 P b with Dm_j = max(|D_j|, floor) (floor > 0).
    Eigen::VectorXd solve_modified(const Eigen::VectorXd& b, double floor) const;
    // LinearSolver: solve_modified with the floor the last factorize() shifted by (the smallest positive number if that
    // was not positive).
    Eigen::VectorXd solve(const Eigen::VectorXd& b) const override;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fibernet
