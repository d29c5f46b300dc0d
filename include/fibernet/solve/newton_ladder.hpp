#pragma once
// Newton's step ladder (newton.hpp; docs/moduli.md, "Newton ladder") as strategies over one linear-solver interface
// (linear_solver.hpp). Each rung turns the current gradient and Hessian into a descent direction or declines; the
// ladder tries its rungs in order from the iteration's starting level and takes the first direction found.
//   level 0  ModifiedLdlRung       (SolverOptions::ldl) H + mu I by a factorization that replaces negative pivots
//            ShiftedHessianRung    exact H + mu I, then the shift raised 4x at a time up to 0.2 mean diag(H)
//                                  (SolverOptions::projected: exact H + mu I only, not escalated)
//   level 1  ProjectedHessianRung  element-wise PSD-projected H + mu I
//   level 2  ProjectedShiftRung    projected H + lambda I, lambda = 1e-8 mean diag(H) 10^j, j = 0..10
//   level 3  SteepestDescentRung   d = -g / mean diag(H)
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "fibernet/energy/objective.hpp"
#include "fibernet/solve/linear_solver.hpp"
#include "fibernet/solve/result.hpp"

namespace fibernet {

// What a rung sees of the iteration: the objective at q, its gradient, the Hessian H (exact, or projected once a
// rung asked for it), the Levenberg-Marquardt shift mu and the Hessian's scale, the pass (1: the retry after a
// modified direction's line search failed), and the counts and timings it adds to.
struct LadderState {
    Objective& f;
    const Eigen::VectorXd& q;
    const Eigen::VectorXd& g;
    Eigen::SparseMatrix<double>& H;
    bool& projected;     // what H holds
    double mu = 0;       // this iteration's shift
    double dm = 1;       // mean |diag(H)|
    int pass = 0;
    SolveResult& result;

    // g.d < -1e-12 |g| |d| with d finite.
    bool descent(const Eigen::VectorXd& d) const;
    // Factors H + shift I with `lin` and solves d = -(H + shift I)^-1 g; true if that is a descent direction.
    bool factor_and_solve(LinearSolver& lin, double shift, Eigen::VectorXd& d);
    // Replaces H by the element-wise PSD-projected Hessian at q (once per iteration).
    void make_projected();
};

class NewtonRung {
public:
    virtual ~NewtonRung() = default;
    virtual std::string name() const = 0;
    virtual int level() const = 0;
    // A descent direction into d and the shift it factored with (0 if none), or false.
    virtual bool direction(LadderState& s, Eigen::VectorXd& d, double& shift) = 0;
    // The last direction came from a modified factorization of an indefinite H + shift I (so a failed line search
    // along it is worth a retry with the shifted rungs).
    virtual bool modified() const { return false; }
};

// A rung that factors with a linear solver.
class FactoringRung : public NewtonRung {
public:
    explicit FactoringRung(LinearSolver& lin) : lin_(lin) {}

protected:
    LinearSolver& lin_;
};

class ModifiedLdlRung : public FactoringRung {
public:
    using FactoringRung::FactoringRung;
    std::string name() const override { return "modified " + lin_.name(); }
    int level() const override { return 0; }
    bool direction(LadderState& s, Eigen::VectorXd& d, double& shift) override;
    bool modified() const override { return modified_; }
    int negative_pivots() const { return lin_.negative_pivots(); }

private:
    bool modified_ = false;
};

class ShiftedHessianRung : public FactoringRung {
public:
    // escalate = false: H + mu I only (projected Newton tries the exact Hessian as it is, then projects).
    ShiftedHessianRung(LinearSolver& lin, bool escalate = true) : FactoringRung(lin), escalate_(escalate) {}
    std::string name() const override { return (escalate_ ? "shifted exact " : "exact ") + lin_.name(); }
    int level() const override { return 0; }
    bool direction(LadderState& s, Eigen::VectorXd& d, double& shift) override;

private:
    bool escalate_;
};

class ProjectedHessianRung : public FactoringRung {
public:
    using FactoringRung::FactoringRung;
    std::string name() const override { return "projected " + lin_.name(); }
    int level() const override { return 1; }
    bool direction(LadderState& s, Eigen::VectorXd& d, double& shift) override;
};

class ProjectedShiftRung : public FactoringRung {
public:
    using FactoringRung::FactoringRung;
    std::string name() const override { return "projected shifted " + lin_.name(); }
    int level() const override { return 2; }
    bool direction(LadderState& s, Eigen::VectorXd& d, double& shift) override;
};

class SteepestDescentRung : public NewtonRung {
public:
    std::string name() const override { return "steepest descent"; }
    int level() const override { return 3; }
    bool direction(LadderState& s, Eigen::VectorXd& d, double& shift) override;
};

// The rungs in order. `ldl`: the modified factorization for level 0 (SolverOptions::ldl), or null; `llt`: the
// definite factorization of the other rungs; escalate: whether level 0's exact shift is raised before the ladder
// moves on to the projected Hessian (false for SolverOptions::projected).
class NewtonLadder {
public:
    NewtonLadder(LinearSolver& llt, LinearSolver* ldl, bool escalate = true);
    // The first rung at or above `start_level` with a direction; the steepest-descent rung always has one.
    NewtonRung& descend(LadderState& s, int start_level, Eigen::VectorXd& d, double& shift);
    NewtonRung& steepest() { return *rungs_.back(); }
    // The level-0 modified factorization's rung, if the ladder has one.
    ModifiedLdlRung* modified_ldl() { return ldl_; }

private:
    std::vector<std::unique_ptr<NewtonRung>> rungs_;
    ModifiedLdlRung* ldl_ = nullptr;
};

}  // namespace fibernet
