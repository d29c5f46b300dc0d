#pragma once
// Stress from the energy's strain derivatives (DESIGN.md §2). P_ab = dE/dF_ab at fixed free coordinates q
// (at an equilibrium dE/dq = 0, so this is the total derivative along any strain path); the Cauchy stress is
// sigma = (1/A) P F^T with A = |det F| L^2 the deformed box area. For simple shear F = I + gamma e_x e_y^T this
// gives sigma_xy = (1/A) dE/dgamma; for uniaxial x, sigma_xx = (1/A) dE/dt (1 + t). sigma is symmetric at an
// equilibrium (rotation invariance of E), which tests use as a check.
#include <Eigen/Core>

#include "fibernet/energy/network_energy.hpp"

namespace fibernet {

struct Stress {
    Eigen::Matrix2d P = Eigen::Matrix2d::Zero();      // dE/dF
    Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();  // Cauchy stress, energy per area (seed units)
    double area = 0;                                  // deformed box area
};

Stress stress(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F);

}  // namespace fibernet
