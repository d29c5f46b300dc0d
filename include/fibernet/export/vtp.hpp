#pragma once
// A network state as VTK XML PolyData (.vtp) for ParaView, and a .pvd collection of such files (a sweep's steps).
// Each segment is one line cell with its own two points, drawn unwrapped (x_i, x_i + d), so that a segment across the
// periodic boundary is not drawn across the box. Cell data per segment: fiber, strain eps = |d| / l0 - 1,
// stretch_energy, bend_energy (each hinge's energy split half and half between its two segments, so the cells sum to
// the total), and any per-fiber integer fields given (e.g. rigid_cluster). Point data: node (its model index),
// displacement u = x - x_ref, crosslink (1 at a supernode). Field data: the scalars given (gamma, energy, ...).
// Bridges, if given, are vertex cells of their own (VtpFields::bridges).
#include <Eigen/Core>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "fibernet/energy/network_energy.hpp"

namespace fibernet {

struct VtpFields {
    std::vector<std::pair<std::string, std::vector<int>>> per_fiber;  // name, one value per fiber id
    std::vector<std::pair<std::string, double>> scalars;              // written as FieldData
    // Capillary bridges (a wet state): one vertex cell each, before the segments' line cells (VTK's cell order).
    // Their cells have bridge = 1 (2: locked), fiber = -1 and zero segment fields; the segments' have bridge = 0.
    std::vector<Eigen::Vector2d> bridges;
    std::vector<int> bridge_locked;
};

// The state q (free coordinates of e) at deformation F.
void write_vtp(std::ostream& os, const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
               const VtpFields& fields = {});

// A ParaView collection: each file with its time value (paths as they should appear in the .pvd, relative to it).
void write_pvd(std::ostream& os, const std::vector<std::pair<double, std::string>>& steps);

}  // namespace fibernet
