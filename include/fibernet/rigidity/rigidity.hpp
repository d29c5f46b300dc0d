#pragma once
// Rigidity of a body-and-pin framework by the (3,3) pebble game (DESIGN.md §2; Lee & Streinu 2008):
// floppy modes, independent and redundant constraints, rigid clusters, and with clamps the top clamp's
// remaining degrees of freedom d and connectivity spanning.
#include <vector>

#include "fibernet/rigidity/body_pin.hpp"

namespace fibernet {

struct RigidityResult {
    int fibers = 0, bodies = 0, pins = 0;
    long bars = 0;                 // 2 per pinned body pair
    long independent = 0, redundant = 0;
    long floppy_modes = 0;         // 3 bodies - independent: every zero mode, trivial motions included
    std::vector<int> cluster;      // rigid cluster label per body, 0.. in order of first body
    int clusters = 0;
    int largest_cluster = 0;       // fibers in the largest rigid cluster

    // Clamped frameworks only.
    bool clamped = false;
    int d = -1;                    // degrees of freedom of the top clamp with the bottom clamp grounded (0..3)
    bool rigid_spanning = false;   // d == 0: both clamps in one rigid cluster
    bool carries_shear = false;    // d < 3: at least one independent constraint reaches the top clamp
    bool connected_spanning = false;  // the clamps are joined by a chain of pins (ordinary percolation)
    long floppy_grounded = 0;      // zero modes with the bottom clamp grounded (floppy_modes - 3)
    long floppy_both_grounded = 0; // zero modes with both clamps held (floppy_modes - 3 - d)
};

RigidityResult analyze_rigidity(const BodyPinFramework& fw);

// Union-find over pins only: connected component label per body (0.. in order of first body).
std::vector<int> pin_components(const BodyPinFramework& fw);

}  // namespace fibernet
