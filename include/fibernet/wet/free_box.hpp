#pragma once
// The free box (issue 6: "optionally with the box free to shrink (zero stress)"; docs/wet.md, "Free box"): the box
// deformation at which a relaxed wet network carries no macroscopic stress (drying shrinkage), on either capillary
// model. One search (free_box.cpp) over a model's relaxations: the event model's (free_box) and the smooth model's
// (smooth_free_box).
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "fibernet/mechanics/stress.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/bundles.hpp"
#include "fibernet/wet/pores.hpp"
#include "fibernet/wet/smooth_wet_relax.hpp"
#include "fibernet/wet/wetting.hpp"

namespace fibernet {

// Free box (issue 6: "optionally with the box free to shrink (zero stress)"; docs/wet.md, "Free box"). After the
// wet relaxation at the fixed box F0, the box deformation F = U F0 is sought at which the relaxed wet network's
// Cauchy stress (dry + capillary) vanishes. Every residual evaluation is a relaxation at the trial box (the event
// model: the active set, relax_wet; the smooth model: relax_smooth_wet), started from an accepted state moved by its
// linear relaxed response or mapped affinely, whichever start has the lower energy. The relaxed response (J = dr/du,
// dq/du, and the stiffness d2E*/du2, E* the relaxed energy):
//   event model: central differences of relaxations at u +- h e_j with the bridge set frozen (2 x unknowns solves);
//   smooth model: exact from one factorization, d2E*/du_i du_j = E_ij - b_i.H^+ b_j and dq/du_j = -H^+ b_j
//       (wet_linear_moduli; the mixed terms by polarization), and J by central differences of the stress along
//       that linear response (no solves).
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
// by 1, the bending-energy unit). The returned state is always an equilibrium of a consistent bridge set (smooth:
// of the whole energy).
struct FreeBoxOptions {
    bool enabled = false;
    bool isotropic = true;       // F = s F0 (robust, the default); false: the full symmetric U (damped Newton)
    double tol = 1e-3;           // on |sigma| / sigma_c, every controlled component
    int max_iter = 40;           // outer (Newton) iterations
    int max_halvings = 6;
    double max_step = 0.05;      // largest change of a component of U per outer iteration
    double fd_strain = 1e-4;     // h of the finite-difference relaxed response (smooth model: of d(sigma)/du alone)
    double snap_width = 1e-7;    // isotropic: a sign-change bracket this narrow (in s) without a root is a snap
    bool stability = true;       // at a converged box, the relaxed stiffness's eigenvalues (event model: 2 x unknowns
                                 // solves; smooth model: one factorization)
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

// The stress of any wet energy at q: P_ab = dE/dF_ab at fixed q, from its strain derivatives along e_a e_b^T
// (WetObjective::strain_derivatives), sigma = P F^T / A.
Stress objective_stress(const WetObjective& W, const Eigen::VectorXd& q);

// The same search on the smooth model (smooth_wet_energy.hpp) from its equilibrium q0 at F0, with its resolved
// parameters (widths set, as relax_smooth_wet had them) and its dry crossings. Each trial box is a relax_smooth_wet
// solve; the relaxed response is exact, from one factorization at the accepted state (see FreeBoxOptions);
// `bridges` in the result are the non-zero pairs (SmoothWetEnergy::bridges), for reports. The returned state is an
// equilibrium of the whole smooth energy at F.
FreeBoxResult smooth_free_box(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const SmoothWetParams& params,
                              const FiberPairs& dry_crossings, const SmoothRelaxOptions& relax,
                              const Eigen::VectorXd& q0, Solver& solver, const FreeBoxOptions& opt);

}  // namespace fibernet
