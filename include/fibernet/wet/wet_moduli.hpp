#pragma once
// Linear moduli of a wet equilibrium with its bridge set frozen (issue 6: "the linear shear modulus dry and wet"):
// the exact relaxed second derivative scale * (E_tt - b.H^+ b) of the wet energy along each strain mode, from one
// Hessian and one factorization (mechanics/moduli.hpp, relaxed_moduli), with the bridges' strain derivatives
// (WetEnergy::strain_derivatives). With beta = 0 (or no bridges) it is the dry energy's linear modulus.
//
// Why not the second difference of relaxed energies at gamma = +-h (relaxed_shear_modulus, wet_run.hpp): a wet
// equilibrium can sit within 1e-4 of shear of a snap (a capillary instability), and a relaxation at +h then lands on
// another branch: on a 1000-fiber network (q = 10, pl = 0.5, seed 1, beta = 0.01) the difference gave G = -0.67,
// -0.012, 0.01429, 0.01430 at h = 1e-3, 1e-4, 1e-5, 1e-6, and the exact linear modulus is 0.01430
// (docs/wet.md, "Shear modulus dry and wet").
#include <Eigen/Core>
#include <vector>

#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/wet/wet_energy.hpp"

namespace fibernet {

// At an equilibrium q of W (its gradient at round-off). Modulus::affine is NaN (no affine prediction here);
// ok = false (value undefined) if H is not positive semidefinite there or the solve failed, with the reason in
// info->message.
std::vector<Modulus> wet_linear_moduli(WetObjective& W, const Eigen::VectorXd& q, const std::vector<StrainMode>& modes,
                                       const ModuliOptions& opt = {}, ModuliInfo* info = nullptr);

}  // namespace fibernet
