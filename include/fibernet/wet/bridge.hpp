#pragma once
// A capillary bridge that moves with its crossing (issue 6, part 2; seed ch. 4 intro: "a mobile, crosslink-like
// object"). A bridge lives on a *home* pair of segments, one on each fiber, where the two fibers cross. Its energy is
// the capillary term of capillary.hpp, E = beta l phi(cos^2 alpha), l = mean rest length of the pair.
//
// Sliding across a node. The crossing moves along each fiber as the network deforms; when it passes a node the bridge
// moves to the neighbouring segment. To keep the energy continuous across that move (issue 6: no jump along a path
// that drags a crossing across nodes), the element blends the home segment with its neighbours on both fibers:
//
//   E = sum_{i in {-,0,+}} sum_{j in {-,0,+}} w1_i w2_j beta l_ij phi(c(d1_i, d2_j))
//
// Fiber 1's weights depend on z, the arc distance from a node to the crossing, measured from the signed distances g
// of fiber-1 nodes to the line of fiber 2's home segment: z_n = -g_n / r_n with r_n the mean rate dg/ds of the two
// segments at node n (symmetric, so both segments compute the same z_n). With S a C2 smoothstep over |z| < delta_n,
// delta_n = min(l0 of the two segments) / 4:  w_- = 1 - S(z_n / delta_n), w_+ = S(z_{n+1} / delta_{n+1}),
// w_0 = 1 - w_- - w_+. At a node the weights are 1/2 and 1/2, and the element of home a and that of home a- are the
// same function near their shared node, so moving the bridge changes no energy. A missing neighbour (fiber end) has
// a zero term: the bridge fades out as its crossing slides off the end, and ruptures once its weight is zero.
// The window ends the same way: a neighbour's weight fades out (C2, S((z + l0 + df) / df) with df = l0 / 8 on the
// - side, mirrored on the + side) as the crossing passes the neighbour's far node, over a quarter of its length, so a
// bridge whose crossing left its 3 x 3 window during a solve of a fixed set pulls no more (it used to keep the
// neighbour's full term however far away the crossing ran). A consistent set never reaches that zone.
// Nearly parallel pairs have no well-defined crossing (r -> 0 sends it to infinity): as any |r| (~ sin alpha) falls from
// sin 5 deg to sin 2 deg, the blend fades (C2) into home-only weights (w_0 = 1), and such a bridge does not move.
//
// Bundles. Two zipped fibers lie side by side: their crossing is undefined. A bridge whose home pair is nearly aligned
// and in contact is *locked* (active_set.hpp): its weights are w_0 = 1 on its home pair, it no longer slides, and it
// ruptures when the pair loses contact. Zipped segment pairs get locked bridges of their own, one per segment, so a
// bundle holds one bridge per segment pair and adheres with -beta per unit overlap (issue 6).
#include <Eigen/Core>
#include <set>
#include <utility>
#include <vector>

#include "fibernet/energy/capillary.hpp"
#include "fibernet/model/model.hpp"

namespace fibernet {

// Fiber pairs (lower index first).
using FiberPairs = std::set<std::pair<int, int>>;

struct Bridge {
    int f1 = 0, f2 = 0;  // fibers, f1 != f2
    int k1 = 0, k2 = 0;  // home segments: index into chains[f].segments
    // Fiber 2's node chains[f2].nodes[k2] is taken at x + B image, the periodic image next to fiber 1's home.
    Eigen::Vector2i image{0, 0};
    int crossing = -1;   // network crossing it was made for; -1 if it formed during a relaxation
    bool locked = false; // a bundle bridge: home pair only, does not slide

    bool operator==(const Bridge& o) const {
        return f1 == o.f1 && f2 == o.f2 && k1 == o.k1 && k2 == o.k2 && image == o.image;
    }
};

using Vector16d = Eigen::Matrix<double, 16, 1>;
using Matrix16d = Eigen::Matrix<double, 16, 16>;

// A bridge resolved against the model: side s uses local nodes 4s..4s+3 = chain nodes k-1, k, k+1, k+2
// (-1 where the fiber ends), each at its image `shift` in the bridge's frame; segments -, 0, + have rest lengths l0.
struct BridgeElement {
    int node[8];
    Eigen::Vector2i shift[8];
    double l0[6];  // side s: l0[3s + 0/1/2] for segments -, 0, +; 0 where absent
    bool locked = false;
};
BridgeElement resolve(const Model& m, const Bridge& b);
// resolve(m, b).node alone, at a fraction of its cost (the active-set loop asks it of every bridge each round).
void bridge_nodes(const Model& m, const Bridge& b, int node[8]);

// Local coordinates of the element (absent nodes: zero) at node positions x and box matrix B.
Vector16d element_coordinates(const BridgeElement& e, const Eigen::VectorXd& x, const Eigen::Matrix2d& B);

// Energy of the blended element and, where non-null, its gradient and Hessian in the local coordinates.
// project_psd: the Hessian projected to positive semidefinite (per segment pair where the weights are constant, which
// is cheap; the whole 16 x 16 block inside a blend zone).
double bridge_element_energy(const BridgeElement& e, const Vector16d& X, double beta, const CapillaryLaw& law,
                             Vector16d* grad, Matrix16d* hess, bool project_psd = false);
// The same by the original evaluation (weights differentiated in Jet<16> through all 16 coordinates): several times
// slower, kept to check bridge_element_energy against (tests/wet/bridge_fast_test.cpp, bench/bench_bridge_eval.cpp).
double bridge_element_energy_reference(const BridgeElement& e, const Vector16d& X, double beta,
                                       const CapillaryLaw& law, Vector16d* grad, Matrix16d* hess,
                                       bool project_psd = false);

// Where the crossing is relative to the home pair: side s, z[s][0] = arc distance from the home's start node to the
// crossing (> 0: past the start), z[s][1] = from its end node (< 0: before the end), delta[s][.] the blend
// half-widths. defined = false for a locked bridge or a nearly parallel pair (some |r| < sin 5 deg): it does not move.
struct CrossingPosition {
    double z[2][2], delta[2][2];
    bool defined = true;
    // The crossing lies inside the home segment of side s.
    bool inside(int s) const { return z[s][0] >= 0 && z[s][1] <= 0; }
};
CrossingPosition crossing_position(const BridgeElement& e, const Vector16d& X);

}  // namespace fibernet
