#pragma once
// Upper-triangular CSC Hessian patterns built from elements and other patterns, and the value slots of entries: shared
// by the energies that assemble into a fixed pattern (wet_energy.hpp, wet_region.hpp, network_energy.hpp).
#include <Eigen/Core>
#include <algorithm>
#include <Eigen/SparseCore>
#include <utility>
#include <vector>

namespace fibernet {

// An upper-triangular pattern (rows sorted and unique in each column, values zero) built by counting (two passes over
// the entries, no list per column) from any mix of: every entry of given patterns, the upper M x M entries of
// elements (idx as in element_slots below), the diagonal. For the wet Hessian's union pattern, built once per bridge
// set: ~1e7 entries at 1e4 fibers.
class PatternBuilder {
public:
    explicit PatternBuilder(int n) : n_(n) {}
    // The sources are kept by reference until build().
    void add_pattern(const Eigen::SparseMatrix<double>& P) { patterns_.push_back(&P); }
    void add_elements(const std::vector<int>& idx, int M) { elements_.push_back({&idx, M}); }
    void add_diagonal() { diagonal_ = true; }
    Eigen::SparseMatrix<double> build() const;

private:
    struct Elements {
        const std::vector<int>* idx;
        int M;
    };
    int n_;
    std::vector<const Eigen::SparseMatrix<double>*> patterns_;
    std::vector<Elements> elements_;
    bool diagonal_ = false;
};

// Whether A and B have the same size and the same entries (compressed CSC; values ignored).
bool same_pattern(const Eigen::SparseMatrix<double>& A, const Eigen::SparseMatrix<double>& B);

// Index into P's values of entry (r, c), r <= c; throws std::logic_error if P lacks it.
int pattern_slot(const Eigen::SparseMatrix<double>& P, int r, int c);

// The slot of entry (r, c) in P (either order), or -1 if P lacks it.
int find_slot(const Eigen::SparseMatrix<double>& P, int r, int c);

// Adds kappa G G^T to the values hv of the upper pattern P, G a sparse vector given as (coordinate, value) entries in
// any order, with repeats (summed first, in coordinate order). Returns false if P lacks an entry (left out).
bool add_outer_product(const Eigen::SparseMatrix<double>& P, std::vector<std::pair<int, double>>& G, double kappa,
                       double* hv);

// Value slots of many elements at once, each with M local coordinates: idx[e M + a] is local coordinate a's row/column
// in P (-1: none). out (resized to elements x M x M) gets at e M M + a M + b the slot of (idx[e M + a], idx[e M + b])
// if both exist and the first <= the second, else -1. The same as pattern_slot entry by entry, in time linear in the
// entries (one pass per column, no search): a 1e4-fiber wet Hessian has ~6e6 of them. Throws like pattern_slot, or,
// given `lacking` (resized to elements), leaves a missing entry at -1 and marks its element there.
void element_slots(const Eigen::SparseMatrix<double>& P, const std::vector<int>& idx, int M, std::vector<int>& out,
                   std::vector<char>* lacking = nullptr);

// The slot in P of every entry of a pattern S contained in P, in S's value order (one pass per column). Throws like
// pattern_slot if P lacks one.
std::vector<int> subpattern_slots(const Eigen::SparseMatrix<double>& P, const Eigen::SparseMatrix<double>& S);

// The values of H (a pattern containing S's) set to S's, through S's slots in H (subpattern_slots), zero elsewhere:
// the dry Hessian as the first part of a wet one. Returns H's values for the elements to add to.
inline double* assign_subpattern(const Eigen::SparseMatrix<double>& S, const std::vector<int>& slots,
                                 Eigen::SparseMatrix<double>& H) {
    double* hv = H.valuePtr();
    std::fill(hv, hv + H.nonZeros(), 0.0);
    const double* sv = S.valuePtr();
    for (size_t i = 0; i < slots.size(); ++i) hv[slots[i]] += sv[i];
    return hv;
}

// Adds one element's gradient ge (M local coordinates) to g and its Hessian block he (M x M, column-major) to the
// values hv, through the element's index table idx (-1: a held coordinate) and slot table (element_slots; -1: not
// stored). g or hv may be null (value or gradient only).
inline void scatter_element(const int* idx, const int* slot, int M, const double* ge, const double* he,
                            Eigen::VectorXd* g, double* hv) {
    if (g)
        for (int a = 0; a < M; ++a)
            if (idx[a] >= 0) (*g)[idx[a]] += ge[a];
    if (hv)
        for (int j = 0; j < M * M; ++j)
            if (slot[j] >= 0) hv[slot[j]] += he[(j % M) * M + j / M];
}

}  // namespace fibernet
