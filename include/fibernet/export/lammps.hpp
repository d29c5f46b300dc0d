#pragma once
// A model state as a LAMMPS data file plus an input script whose energy is the model's (docs/formats.md, "LAMMPS"):
// bond_style harmonic with K = 4 a^2 / l0 and r0 = l0 (LAMMPS' K (r - r0)^2 has no 1/2), angle_style cosine with
// K = 2 / lt0 (K (1 + cos theta) = K (1 - cos phi) for the turning angle phi), units lj, dimension 2, the box
// B = F L I as a restricted triclinic box (xy = F01 L). Clamped nodes form the group `clamped`, held by setforce.
#include <iosfwd>
#include <string>

#include "fibernet/model/model.hpp"

namespace fibernet {

struct LammpsExport {
    int bond_types = 0, angle_types = 0;
    int softcore_segments = 0;  // segments with eps < eps* at this state: LAMMPS' harmonic branch differs there
};

// Writes the data file to `data` and the input script to `input`; the script reads `data_name` and prints
// step, pe, ebond, eangle and max |fx|, max |fy| over the free atoms with 17 digits after `run 0`. u: displacements (2 per
// node) at box deformation F, which must keep the first box vector along x (F10 = 0). Throws InputError otherwise.
LammpsExport write_lammps(std::ostream& data, std::ostream& input, const Model& m, const Eigen::VectorXd& u,
                          const Eigen::Matrix2d& F, const std::string& data_name, const std::string& title);

}  // namespace fibernet
