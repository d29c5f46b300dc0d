#include "fibernet/wet/wet_moduli.hpp"

#include <limits>

namespace fibernet {

std::vector<Modulus> wet_linear_moduli(WetObjective& W, const Eigen::VectorXd& q, const std::vector<StrainMode>& modes,
                                       const ModuliOptions& opt, ModuliInfo* info) {
    const NetworkEnergy& dry = W.dry();
    Eigen::SparseMatrix<double> H = W.hessian_pattern();
    Eigen::VectorXd g;
    W.hessian(q, g, H, false);
    const Eigen::VectorXd x = dry.positions(q, W.F());
    const Eigen::Matrix2d Finv = W.F().inverse();
    std::vector<StrainTerms> terms(modes.size());
    for (size_t m = 0; m < modes.size(); ++m) {
        EnergyEval ev;
        W.strain_derivatives(q, modes[m].dF, ev, true);  // comoving, per element (StrainTerms::comoving)
        terms[m] = {ev.d2E_dt2, std::move(ev.d2E_dqdt), affine_velocity(dry, x, modes[m].dF * Finv), true,
                    ev.d2E_dt2_size};
    }
    std::vector<Modulus> out = relaxed_moduli(H, terms, modes, opt, info);
    for (Modulus& mo : out) mo.affine = std::numeric_limits<double>::quiet_NaN();
    return out;
}

}  // namespace fibernet
