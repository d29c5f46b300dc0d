#pragma once
// The wet network's energy at a fixed box deformation F, as a solver sees it (issue 6, part 1):
//   E(q) = dry stretching + bending (NetworkEnergy, unchanged) + sum over bridges of the blended capillary element
// (bridge.hpp). The bridge set is fixed for the lifetime of a WetEnergy: the Hessian pattern (the dry pattern united
// with each bridge's 8-node block) is built once, on first use, and the active-set loop (active_set.hpp) makes a new WetEnergy
// when the set changes. With beta = 0 no bridge term is evaluated and the pattern is the dry one, so every value,
// gradient and Hessian (and hence every solve) is bit for bit the dry one.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>
#include <vector>

#include "fibernet/energy/capillary.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/objective.hpp"
#include "fibernet/wet/bridge.hpp"
#include "fibernet/wet/wet_objective.hpp"

namespace fibernet {

struct WetParams {
    double beta = 0;    // adhesion energy per unit length of a two-fiber bundle (bending-energy units per seed unit)
    CapillaryLaw law;   // phi(cos^2 alpha); default -c
};

struct WetSplit {
    double stretch = 0, bend = 0, capillary = 0;
    double total() const { return stretch + bend + capillary; }
};

class WetEnergy : public WetObjective {
public:
    // Keeps a reference to `dry` (and through it to its Model), which must outlive this energy.
    WetEnergy(const NetworkEnergy& dry, const Eigen::Matrix2d& F, std::vector<Bridge> bridges, WetParams params);
    WetEnergy(const NetworkEnergy&& dry, const Eigen::Matrix2d& F, std::vector<Bridge> bridges, WetParams params) = delete;

    int size() const override { return dry_.num_dofs(); }
    double value(const Eigen::VectorXd& q) override;
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override;
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool project_psd) override;
    const Eigen::SparseMatrix<double>& hessian_pattern() const override;
    // The energy of the coordinates `coords` alone (Objective::restriction; nonlinear elimination): a WetRegion
    // (wet_region.hpp) over their nodes, at the cost of the nodes' elements. nullptr when some node has only one of
    // its two free coordinates in the set (the caller then restricts through value/gradient/Hessian).
    // wet_restriction.cpp.
    std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) override;

    WetSplit split(const Eigen::VectorXd& q) const;
    // Each bridge's own energy at q (for reports and the continuity test).
    std::vector<double> bridge_energies(const Eigen::VectorXd& q) const;

    // The derivatives along a strain path F(t) = F + t dF at fixed q (dE/dt, d2E/dq dt, d2E/dt2 of `out`; its energy is
    // the dry terms' only and its gradient is not filled): the dry terms' (NetworkEnergy::evaluate with kStrain) plus
    // each bridge's. A bridge's coordinates move with F only through its nodes' periodic images and fixed nodes
    // (X_a = x_a + F B0 n_a, x_a = F x_ref for a fixed node: linear in F), so dX_a/dt = w_a = dF r_a with r_a = B0 n_a
    // (+ x_ref for a fixed node), d2X/dt2 = 0, and its terms are g.w, H w and w.H w.
    // For the wet linear moduli (wet_moduli.hpp).
    // comoving: along the affine path of every node instead (kComoving, network_energy.hpp): w_a = dF F^-1 (X_a -
    // X_0), X_0 the element's first node (each element is translation invariant, so the reference point drops out of
    // g.w and H w and only the element's own extent enters, without the cancellation of the large |v|).
    void strain_derivatives(const Eigen::VectorXd& q, const Eigen::Matrix2d& dF, EnergyEval& out,
                            bool comoving = false) const override;

    const NetworkEnergy& dry() const override { return dry_; }
    const Eigen::Matrix2d& F() const override { return F_; }
    const std::vector<Bridge>& bridges() const { return bridges_; }
    const std::vector<BridgeElement>& elements() const { return elements_; }
    const WetParams& params() const { return params_; }
    // Distinct for every WetEnergy constructed in this process (never 0): tells whether data derived from one energy
    // (ElementIncidence, wet_region.hpp) belongs to another.
    std::uint64_t id() const { return id_; }
    // Bridge elements evaluated per chunk when a Hessian is wanted (2 KB of buffer each; default 16384, enough for
    // the dry terms to run beside the first chunk on a 1e4-fiber network). Results do not depend on it.
    void set_chunk(size_t elements) { chunk_ = elements < 1 ? 1 : elements; }

    // What restriction() builds once per energy: the element incidence of every node and each coordinate's node.
    struct RestrictionData;

private:
    double eval(const Eigen::VectorXd& q, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd);
    bool active() const { return params_.beta != 0 && !bridges_.empty(); }

    const NetworkEnergy& dry_;
    Eigen::Matrix2d F_;
    std::vector<Bridge> bridges_;
    std::vector<BridgeElement> elements_;
    WetParams params_;
    std::uint64_t id_;
    // Built on first use (hessian_pattern()); not thread safe (one WetEnergy per solve).
    mutable bool pattern_built_ = false;
    std::shared_ptr<RestrictionData> restriction_;  // built on the first restriction()
    mutable Eigen::SparseMatrix<double> pattern_, dry_H_;
    mutable std::vector<int> dry_slot_;     // dry pattern value index -> union value index
    mutable std::vector<int> bridge_slots_; // 256 per bridge: union value index of local (a, b) with row <= col, else -1
    EnergyEval eval_;
    // Per-chunk element results (eval): filled in parallel, summed in element order.
    static constexpr size_t kParallelMin = 1024;
    size_t chunk_ = 16384;  // set_chunk
    std::vector<double> chunk_E_;
    std::vector<Vector16d, Eigen::aligned_allocator<Vector16d>> chunk_g_;
    std::vector<Matrix16d, Eigen::aligned_allocator<Matrix16d>> chunk_H_;
};

}  // namespace fibernet
