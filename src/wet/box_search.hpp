#pragma once
// The free-box search (free_box.hpp) over one capillary model's relaxations: the searches (isotropic bracket, full
// damped Newton) see a model only through BoxSearch, which the event model (free_box.cpp) and the smooth model
// (smooth_free_box.cpp) implement.
#include <Eigen/Core>
#include <cmath>
#include <string>
#include <vector>

#include "fibernet/wet/free_box.hpp"

namespace fibernet::box_search {

// U of the free box from its unknowns: full (U_xx - 1, U_yy - 1, U_xy), isotropic (s - 1).
Eigen::Matrix2d stretch_of(const Eigen::VectorXd& u);

// A point of the search: an equilibrium at F = U(u) F0, with its controlled residual r (stress components in units of
// sigma_c: full xx, yy, xy; isotropic the mean normal stress) and, once computed, its relaxed response: J = dr/du,
// K = d2E*/du2 (symmetric), dQ = dq/du.
struct BoxState {
    Eigen::VectorXd u, q, r;
    Eigen::Matrix2d F;
    std::vector<Bridge> bridges;  // event model: the bridge set; smooth model: the non-zero pairs (for reports)
    Stress stress;
    double E = 0;
    WetEvents events;  // of the relaxation that produced it (event model)
    Eigen::MatrixXd J, K, dQ;
    bool has_response = false;
    double residual() const { return r.cwiseAbs().maxCoeff(); }
};

class BoxSearch {
public:
    BoxSearch(const NetworkEnergy& dry, const Eigen::Matrix2d& F0, double beta, const FreeBoxOptions& opt,
              FreeBoxResult& R);
    virtual ~BoxSearch() = default;
    int n() const { return n_; }
    double sc() const { return sc_; }
    double elapsed() const;
    const FreeBoxOptions& options() const { return opt_; }
    const NetworkEnergy& dry() const { return dry_; }

    // The state (u, q) of the model: its stress, residual and energy (`bridges`: the event model's set; the smooth
    // model finds its own).
    virtual BoxState make(const Eigen::VectorXd& u, const Eigen::VectorXd& q, std::vector<Bridge> bridges) const = 0;
    // Fills S's relaxed response (J, K, dQ); false (R.message says why) if it failed.
    virtual bool response(BoxState& S, int iter) = 0;
    // The relaxation at u, from S moved by its linear relaxed response (if known) or mapped affinely, whichever start
    // has the lower energy: the affine map of a bending-dominated network stretches its fibers, so its energy rises
    // with the affine, not the relaxed, stiffness, and a relaxation from high up may land in another branch of the
    // path-dependent wet landscape. False (why says so) if it did not reach a stable equilibrium.
    virtual bool trial(const BoxState& S, const Eigen::VectorXd& u, BoxState& out, FreeBoxIteration& it,
                       std::string& why) = 0;
    // The energy split of a state.
    virtual WetSplit split(const BoxState& S) const = 0;

    FreeBoxIteration record(const BoxState& S, int iter, double step, FreeBoxIteration it) const;
    void progress(const FreeBoxIteration& it, const char* what, const std::string& extra = "") const;
    void add_events(const WetEvents& e);

protected:
    Eigen::VectorXd controlled(const Stress& s) const;
    // The start of a trial at u from S: the affine map of S.q, or S moved by its linear response if that is lower
    // in energy(q) at the trial box.
    template <class EnergyAt>
    Eigen::VectorXd trial_start(const BoxState& S, const Eigen::VectorXd& u, const EnergyAt& energy) const {
        const Eigen::Matrix2d Ft = stretch_of(u) * F0_;
        Eigen::VectorXd q = dry_.affine_map(S.q, S.F, Ft);
        if (S.has_response) {
            const Eigen::VectorXd ql = S.q + S.dQ * (u - S.u);
            const double El = energy(ql);
            if (std::isfinite(El) && El < energy(q)) q = ql;
        }
        return q;
    }
    void report_unstable(const FreeBoxIteration& it, const Eigen::Matrix2d& Ft, const std::string& why) const;

    const NetworkEnergy& dry_;
    Eigen::Matrix2d F0_;
    const FreeBoxOptions& opt_;
    FreeBoxResult& R_;
    int n_;
    double t0_, sc_ = 1;
    std::vector<Eigen::Matrix2d> dU_;  // dU/du_j
};

// The search from the equilibrium (q0, bridges0) at F0 and what follows it (stability, the state, energies): R
// complete but for pores, bundles and the shear modulus.
void search_free_box(BoxSearch& S, const Eigen::VectorXd& q0, const std::vector<Bridge>& bridges0, FreeBoxResult& R);

}  // namespace fibernet::box_search
