#pragma once
// The network energy E(q, F) = sum of segment stretching + hinge bending terms (seed eqs. 4.14, 4.15),
// assembled into a global gradient and a sparse Hessian over the free coordinates q, together with the
// derivatives with respect to a strain parameter t along F(t) = F + t dF (DESIGN.md §2).
//
// Coordinates: q holds the free nodes' displacements from their reference positions, x = x_ref + q; a fixed node
// (clamp) sits at F x_ref. Segment vectors are formed as d = d0 + (F - I) B0 n + (u_j - u_i) from the exact rest
// vector d0, so no large wrapped coordinates (~L) are subtracted: the gradient's round-off floor is set by the
// displacements (~1), not by the box size (~100-1000). Derivatives with respect to q equal those with respect to x.
// The Hessian's upper-triangular pattern is built once per model; evaluate() refills the values.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>
#include <vector>

#include "fibernet/energy/bend.hpp"
#include "fibernet/energy/element_assembly.hpp"
#include "fibernet/energy/objective.hpp"
#include "fibernet/energy/stretch.hpp"
#include "fibernet/model/model.hpp"

namespace fibernet {

struct NodeElements;  // network_region.hpp

struct EnergyParams {
    StretchLaw stretch;
};

// What evaluate() computes; combine with |.
enum Want : unsigned {
    kValue = 0,
    kGradient = 1,
    kHessian = 2,
    kStrain = 4,       // dE/dt, d2E/dq dt, d2E/dt2 along dF
    kProjectPSD = 8,   // project each element's Hessian to PSD (Hessian only; strain derivatives stay exact)
    // With kStrain: the strain derivatives along the affine path of all nodes, x(t) = (I + t dF F^-1) x (comoving
    // coordinates, docs/moduli.md) instead of at fixed q: per element dd/dt = dF F^-1 d, so that
    //   d2E_dt2 = E_tt + 2 v.E_xt + v.H v,  d2E_dqdt = E_xt + H v  (v = dF F^-1 x of the free nodes)
    // come from the elements' own edge vectors, without the cancellation of the large |v| (up to L) that the sums
    // on the right carry through H's stiff entries.
    kComoving = 16,
};

struct EnergyEval {
    double energy = 0, stretch = 0, bend = 0;  // the total and the two dry terms' shares (terms, by name)
    std::vector<double> terms;       // the energy by term, in NetworkEnergy::term_names() order
    Eigen::VectorXd gradient;        // over free coordinates
    double dE_dt = 0;                // strain derivatives along dF
    Eigen::VectorXd d2E_dqdt;
    double d2E_dt2 = 0;
    double d2E_dt2_size = 0;         // sum of the elements' |terms| of d2E_dt2 (the scale of its rounding)
};

class NetworkEnergy {
public:
    // Keeps a reference to `model`, which must outlive the energy (a temporary would dangle: refused).
    explicit NetworkEnergy(const Model& model, EnergyParams params = {});
    NetworkEnergy(const Model&& model, EnergyParams params = {}) = delete;

    const Model& model() const { return model_; }
    int num_dofs() const { return ndof_; }
    // Free coordinates (displacements) of a node-position vector (2 per node), and back (fixed nodes at F x_ref).
    Eigen::VectorXd dofs(const Eigen::VectorXd& x) const;
    // The free coordinates of a displacement vector u (2 per node, u = x - x_ref): exact, where dofs(x_ref + u) rounds.
    Eigen::VectorXd dofs_of_displacements(const Eigen::VectorXd& u) const;
    Eigen::VectorXd positions(const Eigen::VectorXd& q, const Eigen::Matrix2d& F) const;
    // Index of coordinate c of node i in q, or -1 if fixed.
    int dof(int node, int c) const { return dof_[2 * node + c]; }
    // The state q at deformation F_old mapped affinely to F_new (a start guess for a changed strain).
    Eigen::VectorXd affine_map(const Eigen::VectorXd& q, const Eigen::Matrix2d& F_old, const Eigen::Matrix2d& F_new) const;

    // Evaluates what `want` asks at (q, F); dF is the strain direction (used with kStrain). H, if kHessian,
    // must carry hessian_pattern()'s pattern.
    void evaluate(const Eigen::VectorXd& q, const Eigen::Matrix2d& F, const Eigen::Matrix2d& dF, unsigned want,
                  EnergyEval& out, Eigen::SparseMatrix<double>* H = nullptr) const;

    const Eigen::SparseMatrix<double>& hessian_pattern() const { return assembly_->pattern(); }
    // The element terms (element_term.hpp) in assembly order: stretch, bend.
    std::vector<std::string> term_names() const;

    // One element at a time, for a caller that assembles part of the network (wet/wet_region.hpp). u: every node's
    // displacement from displacements(q, F) (fixed nodes at (F - I) x_ref). Local coordinates are the element's
    // nodes' (x, y) in order: segment (i, j), hinge (i, j, k). Same terms as evaluate().
    Eigen::VectorXd displacements(const Eigen::VectorXd& q, const Eigen::Matrix2d& F) const;
    // Node i's entries of displacements(q, F) written into u (a region's elements read only their own nodes').
    void displacement_of(int i, const Eigen::VectorXd& q, const Eigen::Matrix2d& F, Eigen::VectorXd& u) const;
    double segment_term(int e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F, Eigen::Vector4d* g,
                        Eigen::Matrix4d* H, bool project_psd) const;
    double hinge_term(int e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F, Eigen::Matrix<double, 6, 1>* g,
                      Eigen::Matrix<double, 6, 6>* H, bool project_psd) const;

private:
    const Model& model_;
    EnergyParams params_;
    int ndof_ = 0;
    std::vector<int> dof_;  // 2 per node: index into q or -1
    // On the heap, so that the assembly's pointers to the terms stay valid when the energy is moved.
    std::unique_ptr<StretchTerm> stretch_;
    std::unique_ptr<BendTerm> bend_;
    std::unique_ptr<ElementAssembly> assembly_;
};

// The energy at a fixed deformation F, as a solver sees it.
class StrainedEnergy : public Objective {
public:
    StrainedEnergy(const NetworkEnergy& e, const Eigen::Matrix2d& F) : e_(e), F_(F) {}  // keeps a reference to e
    StrainedEnergy(const NetworkEnergy&& e, const Eigen::Matrix2d& F) = delete;
    int size() const override { return e_.num_dofs(); }
    double value(const Eigen::VectorXd& q) override;
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override;
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool project_psd) override;
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return e_.hessian_pattern(); }
    // A NetworkRegion (network_region.hpp): the segments and hinges at the set's nodes only.
    std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) override;
    const Eigen::Matrix2d& F() const { return F_; }

private:
    const NetworkEnergy& e_;
    Eigen::Matrix2d F_;
    EnergyEval eval_;
    std::shared_ptr<const NodeElements> incidence_;  // built on the first restriction()
};

}  // namespace fibernet
