#pragma once
// The dense rigidity matrix of a body-and-pin framework, a reference for the pebble game on small frameworks.
// Each body has the velocity field v + omega J x (J = rotation by +90 degrees, about the origin), i.e. 3
// unknowns (vx, vy, omega); each extra body b of a pin at p adds 2 rows: velocity of p on b0 = on b.
// With this parametrisation two bodies move as one rigid body in a motion iff their 3 unknowns are equal.
#include <Eigen/Core>
#include <vector>

#include "fibernet/rigidity/body_pin.hpp"

namespace fibernet {

Eigen::MatrixXd rigidity_matrix(const BodyPinFramework& fw);

struct DenseRigidity {
    Eigen::VectorXd singular_values;  // descending (min(rows, cols) of them)
    double cut = 0;                   // a singular value <= cut counts as zero
    int rank = 0;
    long nullity = 0;                 // 3 bodies - rank: zero modes, trivial motions included
    double largest_zero = 0;          // largest singular value at or below the cut (0 if none)
    double smallest_nonzero = 0;      // smallest above it (0 if none)
    std::vector<int> cluster;         // per body: rigid cluster label from the null space (0.. by first body)
    int d = -1;                       // clamped: rank of the top clamp's motions with the bottom clamp grounded
};

// Rank decided with a cut relative to the largest singular value (rel_cut * s_max); the matrix entries are
// O(1) to O(L) pure geometry, so the gap is many orders wide (the tests check it).
DenseRigidity dense_rigidity(const BodyPinFramework& fw, double rel_cut = 1e-8);

}  // namespace fibernet
