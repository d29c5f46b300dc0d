#pragma once
// The rigid-fiber limit of a network (DESIGN.md §2, seed §3): every fiber is a rigid body with 3 degrees of
// freedom, every crosslink a pin. Pins that coincide on a fiber (hand-made junctions of three or more fibers)
// are one pin shared by all their fibers, as in discretize(). With clamps, the bottom and the top clamp are
// two more bodies and each cut fiber end is pinned to one of them.
// Jackson & Jordan (2008): body-and-pin frameworks whose pins on each body are collinear (rods) have the
// generic rigidity of body-and-pin frameworks, so the counting of the (3,3) pebble game applies.
#include <Eigen/Core>
#include <vector>

#include "fibernet/network/clamp.hpp"
#include "fibernet/network/network.hpp"

namespace fibernet {

struct BodyPinFramework {
    int fibers = 0;   // bodies 0 .. fibers-1 are the fibers
    int bodies = 0;   // fibers, + 2 clamp bodies when clamped
    bool clamped = false;
    std::vector<Eigen::Vector2d> pin_point;  // per pin, in fiber lengths
    std::vector<int> pin_offset{0};          // bodies of pin k: pin_body[pin_offset[k] .. pin_offset[k+1])
    std::vector<int> pin_body;

    int num_pins() const { return static_cast<int>(pin_point.size()); }
    int bottom() const { return fibers; }     // clamp bodies (clamped only)
    int top() const { return fibers + 1; }
    // Bars of the equivalent body-and-bar framework: 2 per extra body of each pin.
    long num_bars() const { return 2L * (static_cast<long>(pin_body.size()) - num_pins()); }
};

// Open network (throws InputError for a periodic one: periodic rigidity is not this count).
BodyPinFramework body_pin_framework(const Network& net);
// Clamped network: fibers + bottom + top clamp bodies.
BodyPinFramework body_pin_framework(const ClampedNetwork& clamped);

}  // namespace fibernet
