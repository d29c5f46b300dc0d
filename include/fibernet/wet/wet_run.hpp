#pragma once
// The `fibernet wet` workflow (issue 6, part 3): dry network -> relax -> wet -> relax under capillary load with
// mobile bridges, then energies, bridges and events, bundles, pores dry and wet, and the linear shear modulus dry
// and wet. Shared by the CLI and bench/bench_wet.cpp.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "fibernet/network/network.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/bundles.hpp"
#include "fibernet/wet/pores.hpp"
#include "fibernet/wet/wetting.hpp"

namespace fibernet {

struct WetRunOptions {
    WetParams params;
    WettingRule rule;
    ActiveSetOptions active_set;
    std::string solver = "newton";
    SolverOptions solver_options;
    double bundle_angle_deg = 10;
    bool moduli = true;          // linear shear modulus dry and wet (two extra relaxations each, see wet_run.cpp)
    double modulus_strain = 1e-4;
};

struct WetState {
    Eigen::VectorXd q;
    WetSplit energy;
    PoreStats pores;
    double shear_modulus = 0;    // NaN when not computed or a relaxation failed
    bool converged = false;
};

struct WetRun {
    WetState dry, wet;
    SolveResult dry_solve;
    ActiveSetResult active;        // the wet relaxation
    std::vector<Bridge> initial_bridges;
    BundleStats bundles;
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
