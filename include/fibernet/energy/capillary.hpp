#pragma once
// Capillary bridge at a wet crossing (seed ch. 4 intro; issue 6): an energy of the crossing angle alpha between
// two segments of different fibers that aligns them and does not resist sliding.
//
//   E = beta * l * phi(c),  c = cos^2 alpha = (d1.d2)^2 / (|d1|^2 |d2|^2)
//
// l is the mean rest length of the two segments, beta the adhesion energy per unit length of a bundle of two aligned
// fibers. Writing the law in c = cos^2 alpha makes E smooth at alpha = 0 and 90 deg (no arccos, no sign of d1.d2:
// fibers have no direction) and gives zero torque there automatically (dc/dalpha = -sin 2 alpha).
// Default law phi(c) = -c: E(90) - E(0) = beta l. A tabulated law E(alpha)/(beta l) (e.g. from Surface Evolver) is
// interpolated by a natural cubic spline in c.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace fibernet {

// Largest |E / (beta l)| a tabulated law may give: the law's shape is of order 1, its strength is beta.
constexpr double kMaxLawValue = 10;
// Largest beta relative to the stretching stiffness 4 a^2 (energy per unit length, seed eq. 4.14): a bundle's
// adhesion beta compresses a segment by eps ~ beta / (8 a^2), so beta = 4 a^2 is a 50% axial strain, far outside a
// model of nearly inextensible fibers (and the softcore takes over at eps* = -0.95).
constexpr double kMaxBetaOverStretch = 1;

class CapillaryLaw {
public:
    CapillaryLaw() = default;  // phi(c) = -c
    // Table of (alpha in degrees, E / (beta l)); alpha strictly increasing in [0, 90], >= 2 points, finite.
    // `where` names the source in errors (InputError).
    static CapillaryLaw tabulated(const std::vector<double>& alpha_deg, const std::vector<double>& value,
                                  const std::string& where);
    // Reads "alpha_deg value" lines ('#' comments allowed).
    static CapillaryLaw read(const std::string& path);

    // phi, dphi/dc, d2phi/dc2 at c in [0, 1].
    void eval(double c, double& phi, double& dphi, double& d2phi) const;
    bool is_default() const { return c_.empty(); }

private:
    std::vector<double> c_, y_, m_;  // knots in c (increasing), values, spline second derivatives
};

// Value and, where non-null, gradient and Hessian with respect to (d1, d2).
double bridge_energy(const Eigen::Vector2d& d1, const Eigen::Vector2d& d2, double l, double beta,
                     const CapillaryLaw& law, Eigen::Vector4d* grad, Eigen::Matrix4d* hess);

}  // namespace fibernet
