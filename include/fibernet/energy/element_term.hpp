#pragma once
// An energy term as a sum over elements of a fixed number of nodes (issue 22): stretching over segments (2 nodes),
// bending over hinges (3). A term gives each element's value, and where asked its gradient and Hessian on the
// element's local coordinates (x, y of each node in order) and its strain derivatives along dF; one assembler
// (element_assembly.hpp) sums them into E, g and the sparse Hessian. Adding a term is one class like StretchTerm
// (stretch.hpp) plus its finite-difference test, and a line in the energy's list of terms.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "fibernet/model/model.hpp"

namespace fibernet {

// What an element evaluation computes besides its value.
struct ElementWant {
    bool gradient = false, hessian = false, strain = false;
    bool psd = false;  // the Hessian projected to positive semi-definite (the strain derivatives stay exact)
};

// The state every element reads: all nodes' displacements u = x - x_ref (fixed nodes at (F - I) x_ref), the box
// and, with strain, the strain direction dF. Cheap to build (no pass over the network): a region builds one per
// evaluation.
class ElementFrame {
public:
    // comoving: the strain derivatives along the affine path of every node (NetworkEnergy's kComoving).
    ElementFrame(const Model& m, const std::vector<int>& dof, const Eigen::VectorXd& u, const Eigen::Matrix2d& F,
                 const Eigen::Matrix2d& dF, bool strain, bool comoving);
    const Model& model() const { return m_; }
    const Eigen::VectorXd& u() const { return u_; }
    bool strain() const { return strain_; }
    // Edge vector d = d0 + (F - I) B0 n + u_j - u_i (= x_j - x_i + F B0 n, without subtracting large wrapped
    // coordinates) and, with strain, its rate c = dd/dt: dF (B0 n + [fixed] x_ref differences), or dF F^-1 d when
    // every node moves affinely.
    void edge(int i, int j, const Eigen::Vector2i& n, const Eigen::Vector2d& d0, Eigen::Vector2d& d,
              Eigen::Vector2d& c) const;

private:
    const Model& m_;
    const std::vector<int>& dof_;
    const Eigen::VectorXd& u_;
    Eigen::Matrix2d FmIB0_, dB_, dF_, V_;
    bool strain_, comoving_;
};

constexpr int kMaxElementCoords = 8;  // 4 nodes (a capillary pair of segments)

struct ElementResult {
    double energy = 0;
    Eigen::Matrix<double, kMaxElementCoords, 1> gradient;                    // first 2 K entries (K nodes)
    Eigen::Matrix<double, kMaxElementCoords, kMaxElementCoords> hessian;     // first 2 K x 2 K block
    // Strain: the element's dE/dt and d2E/dt2 along dF at fixed coordinates, and d2E/dq dt on its coordinates.
    double dE_dt = 0, d2E_dt2 = 0;
    Eigen::Matrix<double, kMaxElementCoords, 1> d2E_dqdt;
};

class ElementTerm {
public:
    virtual ~ElementTerm() = default;
    virtual const char* name() const = 0;   // the energy split's key ("stretch", "bend")
    virtual int valence() const = 0;        // nodes per element, at most kMaxElementCoords / 2
    virtual std::size_t size() const = 0;   // elements
    virtual void nodes(std::size_t e, int* out) const = 0;  // element e's valence() nodes, in local order
    virtual void evaluate(std::size_t e, const ElementFrame& frame, const ElementWant& want,
                          ElementResult& out) const = 0;
};

// The exact rest vector of an edge from the discretization when given (finite), else from the reference positions.
inline Eigen::Vector2d rest_vector(const Model& m, const Eigen::Vector2d& given, int i, int j, const Eigen::Vector2i& n) {
    if (given.allFinite()) return given;
    return m.x.segment<2>(2 * j) - m.x.segment<2>(2 * i) + m.box.B0() * n.cast<double>();
}

// The Hessian h projected to positive semi-definite (eigenvalues clipped at 0).
Eigen::Matrix2d project_psd(const Eigen::Matrix2d& h);
Eigen::Matrix4d project_psd(const Eigen::Matrix4d& h);

}  // namespace fibernet
