#pragma once
// Model export (docs/formats.md, "model"): everything needed to rebuild this exact energy elsewhere, e.g. in LAMMPS
// (bond harmonic with K = 4 a^2 / l0 and r0 = l0; angle cosine with K = 2 / lt0). Round-trips exactly.
#include <iosfwd>
#include <string>

#include "fibernet/model/model.hpp"

namespace fibernet {

// Writes the model with node positions x (2 per node; the model's reference positions if empty) at box deformation F.
void write_model(std::ostream& os, const Model& m, const Eigen::VectorXd& x = {},
                 const Eigen::Matrix2d& F = Eigen::Matrix2d::Identity());
// Reads a model file; positions and F are returned through the out-parameters when given. `source` names the stream.
Model read_model(std::istream& is, const std::string& source, Eigen::VectorXd* x = nullptr, Eigen::Matrix2d* F = nullptr);

}  // namespace fibernet
