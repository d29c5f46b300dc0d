#pragma once
// Internal (CholmodLDL): the numeric LDL^T of a matrix in CholmodLDL's two-thread order, rows [0, a) (part A),
// [a, b) (part B) and [b, n) (the separator S), with no entry between A and B.
//
// CHOLMOD's simplicial factorization computes L row by row ("up-looking", t_cholmod_rowfac.c): row k solves
// L(0:k-1, 0:k-1) y = S(0:k-1, k) over the rows that the elimination tree reaches from column k's entries. Rows of A
// reach only A and rows of B only B, so two threads can compute them at the same time. A separator row reaches into
// A, B and S, and up-looking charges it the updates that the parts' columns send to the separator: late in a 1e4-fiber
// wet run, 40 % of the work for the 0.2 % of rows in S. Here each part's thread also computes the part of every
// separator row's solve that runs over its own columns (its entries of L(k, part) and the updates they send to the
// separator's rows and pivot), and one thread then finishes the separator rows from those updates.
//
// The rows of A and B, and the separator rows' entries in A's and B's columns, are CHOLMOD's arithmetic exactly (same
// operations, same order); a separator row's pivot and entries in S's columns sum the same terms in another order
// (A's, then B's, then S's), so they differ from CHOLMOD's in the last bits. The result
// does not depend on the number of threads. L is CHOLMOD's simplicial numeric factor (columns allocated by its
// symbolic analysis, which bounds every column's entries), so CHOLMOD's solves use it as is.
#include <cholmod.h>

#include <vector>

namespace fibernet::detail {

class SplitLDL {
public:
    // S's size and parts; parent: the elimination tree of the analyzed matrix (cholmod_etree), -1 at a root.
    void setup(int n, int a, int b, std::vector<int> parent);
    // L D L^T = S + beta I into L (simplicial, numeric, LDL^T, from the analysis of S in its natural order; its row
    // counts L->nz are reset here). S: the upper triangle, CSC with sorted rows. False on a zero pivot.
    bool factorize(const cholmod_sparse& S, double beta, cholmod_factor& L, int threads);

private:
    struct Part {
        std::vector<double> w;              // the dense row being solved (zero between rows)
        std::vector<int> flag, stack;       // visited marks (the row's index) and the reach
        std::vector<int> mark;              // separator rows touched by this part's updates to the current row
        std::vector<int> touched, u_start;  // their list; u_start[k - b]: the first update of separator row k
        std::vector<int> u_row;             // the updates to separator rows: row of S and value, per separator row
        std::vector<double> u_val, dk;      // dk[k - b]: this part's contribution to separator row k's pivot
        bool ok = true;
    };
    void part_rows(int t, const cholmod_sparse& S, double beta, cholmod_factor& L);
    bool separator_rows(const cholmod_sparse& S, double beta, cholmod_factor& L);

    int n_ = 0, a_ = 0, b_ = 0;
    std::vector<int> parent_;
    Part part_[2];
    std::vector<double> ws_;  // the separator's dense row
    std::vector<int> fs_, ss_;
};

}  // namespace fibernet::detail
