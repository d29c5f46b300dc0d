#pragma once
// Parts of the wet network solved on their own (issue 6, "Performance"). On a large network the events of a round
// (bridges that move, form or rupture) are local, and after the first rounds most of the network is near equilibrium:
// in a 1e4-fiber run the regions that needed a solve held a median 2 % of the coordinates (docs/wet.md, "Local rounds"). A
// WetRegion is the energy as a function of the coordinates of a set of nodes only, every other node held where it is.
// The connected parts of a region share no element, so their energies are independent: each is minimized on its own,
// with its own line search, at the cost of its size (a global line search is set by the network's worst spot).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <vector>

#include "fibernet/energy/objective.hpp"
#include "fibernet/wet/wet_energy.hpp"

namespace fibernet {

// The elements of W at each node (compressed rows): segments, hinges and bridges, for building regions in time
// proportional to their size.
struct ElementIncidence {
    std::vector<int> seg_start, seg, hinge_start, hinge, bridge_start, bridge;
    std::uint64_t bridges_of = 0;  // WetEnergy::id() of the energy the bridge rows were built from
};
ElementIncidence element_incidence(const WetEnergy& W);
// Rebuilds only the bridge rows of inc for W: the segment and hinge rows depend only on the model, which every
// WetEnergy of one relaxation shares (relax_wet rebuilds O(bridges) per round, not O(network)).
void update_bridge_incidence(const WetEnergy& W, ElementIncidence& inc);
// Makes inc W's incidence at the least cost: built whole if empty, its bridge rows rebuilt if they are another
// energy's (same model), else left as it is.
void incidence_for(const WetEnergy& W, ElementIncidence& inc);

// Flags (one per node) the nodes holding a free coordinate with |g| > threshold.
std::vector<char> nodes_above(const NetworkEnergy& dry, const Eigen::VectorXd& g, double threshold);
// Grows the flagged set `hops` times by whole elements of W (a node joins when it shares a segment, hinge or bridge
// with a node already in); inc is W's incidence. Costs the size of the grown set, not of the network.
void grow_region(const WetEnergy& W, const ElementIncidence& inc, std::vector<char>& in, int hops);
// The flagged nodes with coordinates split into parts joined by elements (nodes of distinct parts share no element
// but held ones); each sorted. Fixed nodes never move and join nothing.
std::vector<std::vector<int>> region_parts(const WetEnergy& W, const ElementIncidence& inc, const std::vector<char>& in);

// Recomputes g's entries at the free coordinates of the flagged nodes as W's gradient at q: each from every element
// at its node, summed in the order WetEnergy::gradient sums them (segments, hinges, bridges, each by index), so they
// are W.gradient(q)'s bit for bit. Where the other entries are those of an earlier gradient whose elements at their
// nodes were the same (relax_wet after a local round: only the region's nodes moved, a few bridges changed), g is
// W.gradient(q) bit for bit at the cost of the flagged nodes' elements, not of the network's.
void gradient_rows(const WetEnergy& W, const ElementIncidence& inc, const Eigen::VectorXd& q,
                   const std::vector<char>& nodes, Eigen::VectorXd& g);

// Brings g, the gradient of an earlier energy W0 at an earlier state q0, to W's gradient at q, bit for bit, where q
// differs from q0 only at the `moved` nodes and W's elements from W0's only by bridges whose nodes are all `touched`
// (bridges added, removed, moved or locked), the others in the same order: the rows that can differ are those of the
// nodes of the elements at moved nodes and the touched nodes (recomputed by gradient_rows). inc is W's incidence.
void update_gradient(const WetEnergy& W, const ElementIncidence& inc, const Eigen::VectorXd& q, std::vector<char> moved,
                     const std::vector<char>& touched, Eigen::VectorXd& g);

// Every node's displacement and position at a state q (NetworkEnergy::displacements, positions), computed once and
// shared by the parts of one region: a part's evaluations rewrite its own nodes' entries only, which no other part's
// elements read, so parts solved one after another need no copy each (at 1e4 fibers a copy costs as much as
// evaluating a small part).
struct RegionState {
    RegionState(const WetEnergy& W, const Eigen::VectorXd& q);
    Eigen::VectorXd u, x;
};

class WetRegion : public Objective {
public:
    // W's energy as a function of the free coordinates of `nodes`; the other nodes stay where `state` has them (at q).
    // Elements with no node in the region are left out: their energy is constant here, so value() is W's energy less
    // a constant, and gradient and Hessian are W's restricted to the region's coordinates.
    WetRegion(const WetEnergy& W, RegionState& state, const std::vector<int>& nodes, const ElementIncidence& inc);

    int size() const override { return static_cast<int>(dofs_.size()); }
    double value(const Eigen::VectorXd& qa) override { return eval(qa, nullptr, nullptr, false); }
    double gradient(const Eigen::VectorXd& qa, Eigen::VectorXd& g) override { return eval(qa, &g, nullptr, false); }
    double hessian(const Eigen::VectorXd& qa, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        return eval(qa, &g, &H, psd);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override;

    // The region's coordinates of a full state, and back into one.
    Eigen::VectorXd restrict(const Eigen::VectorXd& q) const;
    void embed(const Eigen::VectorXd& qa, Eigen::VectorXd& q) const;
    const std::vector<int>& dofs() const { return dofs_; }  // region coordinate -> coordinate of W

private:
    double eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd);

    const WetEnergy& W_;
    Eigen::VectorXd &u_, &x_;  // the shared state; an evaluation rewrites the region's entries only
    std::vector<int> dofs_, dof_node_;           // region coordinate -> coordinate of W, and its node's u_ index
    std::vector<int> segs_, hinges_, bridges_;  // elements with a node in the region
    // Per element: region index of each local coordinate (-1: held), and the Hessian value slot of each local pair
    // (a, b) with row <= column (-1 otherwise); segment 4 / 16, hinge 6 / 36, bridge 16 / 256.
    std::vector<int> seg_idx_, hinge_idx_, bridge_idx_;
    mutable std::vector<int> seg_slot_, hinge_slot_, bridge_slot_;  // built with the pattern, on first use
    mutable Eigen::SparseMatrix<double> pattern_;
    mutable bool pattern_built_ = false;
};

}  // namespace fibernet
