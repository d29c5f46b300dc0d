#pragma once
// Periodic (or open) square box with an affine deformation F (DESIGN.md §2, "Periodic box and strain").
// Box vectors are the columns of B = F B0, B0 = L I. A segment's vector is d = x_j - x_i + B n_ij.
#include <Eigen/Core>
#include <Eigen/LU>  // determinant
#include <cmath>
#include <string>

namespace fibernet {

// The one-parameter strain paths F(t) = I + t dF. Every path is linear in t, so d2F/dt2 = 0 and the
// strain derivatives of the energy need only dF.
enum class StrainKind { Shear, UniaxialX, UniaxialY, Isotropic };

StrainKind parse_strain_kind(const std::string& s);  // "shear", "uniaxial" (=x), "uniaxial-y", "isotropic"
std::string to_string(StrainKind k);
Eigen::Matrix2d strain_direction(StrainKind k);      // dF/dt
Eigen::Matrix2d deformation(StrainKind k, double t);  // F(t) = I + t dF

struct Box {
    double L = 1.0;          // side in model (seed) units: 10x Network::L, which is in fiber lengths
    bool periodic = true;
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();

    Eigen::Matrix2d B0() const { return L * Eigen::Matrix2d::Identity(); }
    Eigen::Matrix2d B() const { return F * B0(); }
    // Area of the deformed box |det B|; stress and moduli divide by it.
    double area() const { return std::abs(B().determinant()); }
    double reference_area() const { return L * L; }
};

}  // namespace fibernet
