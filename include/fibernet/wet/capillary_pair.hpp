#pragma once
// The smooth capillary energy of one pair of segments of different fibers (issue 22; seed ch. 4 intro; docs/wet.md,
// "The smooth model"). A wet network's capillary energy is the sum of this term over every such pair within range
// (neighbour_list.hpp): no bridge set, no events, one C2 function of the node positions.
//
// Segment a joins p0 -> p1 (fiber A), segment b joins q0 -> q1 (fiber B, at the periodic image next to a), with rest
// lengths l0a, l0b, directions u1, u2 and s = sin^2 alpha = (u1 x u2)^2, c = cos^2 alpha = 1 - s.
//
//   E = beta [ b(s) lbar phi(c) W_A W_B  +  (1 - b(s)) (-1) overlap D(delta) ],     lbar = (l0a + l0b) / 2
//
// Crossing term (today's law, capillary.hpp). W_A = sgn(u1 x u2) [H(g1 / eps) - H(g0 / eps)], g_k the signed distance
// of p_k to the line of b, H a C2 step from 0 at -1 to 1 at +1: the share of the crossing with b's line that a holds.
// Along fiber A, for one segment b, these shares telescope (node n's H enters the two segments at n with opposite
// signs), so they sum to H(g_end) - H(g_start): exactly 1 while the crossing is on the fiber, whatever its
// discretization, C2 as the crossing slides across a node, and fading to 0 (rupture) as it slides off an end.
// W_B likewise with the roles swapped. eps (`crossing_width`) is a distance; the arc over which a crossing is shared
// is eps / sin alpha.
//
// Contact term (aligned fibers). Both segments are projected on the bisector e of u1 and +-u2: intervals [a0, a1] and
// [c0, c1]. overlap = A(a0 - c1) + A(a1 - c0) - A(a0 - c0) - A(a1 - c1), with A a C2 smoothing of |x| / 2 over
// |x| < w (`overlap_width`): the length the intervals share (exactly, for |differences| >= w). The formula is additive
// under splitting an interval at a point (the A terms at the split cancel), so the overlaps of two straight fibers'
// segments sum to the fibers' overlap at any discretization, and sliding a fiber along a bundle changes no energy.
// D(delta) = 1 for |delta| <= contact, fading (C2) to 0 at 1.5 contact, delta the offset of the midpoints across e.
//
// The angle blend b(s) goes (C2, in s) from 0 at alpha = angle_lo to 1 at angle_hi: below angle_lo the crossing of two
// near-parallel lines is undefined and only the contact term acts; above angle_hi only the crossing term. The sign
// sgn(u1 x u2) and the bisector's sign sgn(u1.u2) change only where their term's factor is zero.
//
// A pair whose crossing is dry (a crosslinked fiber pair, or one the wetting rule left dry) has only the contact term.
// Every term is exactly zero (value and derivatives) when the segments are farther apart than support_distance().
#include <Eigen/Core>
#include <algorithm>

#include "fibernet/energy/capillary.hpp"

namespace fibernet {

using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix8d = Eigen::Matrix<double, 8, 8>;

struct CapillaryPairParams {
    double beta = 0;              // adhesion energy per unit length of a two-fiber bundle
    CapillaryLaw law;             // phi(cos^2 alpha) of the crossing term
    double crossing_width = 0.1;  // eps: distance over which a crossing passes from one segment to the next
    double contact = 0.2;         // contact distance (the fiber diameter 2/a by default)
    double overlap_width = 0.1;   // w: smoothing of the overlap's ends
    double angle_lo_deg = 10;     // below: contact term only
    double angle_hi_deg = 20;     // above: crossing term only

    // Largest distance between two segments (current length at most `max_length` each) at which a term can be
    // non-zero: the crossing term needs both segments within eps of the other's line, so both within eps / sin
    // angle_lo of the lines' intersection; the contact term needs overlapping projections, midpoints within 1.5
    // contact across e and both segments within angle_hi / 2 of e.
    double support_distance(double max_length) const;
    // Throws InputError naming the value (and `where`) for a width, contact or angle out of range.
    void check(const char* where) const;
};

// CapillaryPairParams::support_distance with its sines taken once: the neighbour list asks it for every segment it
// enters, at each build and at each local solve's update.
struct PairSupport {
    double crossing = 0, contact = 0, slope = 0;  // support(L) = max(crossing, contact + slope L)
    explicit PairSupport(const CapillaryPairParams& p);
    double operator()(double max_length) const { return std::max(crossing, contact + slope * max_length); }
};

// The parts of a pair's energy (for reports): crossing weight b W_A W_B (0..1 for a single crossing), the contact
// term's weight (1 - b) D and overlap, and the two energies.
struct CapillaryPairParts {
    double crossing_weight = 0, contact_weight = 0, overlap = 0;
    double crossing_energy = 0, contact_energy = 0;
    double sin2 = 0;  // sin^2 alpha
    bool nonzero = false;  // a term acts: the energy and its derivatives are not identically zero here
};

// X = (p0, p1, q0, q1). Value and, where non-null, gradient and Hessian in X. wet_crossing: the crossing term applies
// (false: contact term only). project_psd: the Hessian projected to positive semidefinite (eigen-decomposition).
// contact_scale: the contact term enters scaled by it (the partner cap's weight of the pair, bundle_saturation.hpp;
// 1: the pair term itself, bit for bit); contact_grad: the unscaled contact term's gradient.
double capillary_pair_energy(const Vector8d& X, double l0a, double l0b, bool wet_crossing,
                             const CapillaryPairParams& p, Vector8d* grad, Matrix8d* hess, bool project_psd = false,
                             CapillaryPairParts* parts = nullptr, double contact_scale = 1,
                             Vector8d* contact_grad = nullptr);

// Whether the pair's energy is exactly zero with zero derivatives at X (cheap: no derivatives), so that an assembler
// can skip it.
bool capillary_pair_vanishes(const Vector8d& X, bool wet_crossing, const CapillaryPairParams& p);

// The distance between segments p0-p1 and q0-q1 (0 if they intersect).
double segment_distance(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& q0,
                        const Eigen::Vector2d& q1);

}  // namespace fibernet
