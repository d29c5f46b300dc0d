#pragma once
// The dry network energy restricted to a set of coordinates (issue 23, nonlinear elimination): a StrainedEnergy as a
// function of some coordinates alone, every other one held. Only the segments and hinges with a node in the set are
// evaluated, so a local solve on a few hundred nodes costs their elements, not the network's
// (Objective::restriction; solve/nonlinear_elimination.hpp).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/objective.hpp"

namespace fibernet {

// Per node the segments and hinges that hold it (compressed rows), and per coordinate of q its node: built once per
// energy (O(network)), shared by every region of it.
struct NodeElements {
    std::vector<int> seg_start, seg, hinge_start, hinge;
    std::vector<int> dof_node;  // coordinate of q -> 2 node + c
};
NodeElements node_elements(const NetworkEnergy& e);
// The elements listed (compressed rows start/list, as in NodeElements) at any of `nodes`, sorted and distinct.
std::vector<int> elements_at(const std::vector<int>& start, const std::vector<int>& list, const std::vector<int>& nodes);

class NetworkRegion : public EvaluatedObjective {
public:
    // e's energy at deformation F over the coordinates `coords` of q (sorted, distinct); the others stay at q.
    // Keeps references to e and inc.
    NetworkRegion(const NetworkEnergy& e, const Eigen::Matrix2d& F, const NodeElements& inc, const Eigen::VectorXd& q,
                  const std::vector<int>& coords);

    int size() const override { return static_cast<int>(coords_.size()); }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return pattern_; }

private:
    double eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) override;

    const NetworkEnergy& e_;
    Eigen::Matrix2d F_;
    std::vector<int> coords_, coord_u_;  // region coordinate -> coordinate of q, and its entry of u_
    Eigen::VectorXd u_;                  // the elements' nodes' displacements (other entries unset); an evaluation
                                         // rewrites the region's entries
    std::vector<int> segs_, hinges_;     // elements with a node in the region
    std::vector<int> seg_idx_, hinge_idx_;    // per element and local coordinate: region index or -1 (held)
    std::vector<int> seg_slot_, hinge_slot_;  // per element: value slot of each local pair (a, b), -1 if none
    Eigen::SparseMatrix<double> pattern_;
};

}  // namespace fibernet
