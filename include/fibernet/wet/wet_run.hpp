#pragma once
// The `fibernet wet` workflow (issue 6, part 3): dry network -> relax -> wet -> relax under capillary load with
// mobile bridges, then energies, bridges and events, bundles, pores dry and wet, and the linear shear modulus dry
// and wet; optionally the free box: the box deformation at which the wet network carries no macroscopic stress
// (drying shrinkage). Shared by the CLI and bench/bench_wet.cpp.
#include <Eigen/Core>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "fibernet/mechanics/stress.hpp"
#include "fibernet/network/network.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/bundles.hpp"
#include "fibernet/wet/free_box.hpp"
#include "fibernet/wet/pores.hpp"
#include "fibernet/wet/smooth_wet_relax.hpp"
#include "fibernet/wet/wetting.hpp"

namespace fibernet {

// Which capillary model relaxes the wet network: the event model (bridges on segment pairs, moved, formed, ruptured and
// zipped by the active-set loop between solves; active_set.hpp) or the smooth model (one C2 energy over every segment
// pair within range; smooth_wet_energy.hpp, issue 22).
enum class WetModel { Events, Smooth };
WetModel parse_wet_model(const std::string& s);  // "events" | "smooth"; InputError otherwise
std::string to_string(WetModel m);
// The dry crossings of the smooth model: the fiber pairs the rule leaves dry and every crosslinked pair (a
// crosslinked pair gets no capillary term at its crosslink, issue 22).
FiberPairs smooth_dry_pairs(const Network& net, const WettingRule& rule);

struct WetRunOptions {
    WetParams params;
    WetModel model = WetModel::Events;
    SmoothWetParams smooth;      // the smooth model's pair parameters (beta and law come from `params`; widths <= 0:
                                 // the fiber radius 1/a, the contact distance 2/a)
    SmoothRelaxOptions smooth_relax;
    WettingRule rule;
    ActiveSetOptions active_set;
    std::string solver = "newton";
    SolverOptions solver_options;
    double bundle_angle_deg = 10;
    bool moduli = true;          // linear shear modulus dry and wet (one factorization each, and three relaxations each
                                 // for the second difference at modulus_strain; see WetState)
    double modulus_strain = 1e-4;
    FreeBoxOptions free_box;
    // The smooth model only (InputError otherwise): the wet relaxation starts from these coordinates (the dry energy's
    // dofs, e.g. a checkpoint of an interrupted run) instead of the dry equilibrium; empty: from the dry equilibrium.
    Eigen::VectorXd wet_start;
    // The smooth model: called with each accepted iterate of the fixed-box wet relaxation (not of the moduli's or the
    // free box's relaxations), e.g. to write checkpoints (SolverOptions::observe); empty: none.
    std::function<void(const Eigen::VectorXd& q, double energy, double grad_max)> observe_wet;
    // The same relaxation between the local solves of an iteration (SolverOptions::observe_within); empty: none.
    WithinObserver observe_wet_within;
};

struct WetState {
    Eigen::VectorXd q;
    WetSplit energy;
    PoreStats pores;
    // Linear shear modulus with the bridge set frozen (wet_moduli.hpp: exact, one factorization), and the central
    // second difference of relaxed energies at gamma = +-modulus_strain (relaxed_shear_modulus), which departs from
    // it when a capillary instability lies within that strain. NaN when not computed or when it failed (a saddle, a
    // relaxation that did not converge).
    double shear_modulus = std::numeric_limits<double>::quiet_NaN();
    double shear_modulus_error = std::numeric_limits<double>::quiet_NaN();  // its bound (Modulus::error)
    double shear_modulus_fd = std::numeric_limits<double>::quiet_NaN();
    bool converged = false;
};

struct WetRun {
    WetState dry, wet;
    SolveResult dry_solve;
    ActiveSetResult active;        // the wet relaxation (the smooth model fills bridges, last, rounds, stable, message)
    SmoothRelaxResult smooth;      // the smooth model's relaxation
    std::vector<Bridge> initial_bridges;
    BundleStats bundles;
    FreeBoxResult free_box;        // attempted only if asked and the fixed-box wet state is stable
    double seconds_dry = 0, seconds_wet_solve = 0, seconds_events = 0, seconds_pores = 0, seconds_moduli = 0;
};

// Runs the workflow on `net` discretized as `m` at box deformation F. `dry_start`, if given, is a dry equilibrium
// to reuse (a beta sweep relaxes the dry network once).
WetRun run_wet(const Network& net, const Model& m, const Eigen::Matrix2d& F, const WetRunOptions& opt,
               const WetState* dry_start = nullptr);

// Linear shear modulus of the wet network with its bridge set frozen: G = (1/A) d2E/dgamma2 of the relaxed energy,
// by central differences of relaxed energies at gamma +- h (simple shear of the current box). Dry networks get the
// same treatment so that the two are compared like for like (and the dry value can be checked against the exact
// linear_moduli). NaN if a relaxation fails.
double relaxed_shear_modulus(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const Eigen::VectorXd& q,
                             const std::vector<Bridge>& bridges, const WetParams& params, Solver& solver, double h);

}  // namespace fibernet
