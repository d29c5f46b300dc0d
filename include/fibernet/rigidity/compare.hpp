#pragma once
// The exact per-network comparison of pebble-game rigidity with the elastic model (DESIGN.md §2, issue 4 part 3).
// On the open network: pebble-game floppy modes == nullity of the elastic Hessian at rest.
// With both clamps: clamped shear modulus G > g_cut exactly when d < 3, and the clamped Hessian's nullity ==
// floppy modes with both clamps held (floppy_modes - 3 - d).
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/network.hpp"
#include "fibernet/rigidity/elastic_rigidity.hpp"

namespace fibernet {

// G of a network with d = 3 is round-off of the pseudo-inverse: |G| <= 1.4e-7 measured on 400 networks (a = 3;
// the 200 test networks and the 200 of bench/compare_elastic.sh); with d < 3 it is at least the bending scale of
// the softest load path, G >= 3.7e-6 measured. The cut sits near their geometric mean (docs/rigidity.md).
inline constexpr double kShearModulusCut = 7e-7;

struct RigidityComparison {
    int fibers = 0, crosslinks = 0, dofs = 0, clamped_dofs = 0;
    // Open network.
    long floppy_modes = 0, nullity = 0;
    double largest_zero = 0, smallest_nonzero = 0;
    bool nullity_agrees = false;
    // Clamped network.
    int d = -1;
    double G = 0;
    bool shear_agrees = false;
    long floppy_both_grounded = 0, clamped_nullity = 0;
    double clamped_largest_zero = 0, clamped_smallest_nonzero = 0;
    bool clamped_nullity_agrees = false;

    bool agrees() const { return nullity_agrees && shear_agrees && clamped_nullity_agrees; }
};

RigidityComparison compare_rigidity(const Network& open_network, const DiscretizationParams& p,
                                    double zero_cut = kZeroEigenvalueCut, double g_cut = kShearModulusCut);

}  // namespace fibernet
