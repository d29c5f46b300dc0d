#pragma once
// One deterministic, parallel assembler for element terms (element_term.hpp, issue 22): sums their elements into the
// energy by term, the gradient, the strain derivatives and the values of a fixed upper-triangular Hessian pattern.
//
// The elements are evaluated in parallel, each into its own slots. Then every free coordinate and every Hessian entry
// sums its contributions in one fixed order (the terms in order, their elements in order), and the scalar sums run in
// that order too: the result is bit for bit the same for any thread count, and the same as one loop that adds element
// after element (the dry energy's before issue 22; tests/energy/element_assembly_test.cpp).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <vector>

#include "fibernet/energy/element_term.hpp"

namespace fibernet {

class ElementAssembly {
public:
    // terms: kept by pointer (they must outlive the assembly); dof: 2 per node, the node coordinate's index in q or -1
    // (fixed); ndof: the free coordinates.
    ElementAssembly(std::vector<const ElementTerm*> terms, const std::vector<int>& dof, int ndof);

    // Every pair of free coordinates that one element couples, and every free coordinate's node block, upper
    // triangle (CSC, rows sorted).
    const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }

    struct Sums {
        std::vector<double> energy;  // per term, in the order given
        double dE_dt = 0, d2E_dt2 = 0;
        double d2E_dt2_size = 0;     // sum of the elements' |d2E/dt2| (the scale of its rounding)
    };
    // Evaluates every element at `frame` and sums. gradient, d2E_dqdt (with want.strain) and hessian_values (the
    // pattern's values, with want.hessian) are written when non-null.
    void assemble(const ElementFrame& frame, const ElementWant& want, Sums& sums, Eigen::VectorXd* gradient,
                  Eigen::VectorXd* d2E_dqdt, double* hessian_values) const;

private:
    std::vector<const ElementTerm*> terms_;
    int ndof_;
    std::vector<std::size_t> first_;          // first global element index of each term (and the total)
    std::vector<std::size_t> coord_offset_;   // each term's first entry in the per-element coordinate buffers
    std::vector<std::size_t> upper_offset_;   // each term's first entry in the per-element packed Hessian buffer
    Eigen::SparseMatrix<double> pattern_;
    // Contributions in summation order: to free coordinate r, coordinate buffer entries grad_src_[grad_ptr_[r] ..
    // grad_ptr_[r + 1]); to Hessian value s, packed entries hess_src_[hess_ptr_[s] .. hess_ptr_[s + 1]).
    std::vector<std::size_t> grad_ptr_, hess_ptr_;
    std::vector<std::uint32_t> grad_src_, hess_src_;  // 4 bytes: the gathers are bound by memory traffic
    // Per element, for one thread's scatter (the same sums in the same order): each local coordinate's index in q
    // and each packed Hessian entry's value slot (-1: fixed).
    std::vector<int> coord_index_, upper_slot_;

    void scatter_serially(const ElementFrame& frame, const ElementWant& want, Sums& sums, Eigen::VectorXd* gradient,
                          Eigen::VectorXd* d2E_dqdt, double* hessian_values) const;
};

}  // namespace fibernet
