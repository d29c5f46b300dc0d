#pragma once
// Upper-triangular CSC Hessian patterns built from per-column row lists, and the value slot of an entry: shared by
// the energies that assemble into a fixed pattern (wet_energy.hpp, wet_region.hpp, network_energy.hpp).
#include <Eigen/SparseCore>
#include <vector>

namespace fibernet {

// The pattern of an n x n matrix whose column c holds rows cols[c] (any order, repeats allowed; sorted in place).
Eigen::SparseMatrix<double> pattern_from_columns(int n, std::vector<std::vector<int>>& cols);

// Index into P's values of entry (r, c), r <= c; throws std::logic_error if P lacks it.
int pattern_slot(const Eigen::SparseMatrix<double>& P, int r, int c);

}  // namespace fibernet
