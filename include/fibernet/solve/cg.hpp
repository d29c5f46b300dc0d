#pragma once
// Nonlinear conjugate gradients, Polak-Ribiere+ (beta = max(0, g1.(g1 - g0) / g0.g0)), like LAMMPS
// `min_style cg`: restart with steepest descent every `restart_every` iterations (LAMMPS: the number of
// unknowns), whenever beta would be negative, and whenever the new direction is not a descent direction.
// Line search: strong Wolfe (line_search.hpp) with c2 = 0.1, as PR+ needs; the first trial step is
// alpha_prev * g_prev.d_prev / g.d (Nocedal & Wright eq. 3.60).
#include <memory>
#include <string>

#include "fibernet/solve/line_search.hpp"
#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct CgParams {
    LineSearchParams line_search = [] {
        LineSearchParams p;
        p.c2 = 0.1;
        return p;
    }();
    int restart_every = 0;     // steepest-descent restart period, 0 = number of unknowns
    int stall_iterations = 20; // Stalled after this many iterations with neither an energy decrease beyond
                               // round-off nor a new minimum of max|g|

    void check(const std::string& where) const;
};

class CgSolver : public Solver {
public:
    CgSolver(const SolverOptions& opt, const CgParams& p = {});
    std::string name() const override { return "cg"; }
    SolverOptions& options() override { return opt_; }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override;
    SolverCapabilities capabilities() const override { return {}; }
    std::unique_ptr<Solver> clone() const override { return std::make_unique<CgSolver>(opt_, p_); }

private:
    SolverOptions opt_;
    CgParams p_;
};

}  // namespace fibernet
