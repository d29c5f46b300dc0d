#pragma once
// The `fibernet wet` workflow (issue 6, part 3): dry network -> relax -> wet -> relax under capillary load with
// mobile bridges, then energies, bridges and events, bundles, pores dry and wet, and the linear shear modulus dry
// and wet; optionally the free box: the box deformation at which the wet network carries no macroscopic stress
// (drying shrinkage). Shared by the CLI and bench/bench_wet.cpp.
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "fibernet/mechanics/stress.hpp"
#include "fibernet/network/network.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/bundles.hpp"
#include "fibernet/wet/pores.hpp"
#include "fibernet/wet/smooth_wet_relax.hpp"
#include "fibernet/wet/wetting.hpp"

namespace fibernet {

// Free box (issue 6: "optionally with the box free to shrink (zero stress)"; docs/wet.md, "Free box"). After the
// wet relaxation at the fixed box F0, the box deformation F = U F0 is sought at which the relaxed wet network's
// Cauchy stress (wet_stress: dry + capillary) vanishes. Every residual evaluation is an active-set relaxation
// (relax_wet) at the trial box, started from an accepted state moved by its linear relaxed response or mapped
// affinely, whichever start has the lower energy. The relaxed response (J = dr/du, dq/du, and the stiffness d2E*/du2)
// comes from central differences of relaxations at u +- h e_j with the bridge set frozen (2 x unknowns short solves).
//   isotropic (default): U = s I, residual the mean normal stress (sigma_xx + sigma_yy) / 2. A path from s = 1 in the
//       direction the stress pulls (tension: shrink), each point relaxed from the last, by Newton steps capped at
//       max_step until the stress changes sign, then safeguarded Newton in the bracket (Illinois regula falsi where
//       the Newton step would leave it). Shear stresses are not
//       controlled (reported). A bracket narrower than snap_width with no point below tolerance is reported as a
//       snap (the stress jumps across zero on this path: bridges forming or rupturing).
//   full: U symmetric (U_xx, U_yy, U_xy), residual (sigma_xx, sigma_yy, sigma_xy): damped Newton, du = -J^+ r (SVD;
//       floppy directions get no step), capped at max_step per component and halved until |r| decreases. Less
//       robust: on the worked example the relaxations of nearby boxes land on different branches of the
//       path-dependent wet landscape, with stress jumps as large as the stress itself.
// Converged when every controlled component satisfies |sigma| <= tol * sigma_c, sigma_c = beta * (fiber rest length
// in the box) / A(F0): the stress an adhesion beta per unit fiber length exerts on the box (beta = 0: beta replaced
// by 1, the bending-energy unit). The returned state is always an equilibrium of a consistent bridge set.
struct FreeBoxOptions {
    bool enabled = false;
    bool isotropic = true;       // F = s F0 (robust, the default); false: the full symmetric U (damped Newton)
    double tol = 1e-3;           // on |sigma| / sigma_c, every controlled component
    int max_iter = 40;           // outer (Newton) iterations
    int max_halvings = 6;
    double max_step = 0.05;      // largest change of a component of U per outer iteration
    double fd_strain = 1e-4;     // h of the finite-difference relaxed stiffness
    double snap_width = 1e-7;    // isotropic: a sign-change bracket this narrow (in s) without a root is a snap
    bool stability = true;       // at a converged box, the relaxed stiffness's eigenvalues (2 x unknowns solves)
    bool progress = false;       // one line per outer iteration (and per rejected trial) on stderr
};

struct FreeBoxIteration {
    int iteration = 0;
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    Eigen::Vector3d sigma = Eigen::Vector3d::Zero();  // xx, yy, xy
    double residual = 0;          // max controlled |sigma| / sigma_c
    double step = 0;              // accepted damping factor (0 at the start)
    double energy = 0;            // relaxed wet energy
    int trials = 0, relax_rounds = 0, solver_iterations = 0;
    double seconds = 0;
};

struct FreeBoxResult {
    bool attempted = false, converged = false;
    std::string message;
    Eigen::Matrix2d F0 = Eigen::Matrix2d::Identity(), F = Eigen::Matrix2d::Identity();
    double s = 1;                 // isotropic: the scale; full: sqrt(det F / det F0), the mean linear scale
    double areal_shrinkage = 0;   // 1 - det F / det F0
    double stress_scale = 0;      // sigma_c
    Stress stress0, stress;       // wet stress at F0 (fixed box) and at F
    double residual0 = 0, residual = 0;  // max controlled |sigma| / sigma_c at F0 and at F
    // Eigenvalues of d2E*/du2 / A at the converged F (E* the relaxed energy, bridge set frozen; u the unknowns of
    // U): all >= 0 (up to round-off) for a stable free box; a negative one, a box shape that would run away.
    // Empty if not computed.
    Eigen::VectorXd stiffness_eigenvalues;
    int iterations = 0, relaxations = 0, stiffness_solves = 0, solver_iterations = 0;
    int stiffness_retries = 0;  // stiffness solves retried with Newton's LDL^T rung after the shifted ladder's line
                                // search failed (not counted in stiffness_solves)
    std::vector<FreeBoxIteration> history;  // the start and every iteration's new point
    bool bracketed = false;       // isotropic: a point past zero stress was met (the search bracketed the root)
    bool snap = false;            // isotropic: the mean stress jumps across zero between snap_s[0] and snap_s[1]
    Eigen::Vector2d snap_s = Eigen::Vector2d::Zero(), snap_residual = Eigen::Vector2d::Zero();
    // The state at F (the last accepted one if not converged).
    Eigen::VectorXd q;
    std::vector<Bridge> bridges;
    WetSplit energy;
    WetEvents events;             // summed over the accepted relaxations
    PoreStats pores;
    BundleStats bundles;
    // Linear shear modulus at F with the bridge set frozen (wet_moduli.hpp) and its error bound, of the state above
    // (the last accepted one if not converged); NaN if not computed or if it failed.
    double shear_modulus = std::numeric_limits<double>::quiet_NaN();
    double shear_modulus_error = std::numeric_limits<double>::quiet_NaN();
    double seconds = 0;
};

// Which capillary model relaxes the wet network: the event model (bridges on segment pairs, moved, formed, ruptured and
// zipped by the active-set loop between solves; active_set.hpp) or the smooth model (one C2 energy over every segment
// pair within range; smooth_wet_energy.hpp, issue 22).
enum class WetModel { Events, Smooth };
WetModel parse_wet_model(const std::string& s);  // "events" | "smooth"; InputError otherwise
std::string to_string(WetModel m);

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

// Stress of the wet network at (q, F) with the given bridges: the dry stress (mechanics/stress.hpp) plus the
// capillary term. A bridge's energy depends on F through its nodes' periodic images (X = x + F B0 shift) and, for a
// fixed node, x = F x_ref; P_ab = dE/dF_ab at fixed q, sigma = P F^T / A.
Stress wet_stress(const NetworkEnergy& dry, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                  const std::vector<Bridge>& bridges, const WetParams& params);

// sigma_c of FreeBoxOptions for this model at F0.
double free_box_stress_scale(const Model& m, const Eigen::Matrix2d& F0, double beta);

// The free-box search from a wet equilibrium (q0, bridges0) at F0 (see FreeBoxOptions). The returned state is an
// equilibrium of its bridge set at F; converged says whether its stress is below tolerance.
FreeBoxResult free_box(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const WetParams& params,
                       const Eigen::VectorXd& q0, const std::vector<Bridge>& bridges0, Solver& solver,
                       const ActiveSetOptions& active_set, const FreeBoxOptions& opt);

}  // namespace fibernet
