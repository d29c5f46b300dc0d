#pragma once
// The elastic side of the exact comparison (DESIGN.md §2): at the stress-free rest state the zero modes of the
// elastic Hessian are the motions in which every fiber moves rigidly, so their number must equal the pebble
// game's floppy-mode count, and the clamped shear modulus must be > 0 exactly when d < 3. Dense linear algebra:
// for small networks only (a few hundred degrees of freedom).
#include <Eigen/Core>

#include "fibernet/model/discretize.hpp"
#include "fibernet/network/clamp.hpp"

namespace fibernet {

// Eigenvalues are those of the Jacobi-scaled Hessian S = W H W, W = diag(1 / sqrt(max(H_ii, 1))): a congruence,
// so S has exactly the nullity of H (Sylvester's law of inertia). Unscaled, "zero" was first decided on the
// bending-energy scale (DESIGN.md §2: zeros < 2e-9, non-zeros > 4e-7, cut 3e-8); that held on the 200 test
// networks but failed on one of 200 more (bench/compare_elastic.sh, q = 7, pl = 0.9, seed 26): two crosslinks
// 1.7e-5 fiber lengths apart made a segment of 1.7e-4 ls, lambda_max = 4e9, and round-off zeros reached
// 5.5e-8 = 0.06 eps lambda_max, above the cut (the dense rigidity matrix confirmed the pebble count). Scaled,
// zeros stay below 1e-14 and non-zeros above 4.5e-12 on all 400 networks; the cut sits between them.
inline constexpr double kZeroEigenvalueCut = 1e-12;

struct HessianSpectrum {
    Eigen::VectorXd eigenvalues;    // of the Jacobi-scaled Hessian, ascending
    double cut = kZeroEigenvalueCut;
    long nullity = 0;               // eigenvalues <= cut
    double largest_zero = 0;        // largest |eigenvalue| at or below the cut
    double smallest_nonzero = 0;    // smallest eigenvalue above it (0 if none)
};

// Eigenvalues of the (Jacobi-scaled) Hessian over the free coordinates at the rest state (q = reference, F = I).
HessianSpectrum hessian_spectrum(const Model& model, double cut = kZeroEigenvalueCut);

// The clamped network discretized, with the cut fiber ends fixed (they follow F: the bottom clamp stays, the
// top clamp moves sideways by gamma L under shear).
Model clamped_model(const ClampedNetwork& clamped, const DiscretizationParams& p);

// Clamped shear modulus at the rest state, G = (E_tt - E_xt^T H^+ E_xt) / A, with H^+ the pseudo-inverse on
// the eigen-decomposition of the scaled Hessian that drops eigenvalues <= cut. Model units (energy per seed-unit
// area).
double clamped_shear_modulus(const Model& model, double cut = kZeroEigenvalueCut);

}  // namespace fibernet
