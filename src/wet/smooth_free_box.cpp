// The free box on the smooth model (free_box.hpp): the search of box_search.hpp over relax_smooth_wet solves, with
// the relaxed response exact from one factorization.
#include <cmath>
#include <string>

#include "box_search.hpp"
#include "fibernet/wet/free_box.hpp"
#include "fibernet/wet/smooth_wet_energy.hpp"
#include "fibernet/wet/wet_moduli.hpp"

namespace fibernet {

Stress objective_stress(const WetObjective& W, const Eigen::VectorXd& q) {
    Stress s;
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            Eigen::Matrix2d dF = Eigen::Matrix2d::Zero();
            dF(a, b) = 1;
            EnergyEval ev;
            W.strain_derivatives(q, dF, ev);
            s.P(a, b) = ev.dE_dt;
        }
    s.area = std::abs((W.F() * W.dry().model().box.B0()).determinant());
    if (s.area > 0) s.sigma = s.P * W.F().transpose() / s.area;
    return s;
}

namespace {
using box_search::BoxState;
using box_search::stretch_of;

class SmoothBoxSearch : public box_search::BoxSearch {
public:
    SmoothBoxSearch(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const SmoothWetParams& params,
                    const FiberPairs& dry_crossings, const SmoothRelaxOptions& relax, Solver& solver,
                    const FreeBoxOptions& opt, FreeBoxResult& R)
        : BoxSearch(dry, F0, params.pair.beta, opt, R), params_(params), dry_crossings_(dry_crossings),
          relax_(relax), solver_(solver) {}

    BoxState make(const Eigen::VectorXd& u, const Eigen::VectorXd& q, std::vector<Bridge>) const override {
        BoxState S;
        S.u = u, S.F = stretch_of(u) * F0_, S.q = q;
        SmoothWetEnergy W(dry_, S.F, params_, dry_crossings_, q);
        S.bridges = W.bridges(q);
        S.stress = objective_stress(W, q);
        S.r = controlled(S.stress);
        S.E = W.value(q);
        return S;
    }

    WetSplit split(const BoxState& S) const override {
        const SmoothWetSplit s = SmoothWetEnergy(dry_, S.F, params_, dry_crossings_, S.q).split(S.q);
        return {s.stretch, s.bend, s.capillary()};
    }

    // K = d2E*/du2 and dQ = dq/du from one factorization at S (wet_linear_moduli along dF_j = dU_j F0, and along
    // dF_i + dF_j for the mixed terms: K_ij = (K(i+j) - K_ii - K_jj) / 2); J by central differences of the
    // controlled stress along the linear response (u +- h e_j, q +- h dQ_j): O(h^2), no solves.
    bool response(BoxState& S, int iter) override {
        if (S.has_response) return true;
        std::vector<StrainMode> modes;
        for (int j = 0; j < n_; ++j) modes.push_back({"u" + std::to_string(j), dU_[j] * F0_, 1.0});
        for (int i = 0; i < n_; ++i)
            for (int j = i + 1; j < n_; ++j) modes.push_back({"u" + std::to_string(i) + "+u" + std::to_string(j),
                                                               (dU_[i] + dU_[j]) * F0_, 1.0});
        SmoothWetEnergy W(dry_, S.F, params_, dry_crossings_, S.q);  // its pattern fresh at S.q
        ModuliInfo info;
        const std::vector<Modulus> M = wet_linear_moduli(W, S.q, modes, {}, &info);
        ++R_.stiffness_solves;
        for (const Modulus& m : M)
            if (!m.ok) {
                R_.message = "iteration " + std::to_string(iter) + ": the relaxed response failed (" + info.message +
                             ")";
                return false;
            }
        S.K.resize(n_, n_), S.dQ.resize(S.q.size(), n_), S.J.resize(n_, n_);
        for (int j = 0, p = n_; j < n_; ++j) {
            S.K(j, j) = M[j].value;
            S.dQ.col(j) = -M[j].response;
            for (int k = j + 1; k < n_; ++k, ++p) S.K(j, k) = S.K(k, j) = 0.5 * (M[p].value - M[j].value - M[k].value);
        }
        const double h = opt_.fd_strain;
        for (int j = 0; j < n_; ++j) {
            Eigen::VectorXd r[2];
            for (int k = 0; k < 2; ++k) {
                const double t = k == 0 ? h : -h;
                Eigen::VectorXd uj = S.u;
                uj[j] += t;
                const Eigen::VectorXd qj = S.q + t * S.dQ.col(j);
                r[k] = controlled(objective_stress(SmoothWetEnergy(dry_, stretch_of(uj) * F0_, params_,
                                                                   dry_crossings_, qj),
                                                   qj));
            }
            S.J.col(j) = (r[0] - r[1]) / (2 * h);
        }
        S.has_response = true;
        return true;
    }

    bool trial(const BoxState& S, const Eigen::VectorXd& u, BoxState& out, FreeBoxIteration& it,
               std::string& why) override {
        const Eigen::Matrix2d Ft = stretch_of(u) * F0_;
        // One energy at the trial box for both candidate starts (its values are the whole energy's wherever its list
        // was built) and the relaxation, its list and pattern rebuilt at the start chosen.
        SmoothWetEnergy W(dry_, Ft, params_, dry_crossings_, dry_.affine_map(S.q, S.F, Ft));
        Eigen::VectorXd q = trial_start(S, u, [&](const Eigen::VectorXd& x) { return W.value(x); });
        W.rebuild(q);
        const SmoothRelaxResult a = relax_smooth_wet(W, solver_, q, relax_);
        ++R_.relaxations, ++it.trials;
        R_.solver_iterations += a.iterations;
        it.relax_rounds += a.rounds, it.solver_iterations += a.iterations;
        if (!a.converged) {
            why = a.message;
            report_unstable(it, Ft, why);
            return false;
        }
        out = make(u, q, {});
        // A minimum, not a saddle: its relaxed response (needed next if it is accepted) factors H, and fails where H
        // is not positive semidefinite.
        const std::string msg = R_.message;
        if (!response(out, it.iteration)) {
            why = "not a minimum: " + R_.message;
            R_.message = msg;
            report_unstable(it, Ft, why);
            return false;
        }
        return true;
    }

private:
    const SmoothWetParams& params_;
    const FiberPairs& dry_crossings_;
    const SmoothRelaxOptions& relax_;
    Solver& solver_;
};
}  // namespace

FreeBoxResult smooth_free_box(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, const SmoothWetParams& params,
                              const FiberPairs& dry_crossings, const SmoothRelaxOptions& relax,
                              const Eigen::VectorXd& q0, Solver& solver, const FreeBoxOptions& opt) {
    FreeBoxResult R;
    R.F0 = R.F = F0;
    SmoothBoxSearch S(dry, F0, params, dry_crossings, relax, solver, opt, R);
    box_search::search_free_box(S, q0, {}, R);
    return R;
}

}  // namespace fibernet
