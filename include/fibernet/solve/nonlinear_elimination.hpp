#pragma once
// Nonlinear elimination for Newton (issue 23; Cai & Keyes, SIAM J. Sci. Comput. 24, 2002; Cai & Li, SIAM J. Sci.
// Comput. 33, 2011). Newton's global step on a Mikado network is held back by a few local places (pinned bars and small
// linkages that must rotate: curved valleys, docs/moduli.md "Where Newton's iterations go"); a linear step can follow a
// curved valley only a short way, so each place needs tens of global iterations, and the network's slowest place sets
// the count. Here the places are solved to local equilibrium with the rest of the network held, at the cost of their
// own elements:
//   - before each global step, the coordinates with |g_i| > threshold max|g|, grown by `hops` steps through the
//     Hessian's pattern (one step: the coordinates an element couples), split into connected parts, each minimized;
//   - inside the global line search, the same parts are minimized again at every trial point, so the global step is
//     judged with the places back in their valleys (the Newton step on the remaining coordinates is then the step on
//     the reduced energy, whose Hessian is the Schur complement, because the parts' gradients vanish).
// The Schwarz sweep (EliminationOptions::block > 0; a multiplicative Schwarz smoother, Dolean, Jolivet & Nataf 2015,
// ch. 1, used as the nonlinear preconditioner of a global Newton step, Cai & Keyes 2002) solves every place instead of the
// hot ones: the coordinates are split into connected blocks of about `block` coordinates, each grown by `overlap` hops,
// and before each global step every block is minimized in turn with the rest held. Regions far apart then relax in the
// same global iteration, where a global line search serves one region at a time; the global step is left to the
// coupling between blocks, so it is taken without local solves at its trial points.
// Every local solve only lowers the energy, so the global energy never rises; convergence is still tested on the
// whole gradient. The solver sees only value, gradient, Hessian and the pattern; an objective that offers
// Objective::restriction is restricted at the cost of the parts' elements, any other through SubsetObjective.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <string>
#include <vector>

#include "fibernet/energy/objective.hpp"

namespace fibernet {

struct EliminationOptions {
    double threshold = 0.05;    // a coordinate is hot when |g_i| > threshold max|g|, in (0, 1)
    int hops = 16;              // growth of the hot set through the Hessian pattern, >= 0
    double max_fraction = 0.25; // no elimination when the grown set holds more than this share of the coordinates
    double local_rtol = 1e-3;   // a part is solved to max|g_part| <= max(tol, local_rtol max|g|), in (0, 1)
    int local_max_iter = 200;   // Newton iterations per part and solve, >= 1
    int block = 0;              // > 0: the Schwarz sweep over blocks of about this many coordinates (threshold, hops
                                // and max_fraction then unused); 0: the hot places only
    int overlap = 4;            // the Schwarz blocks' overlap: hops each block is grown by, >= 0

    // Throws InputError("<where>: elimination.<name> = <v> must ...").
    void check(const std::string& where) const;
};

struct EliminationCounts {
    int selections = 0;        // global iterations that eliminated
    int local_solves = 0;      // part solves (before the steps and at the line searches' trial points)
    int local_iterations = 0;  // Newton iterations of those solves
    int local_factorizations = 0;
    double seconds = 0;
};

class NonlinearElimination {
public:
    // pattern: the objective's Hessian pattern (upper triangle), from which the coupling graph is built once;
    // median_floor, max_step: the local solves' SolverOptions::median_floor and max_step (the global Newton's: the
    // smooth wet energy caps steps at its list's skin so that few trials leave the list, in local solves too).
    NonlinearElimination(const Eigen::SparseMatrix<double>& pattern, EliminationOptions opt, bool median_floor = false,
                         double max_step = 0);

    // The coupling graph of a new pattern (the objective's changed: Objective::pattern_version).
    void set_pattern(const Eigen::SparseMatrix<double>& pattern);

    // Picks the parts from the gradient g at the current state; false (no parts) when nothing is hot beyond the grown
    // set's size limit or max|g| is zero. The Schwarz sweep's parts are its blocks, whatever g.
    bool select(const Eigen::VectorXd& g);
    // The local solves judge a global step's trial points too (the hot places' elimination; not the Schwarz sweep's).
    bool at_trial_points() const { return opt_.block == 0; }
    const std::vector<std::vector<int>>& parts() const { return opt_.block > 0 ? blocks_ : parts_; }
    int coordinates() const { return selected_; }

    // Minimizes f over each part in turn, the others held, overwriting q's entries of the parts; never raises f.
    // max_seconds > 0: the parts' solves share this wall-time budget (the caller's remaining one); parts not reached
    // in it are left as they are. between: called with q after each part's solve, with the parts solved and their number
    // (for checkpoints and progress: SolverOptions::observe_within).
    void eliminate(Objective& f, Eigen::VectorXd& q, double tol, double max_seconds = 0,
                   const std::function<void(const Eigen::VectorXd& q, int done, int total)>& between = {});

    const EliminationCounts& counts() const { return counts_; }

private:
    void partition();  // the Schwarz blocks of the current coupling graph

    EliminationOptions opt_;
    bool median_floor_;
    double max_step_;
    std::vector<int> adj_start_, adj_;  // symmetric coupling graph over the coordinates
    std::vector<std::vector<int>> parts_, blocks_;
    int selected_ = 0;
    EliminationCounts counts_;
};

}  // namespace fibernet
