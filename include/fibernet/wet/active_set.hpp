#pragma once
// Relaxation under capillary load with mobile bridges (issue 6, part 2): an outer active-set loop around a
// minimizer. The energy is smooth while the set of bridged segment pairs is fixed (WetEnergy); between solves the
// set is updated from the relaxed geometry:
//   move     a crossing left its home segment by more than move_margin x the blend half-width: the bridge moves to
//            the neighbouring segment (no energy change, see bridge.hpp), repeatedly; the margin is a hysteresis that
//            keeps a bridge whose crossing sits at a node from sliding back and forth every round (cycling);
//   rupture  a crossing slid past a fiber end far enough that the bridge's weight is zero (no energy change);
//   form     two segments of different fibers intersect with no bridge on or next to that pair (fibers zipping):
//            a new bridge (new crossings are always wet);
//   merge    two bridges landed on the same pair: one is dropped;
//   lock     a bridge whose crossing sits inside its home pair (weight 1) and whose pair is aligned within
//            contact_angle becomes a bundle bridge (bridge.hpp; no energy change, not counted as a change);
//   zip      two nearly aligned segments of different fibers in contact (distance <= contact_distance, overlapping
//            by at least half the shorter one) with no bridge on either segment towards the other fiber: a new locked
//            bridge (counted as formed). A locked bridge ruptures when its pair is no longer in contact (hysteresis:
//            twice the angle and the distance).
// The loop stops when q is an equilibrium of the updated set (stable: its gradient is no larger than the one the solver
// accepted, so moves and locks, which leave the energy unchanged, need no new solve), when a bridge set repeats an
// earlier round's more than max_freezes + bridges / bridges_per_freeze times (cycling, reported, the last state kept),
// when the solver fails, or after max_rounds. A repeat is first broken: the fiber pairs whose bridges toggle are frozen (their bridges kept as they
// are, no new ones) and the rounds go on, so the result is an equilibrium with a set that obeys the rules everywhere
// but on those pairs (counted: cycles_broken, frozen_pairs). A solve that
// hits its iteration limit is not a failure: the set is updated and the next round continues from there, unless two
// such rounds in a row (uncut, the set unchanged) did not halve max|g|: then the run ends unconverged. While the
// set keeps changing, rounds are cut at round_iterations on purpose (events interleaved with the solve).
// Local rounds (local_fraction > 0, beta > 0): when the part of the network that needs a solve is small, a round
// solves only that part, each connected piece on its own with the rest held (wet_region.hpp), and updates the set only
// where nodes moved. The whole network's gradient is checked after every round, and only a global round declares the
// set stable (a local round at an equilibrium, or one that changes nothing, hands the next round to the whole network).
#include <Eigen/Core>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/wet_energy.hpp"

namespace fibernet {

struct WetEvents {
    int moves = 0, ruptures = 0, formed = 0, merged = 0, locked = 0;
    // Aligned segment pairs (crossing or in contact) left without a bridge by ActiveSetOptions::bundle_partners at one
    // update (the same pairs are refused every round); a relaxation's result holds its last update's count, not a sum:
    // the final global round's for a stable set (a local round's update sees only the region's segments).
    int capped = 0;
    int total() const { return moves + ruptures + formed + merged; }
};

struct ActiveSetOptions {
    int max_rounds = 1000;      // global rounds (a cut round is only round_iterations solver iterations); local rounds
                                // are bounded by 10 x max_rounds rounds in all
    // > 0: while the set keeps changing, a round's solve stops after this many solver iterations and the set is
    // updated (events interleaved with the solve: new crossings get their bridges while the fibers still move); a
    // round that leaves the set unchanged, or returns to an earlier set, lifts the cap for the next. 0: every round is
    // solved to convergence, so a fiber sweeps across others without feeling them until the solve ends, which ends
    // in deeper minima with more bridges (over 16 networks of 100 fibers: K = 3..20 agree, K = 0 does not; docs/wet.md,
    // "Rounds") and takes 2x the Newton iterations. run_wet ignores it for first-order solvers (cheap, many iterations).
    int round_iterations = 10;
    bool warm_start = true;       // a round after a cut one resumes the solver's adapted state (SolverOptions::warm_start)
    // Newton's rung 0 by LDL^T with flipped negative pivots (SolverOptions::ldl) while beta > 0: a large wet network
    // is indefinite somewhere at almost every iteration, and the escalated shift that the whole Hessian otherwise
    // gets shortens every other part's step (docs/wet.md, "Newton on wet networks"). Other solvers ignore it.
    bool newton_ldl = true;
    // Local rounds (wet_region.hpp): after a round, the nodes with a coordinate |g| > local_threshold x max|g| (and
    // > the solver's tol), grown by local_hops elements, form the next round's region, solved with the rest held, if
    // it holds at most local_fraction of the coordinates; otherwise the round is global. 0: every round global.
    double local_fraction = 0.25;
    double local_threshold = 0.1;
    int local_hops = 3;
    bool form_new = true;        // give new crossings and new contacts bridges
    double contact_distance = 0;  // seed units; 0: the fiber diameter 2 r = 2 ls / a
    double contact_angle_deg = 10;
    bool verbose = false;         // one progress line per round on stderr
    int max_freezes = 5;          // cycles broken by freezing their fiber pairs before cycling is final,
    int bridges_per_freeze = 2000;  // and one more per this many bridges: a large network cycles in more places
    double move_margin = 0.1;     // a bridge moves once its crossing is this fraction of the blend half-width past a node
    // > 0: excluded volume in bundles. A segment adheres along at most this many other fibers: a new aligned bridge
    // (a contact, or a crossing within contact_angle) is not formed if either of its segments already holds aligned
    // bridges (locked, or within contact_angle) with this many fibers other than the new partner (counted as capped).
    // Existing bridges are never removed for it (no energy jump, no cycling), so the cap binds on new bundles only.
    // 2: a flat ribbon (each fiber between two neighbours); 6: a close-packed 3D bundle. 0: no cap (2D stacking
    // unbounded: a bundle of k fibers on one line holds k(k-1)/2 adhering pairs; docs/wet.md, "Bundle partners").
    int bundle_partners = 0;
    // Fiber pairs whose network crossing the wetting rule left dry (wetting.hpp, dry_pairs): no crossing bridge forms
    // between them, since their crossing moves with the fibers and stays dry (contacts of aligned segments still form,
    // as for any pair). Null: every crossing is wet. run_wet sets it from WettingRule.
    std::shared_ptr<const FiberPairs> dry_pairs;
};

struct ActiveSetResult {
    std::vector<Bridge> bridges;   // the final set
    SolveResult last;              // the last solve (its status says whether q is an equilibrium of the final set)
    WetEvents events;              // summed over rounds
    std::vector<WetEvents> per_round;
    int rounds = 0, solver_iterations = 0, factorizations = 0;  // rounds: global and local
    int local_rounds = 0;          // rounds solved on a region of the network (ActiveSetOptions::local_fraction)
    int local_iterations = 0;      // solver iterations in those rounds, summed over their parts
    double seconds_local = 0;      // solve time in those rounds (part of seconds_solve)
    SolveTimings timings;          // the solver's time split, summed over rounds
    SolveTimings timings_local;    // ... over the local rounds' pieces only (part of timings)
    bool stable = false;           // the last round, a global one, changed nothing: q is an equilibrium with a consistent set
    bool cycling = false;          // a bridge set repeated after max_freezes cycles were broken
    int cycles_broken = 0;         // cycles broken by freezing the toggling fiber pairs
    int frozen_pairs = 0;          // fiber pairs whose bridges were frozen
    FiberPairs frozen;             // ... which
    std::string message;
    double seconds_solve = 0, seconds_events = 0;
    // Parts of the above: in seconds_local, building the pieces (incidence, parts, WetRegion); in
    // seconds_events, the bridge update with the set's signature, and the next set's energy and whole gradient.
    double seconds_local_setup = 0, seconds_update = 0, seconds_gradient = 0;
};


// Updates `bridges` (moves, ruptures, merges; new bridges if form_new) at state q of `dry` at F; returns the counts.
// Bridges between `frozen` fiber pairs are kept unchanged and such pairs get no new bridges. settled: q is an
// equilibrium of the current set; only then does a nearly parallel (unlocked) pair out of contact rupture.
// moved (one flag per node, may be null): only these nodes moved since the last update (a local round), so bridges
// with none of them are kept as they are and only segments with one can form new bridges.
WetEvents update_bridges(const NetworkEnergy& dry, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                         std::vector<Bridge>& bridges, const ActiveSetOptions& opt = {},
                         const FiberPairs* frozen = nullptr, bool settled = true, const std::vector<char>* moved = nullptr);

// All intersecting segment pairs of different fibers that share no node, as bridges (nearest periodic image).
// only (one flag per segment, may be null): pairs with at least one flagged segment.
std::vector<Bridge> segment_crossings(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                      const std::vector<char>* only = nullptr);
// All segment pairs of different fibers in contact (see "zip" above), as locked bridges.
std::vector<Bridge> segment_contacts(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double distance,
                                     double angle_deg, const std::vector<char>* only = nullptr);

ActiveSetResult relax_wet(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const WetParams& params,
                          std::vector<Bridge> bridges, Solver& solver, Eigen::VectorXd& q,
                          const ActiveSetOptions& opt = {});

}  // namespace fibernet
