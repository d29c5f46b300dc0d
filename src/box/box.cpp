#include "fibernet/box/box.hpp"

#include "fibernet/util/error.hpp"

namespace fibernet {

StrainKind parse_strain_kind(const std::string& s) {
    if (s == "shear") return StrainKind::Shear;
    if (s == "uniaxial" || s == "uniaxial-x") return StrainKind::UniaxialX;
    if (s == "uniaxial-y") return StrainKind::UniaxialY;
    if (s == "isotropic") return StrainKind::Isotropic;
    throw InputError("strain kind '" + s + "' is unknown (expected shear, uniaxial, uniaxial-y or isotropic)");
}

std::string to_string(StrainKind k) {
    switch (k) {
        case StrainKind::Shear: return "shear";
        case StrainKind::UniaxialX: return "uniaxial";
        case StrainKind::UniaxialY: return "uniaxial-y";
        case StrainKind::Isotropic: return "isotropic";
    }
    return "?";
}

Eigen::Matrix2d strain_direction(StrainKind k) {
    Eigen::Matrix2d d = Eigen::Matrix2d::Zero();
    switch (k) {
        case StrainKind::Shear: d(0, 1) = 1; break;  // Lees-Edwards: x += gamma y
        case StrainKind::UniaxialX: d(0, 0) = 1; break;
        case StrainKind::UniaxialY: d(1, 1) = 1; break;
        case StrainKind::Isotropic: d(0, 0) = d(1, 1) = 1; break;
    }
    return d;
}

Eigen::Matrix2d deformation(StrainKind k, double t) {
    return Eigen::Matrix2d::Identity() + t * strain_direction(k);
}

}  // namespace fibernet
