// WetEnergy::restriction (wet_energy.hpp): the wet energy of a set of coordinates alone, for Newton's nonlinear
// elimination (nonlinear_elimination.hpp), on the region machinery of the active set's local rounds (wet_region.hpp).
#include <algorithm>

#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/wet/wet_region.hpp"

namespace fibernet {

struct WetEnergy::RestrictionData {
    ElementIncidence incidence;
    std::vector<int> coordinate_node;  // coordinate -> node
};

namespace {
// A WetRegion with the state it evaluates at (every node's displacement and position at q, RegionState) of its own.
class WetRestriction : public Objective {
public:
    WetRestriction(const WetEnergy& W, const Eigen::VectorXd& q, const std::vector<int>& nodes,
                   const ElementIncidence& inc)
        : state_(W, q), region_(W, state_, nodes, inc) {}
    int size() const override { return region_.size(); }
    double value(const Eigen::VectorXd& qa) override { return region_.value(qa); }
    double gradient(const Eigen::VectorXd& qa, Eigen::VectorXd& g) override { return region_.gradient(qa, g); }
    double hessian(const Eigen::VectorXd& qa, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        return region_.hessian(qa, g, H, psd);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return region_.hessian_pattern(); }
    const std::vector<int>& dofs() const { return region_.dofs(); }

private:
    RegionState state_;
    WetRegion region_;
};
}  // namespace

std::unique_ptr<Objective> WetEnergy::restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) {
    if (!restriction_) {
        auto d = std::make_shared<RestrictionData>();
        d->incidence = element_incidence(*this);
        d->coordinate_node.assign(size(), -1);
        for (int v = 0; v < dry_.model().num_nodes(); ++v)
            for (int c = 0; c < 2; ++c)
                if (dry_.dof(v, c) >= 0) d->coordinate_node[dry_.dof(v, c)] = v;
        restriction_ = std::move(d);
    }
    std::vector<int> nodes;
    nodes.reserve(coords.size());
    for (int c : coords) {
        if (c < 0 || c >= size()) throw std::logic_error("WetEnergy::restriction: coordinate out of range");
        nodes.push_back(restriction_->coordinate_node[c]);
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    auto r = std::make_unique<WetRestriction>(*this, q, nodes, restriction_->incidence);
    // The region holds every free coordinate of its nodes, in the nodes' order: the set itself, or not offered.
    if (r->dofs() != coords) return nullptr;
    return r;
}

}  // namespace fibernet
