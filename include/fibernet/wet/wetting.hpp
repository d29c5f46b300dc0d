#pragma once
// Which crossings of a network get a capillary bridge when it is wetted (issue 6: all crossings by default, free
// crossings only, or a random fraction), and the bridge made for a given crossing of two segments.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/network/network.hpp"
#include "fibernet/wet/bridge.hpp"

namespace fibernet {

enum class WetWhich { All, Free, Fraction };
WetWhich parse_wet_which(const std::string& s);  // "all" | "free" | "fraction"; InputError otherwise
std::string to_string(WetWhich w);

struct WettingRule {
    WetWhich which = WetWhich::All;
    double fraction = 1;          // WetWhich::Fraction: probability that a crossing is wet
    std::uint64_t seed = 1;
};

// The bridge on the segment pair (k1 of fiber f1, k2 of fiber f2), f1 != f2, taking fiber 2 at the periodic image
// nearest to fiber 1's home at node positions x (box matrix B). Sides are swapped so that f1 < f2.
Bridge make_bridge(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, int f1, int k1, int f2, int k2,
                   int crossing = -1);

// Which network crossings the rule wets (one flag per crossing of net.crossings). Fraction draws one number per
// crossing from `seed` in crossing order (reproducible; the choice of one does not shift the others).
std::vector<char> wet_choice(const Network& net, const WettingRule& rule);

// The fiber pairs of the crossings the rule leaves dry. A crossing moves with its fibers, so a dry one stays dry:
// the active set forms no crossing bridge between such a pair (ActiveSetOptions::dry_pairs); without this, the first
// update gave every free crossing a bridge again, whatever the fraction.
FiberPairs dry_pairs(const Network& net, const WettingRule& rule);

// One bridge per wet network crossing, on the segments that contain it (a crosslink's supernode starts both homes),
// at node positions x. Crossings are drawn for WetWhich::Fraction from `seed` in crossing order (reproducible).
std::vector<Bridge> wet_crossings(const Network& net, const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                  const WettingRule& rule);

}  // namespace fibernet
