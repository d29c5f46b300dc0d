#pragma once
// Linear (differential) moduli at an equilibrium from one Hessian factorization (DESIGN.md §2, docs/moduli.md).
//
// Along a strain path F(t) = F + t dF through an equilibrium q*:
//   d2E/dt2 (relaxed) = E_tt - E_xt^T H^+ E_xt,    H = E_xx, E_xt = d2E/dx dt, E_tt = d2E/dt2 at fixed x,
// and a modulus is scale * that. E_xt lies in range(H) at an equilibrium (differentiate g(q*(t), t) = 0), so
// H's null space (translations, floppy clusters) does not contribute. H^+ E_xt is computed with ONE
// factorization of H + delta D (D = |diag H|, delta = 1e-12, grown on failure), used as the preconditioner of
// conjugate gradients on H u = E_xt: the preconditioned spectrum lambda / (lambda + delta) (lambda: eigenvalues of
// D^-1/2 H D^-1/2) is 1 except for the few modes with lambda ~ delta, so CG converges in a handful of steps, each one
// solve and no new factorization; from u_0 = 0 it never enters the null space (the residual stays in range(H)). The
// shift is not a bias: CG removes it. `error` estimates what the solve and the state leave (docs/moduli.md "Error
// estimates"): the CG's tail, what its true residual shows within its rounding, and the change one Newton step away.
//
// Normalisations (2D, current box area A):
//   shear  G: dF = e_x e_y^T F (simple shear of the current state), G = (1/A) d2E/dt2;
//   bulk   K: dF = F (isotropic dilation, dA/A = 2 dt), K = A d2E/dA2 = (1/(4A)) d2E/dt2  (K = lambda + mu in 2D);
//   path    : dF = strain_direction(kind) of the scene's path, (1/A) d2E/dt2.
// The affine prediction of each is scale * d2E/dt2 along the affine path x(t) = F(t) x_ref (no relaxation).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <string>
#include <vector>

#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"

namespace fibernet {

struct StrainMode {
    std::string name;
    Eigen::Matrix2d dF = Eigen::Matrix2d::Zero();
    double scale = 1;    // modulus = scale * relaxed d2E/dt2
};
StrainMode shear_mode(const Eigen::Matrix2d& F, double area);
StrainMode bulk_mode(const Eigen::Matrix2d& F, double area);
StrainMode path_mode(StrainKind k, double area);

struct Modulus {
    std::string name;
    double value = 0;       // scale * (E_tt - E_xt^T H^+ E_xt); NaN when !ok
    double affine = 0;      // scale * E_tt of the affinely deformed reference (the affine prediction)
    double E_tt = 0, correction = 0;  // unscaled affine (comoving) part and non-affine correction at the equilibrium
    // Estimated |value error| (scaled): the largest of the CG's tail, the cancellation's round-off, the error the
    // solve's true residual shows, and (linear_moduli, ModuliOptions::state_error) state_error.
    double error = 0;
    double state_error = 0;  // |value at q' - value at q|, q' one Newton step from q: the state's share
    int refinements = 0;        // conjugate-gradient steps
    bool stalled = false;       // round-off stopped the conjugate gradients before they converged
    Eigen::VectorXd response;   // a solution of H r = E_xt: dq/dt = -response along the mode
    bool ok = false;        // false: H + delta D could not be factored or the refinement did not converge
};

struct ModuliOptions {
    double delta_rel = 1e-12;   // initial shift delta of H + delta |diag H| (x100 while the factorization fails)
    int max_refinements = 200;  // conjugate-gradient steps
    double refine_tol = 1e-13;  // stop when a CG increment of E_xt.u is below this fraction of max(E_tt, b.M b)
    // linear_moduli: q must be an equilibrium, max|g| <= max(equilibrium_tol, the round-off floor of the coordinates
    // (roundoff_floor, newton.hpp)); otherwise every modulus is refused (ok = false, the message says why).
    double equilibrium_tol = 1e-6;
    // linear_moduli: also compute the moduli one Newton step away and count their difference in `error` (an
    // equilibrium is known only to tol or the round-off floor; one more factorization). Off in sweeps, which report
    // no errors.
    bool state_error = true;
};

struct ModuliInfo {
    double delta = 0;          // shift delta of the factorization of H + delta |diag H| used
    // H + delta D failed to factor at the first shift (round-off made pivots negative): H is ill-conditioned at
    // round-off, the CG resolves its soft modes poorly, and the errors may be understated (docs/moduli.md).
    bool shift_grown = false;
    double grad_max = 0, grad_floor = 0;  // linear_moduli: max|g| at q and its round-off floor
    int factorizations = 0;
    double seconds_assembly = 0, seconds_factorization = 0, seconds_solve = 0, seconds_affine = 0, seconds_total = 0;
    double seconds_one_factorization = 0;   // the successful factorization alone, for the modulus/factorization ratio
    bool state_checked = false;  // the state's share of the errors was estimated (ModuliOptions::state_error)
    double state_step = 0;       // max |q' - q| of that Newton step
    double seconds_state = 0;
    std::string message;
};

// The relaxed part on its own, for any energy that provides its Hessian H (upper triangle, at an equilibrium) and,
// per mode, the fixed-coordinate strain derivatives: value = scale * (E_tt - b.H^+ b), computed in comoving
// coordinates (v: the affine velocity dF F^-1 x of the free coordinates, affine_velocity) as above, or the
// comoving ones themselves (StrainTerms::comoving: the dry energy's, summed per element without cancellation). linear_moduli
// is this plus the dry energy's derivatives and the affine prediction; the wet energy's linear moduli use it with the
// bridges' terms (wet/wet_moduli.hpp). Modulus::affine is left 0.
struct StrainTerms {
    double E_tt = 0;    // d2E/dt2 at fixed q
    Eigen::VectorXd b;  // d2E/dq dt at fixed q
    Eigen::VectorXd v;  // affine velocity of the free coordinates
    // E_tt and b are already the comoving E_tt + 2 v.b + v.H v and b + H v, summed per element (kComoving,
    // network_energy.hpp); E_tt_size: the sum of its terms' magnitudes.
    bool comoving = false;
    double E_tt_size = 0;
};
class LinearSolver;
std::vector<Modulus> relaxed_moduli(const Eigen::SparseMatrix<double>& H, const std::vector<StrainTerms>& terms,
                                    const std::vector<StrainMode>& modes, const ModuliOptions& opt = {},
                                    ModuliInfo* info = nullptr, LinearSolver* llt = nullptr);
// V x_i for every free node i (x: all nodes' positions, 2 per node), in q's layout.
Eigen::VectorXd affine_velocity(const NetworkEnergy& e, const Eigen::VectorXd& x, const Eigen::Matrix2d& V);

// llt: an optional definite linear solver (linear_solver.hpp) already analyzed for e.hessian_pattern() (e.g.
// Solver::factorization_for() after the equilibrium solve), so that the modulus costs one numeric factorization and
// no symbolic analysis; one that is not definite() is not used. Its numeric factor is overwritten.
std::vector<Modulus> linear_moduli(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                                   const std::vector<StrainMode>& modes, const ModuliOptions& opt = {},
                                   ModuliInfo* info = nullptr, LinearSolver* llt = nullptr);

}  // namespace fibernet
