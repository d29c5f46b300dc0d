#pragma once
// Model export (docs/formats.md, "model"): everything needed to rebuild this exact energy elsewhere, e.g. in LAMMPS
// (bond harmonic with K = 4 a^2 / l0 and r0 = l0; angle cosine with K = 2 / lt0). Round-trips exactly.
#include <iosfwd>
#include <string>

#include "fibernet/model/model.hpp"

namespace fibernet {

// Writes the model in state u (each node's displacement from its reference position, 2 per node; zero if empty) at
// box deformation F. Positions x_ref + u are written too, for other programs; u itself makes the state lossless.
void write_model(std::ostream& os, const Model& m, const Eigen::VectorXd& u = {},
                 const Eigen::Matrix2d& F = Eigen::Matrix2d::Identity());
// Reads a model file (format 2, or 1 whose state is positions only); the displacements u and F are returned through
// the out-parameters when given. `source` names the stream in error messages.
Model read_model(std::istream& is, const std::string& source, Eigen::VectorXd* u = nullptr, Eigen::Matrix2d* F = nullptr);

}  // namespace fibernet
