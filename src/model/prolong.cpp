#include "fibernet/model/prolong.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "fibernet/util/error.hpp"

namespace fibernet {
namespace {

void check_same_fibers(const Model& from, const Model& to) {
    if (from.chains.size() != to.chains.size())
        throw InputError("prolong_positions: the models hold " + std::to_string(from.chains.size()) + " and " +
                         std::to_string(to.chains.size()) + " fibers: not discretizations of one network");
    if ((from.box.B0() - to.box.B0()).norm() > 1e-12 * from.box.B0().norm())
        throw InputError("prolong_positions: the models' boxes differ: not discretizations of one network");
    for (size_t f = 0; f < from.chains.size(); ++f) {
        const FiberChain &a = from.chains[f], &b = to.chains[f];
        if (a.s.size() < 2 || b.s.empty()) continue;
        const double tol = 1e-9 * std::max(1.0, a.s.back());
        if (b.s.front() < a.s.front() - tol || b.s.back() > a.s.back() + tol)
            throw InputError("prolong_positions: fiber " + std::to_string(f) + " spans arc " +
                             std::to_string(b.s.front()) + ".." + std::to_string(b.s.back()) + " in the target model but " +
                             std::to_string(a.s.front()) + ".." + std::to_string(a.s.back()) + " in the source");
    }
}

}  // namespace

Eigen::VectorXd prolong_positions(const Model& from, const Eigen::VectorXd& x_from, const Eigen::Matrix2d& B,
                                  const Model& to) {
    if (x_from.size() != from.x.size())
        throw InputError("prolong_positions: " + std::to_string(x_from.size()) + " coordinates for a model of " +
                         std::to_string(from.num_nodes()) + " nodes");
    check_same_fibers(from, to);
    const Eigen::Matrix2d B0 = from.box.B0(), B0inv = B0.inverse();
    Eigen::VectorXd x = to.x;  // nodes on no chain (none, for a model of whole fibers) stay at their reference
    std::vector<char> placed(to.num_nodes(), 0);
    for (size_t f = 0; f < to.chains.size(); ++f) {
        const FiberChain &src = from.chains[f], &dst = to.chains[f];
        if (src.nodes.size() < 2) continue;
        for (size_t n = 0; n < dst.nodes.size(); ++n) {
            const int i = dst.nodes[n];
            if (placed[i]) continue;  // a crosslink: both of its fibers put it at the same place
            // The source segment holding s (the last one for s at the fiber's far end).
            const size_t k = std::min<size_t>(
                std::upper_bound(src.s.begin(), src.s.end(), dst.s[n]) - src.s.begin(), src.s.size() - 1) - 1;
            const Segment& sg = from.segments[src.segments[k]];
            const double t = std::clamp((dst.s[n] - src.s[k]) / (src.s[k + 1] - src.s[k]), 0.0, 1.0);
            const Eigen::Vector2d xa = x_from.segment<2>(2 * sg.i), xb = x_from.segment<2>(2 * sg.j);
            const Eigen::Vector2d ra = from.x.segment<2>(2 * sg.i);
            const Eigen::Vector2d d = xb - xa + B * sg.shift.cast<double>();
            const Eigen::Vector2d d0 = from.x.segment<2>(2 * sg.j) - ra + B0 * sg.shift.cast<double>();
            // The point's reference lies in the image of i's reference that the lattice vector m names; its deformed
            // position in that image is carried back by B m.
            const Eigen::Vector2d m = (B0inv * (ra + t * d0 - to.x.segment<2>(2 * i))).array().round();
            x.segment<2>(2 * i) = xa + t * d - B * m;
            placed[i] = 1;
        }
    }
    return x;
}

}  // namespace fibernet
