#pragma once
// Quasistatic strain sweep (issue 5): equilibria along F(t) = I + t dF from t = 0 to t_max with an adaptive step.
// Predictor: the tangent q + h dq/dt, dq/dt = -H^+ E_xt from the linear response at the last equilibrium
// (the same solve that gives the differential modulus). Corrector: the scene's solver. A corrector that fails
// is retried from the last equilibrium with half the step; below min_step the sweep stops and says so. A corrector
// that converged only after many iterations is retried with smaller steps too, and accepted at the smallest step
// (a snap-through: the equilibrium branch ended; the `iterations` and `retries` columns show it). Every accepted step is an equilibrium to the solver's tolerance: no row is written
// for an unconverged state.
//
// Along the path the generalized stress is s(t) = (1/A0) dE/dt (A0 = reference box area) and the exact
// differential modulus K = ds/dt = (1/A0) (E_tt - E_xt^T H^+ E_xt). For simple shear A = A0 and s = sigma_xy,
// so K = d sigma_xy / d gamma; for uniaxial strain along x, s = sigma_xx (Cauchy, A = A0 (1 + t)).
#include <Eigen/Core>
#include <atomic>
#include <functional>
#include <string>
#include <vector>

#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct SweepParams {
    StrainKind kind = StrainKind::Shear;
    double t_max = 0.5;        // final strain (negative: compression)
    double step = 0.01;        // first step
    double min_step = 1e-6;
    double max_step = 0.05;
    int good_iterations = 4;   // corrector iterations at or below which the step grows by `grow`
    int max_iterations = 30;   // a corrector needing more is retried with half the step (accepted at min_step)
    double grow = 1.5;

    void check(const std::string& where) const;  // InputError naming the bad value
};

struct SweepRow {
    int step = 0;
    double t = 0;
    Eigen::Matrix2d sigma = Eigen::Matrix2d::Zero();  // Cauchy stress
    double stress_path = 0;    // s = (1/A0) dE/dt
    double K = 0;              // ds/dt, exact (linear response)
    double K_affine = 0;       // (1/A0) E_tt: the non-relaxed (affine) part
    double energy = 0, stretch = 0, bend = 0;
    int iterations = 0, factorizations = 0, retries = 0;
    double grad_max = 0, seconds = 0;
};

// The sweep's full state after an accepted step: enough to continue exactly where it stopped.
struct SweepState {
    int step = 0;
    double t = 0;
    double next_step = 0;
    Eigen::VectorXd q;
};

struct SweepOutcome {
    bool completed = false;     // reached t_max
    bool interrupted = false;   // stopped by the stop flag; the last accepted step is kept
    std::string message;        // why it stopped early
};

struct SweepCallbacks {
    // Called after every accepted step (write the row, then the checkpoint).
    std::function<void(const SweepRow&, const SweepState&)> on_step;
    const std::atomic<bool>* stop = nullptr;  // checked before each step
};

// Runs (or, with `resume` non-null, continues) a sweep. The first row (t = 0) comes from relaxing the reference state.
// snap: optional solver with a larger iteration budget. At the smallest step a corrector that hit its iteration
// limit is retried once with it before the sweep gives up: past a fold (snap-through) the next stable state can be
// hundreds of Newton iterations away (docs/sweep.md).
SweepOutcome run_sweep(const NetworkEnergy& e, const SweepParams& p, Solver& solver, const SweepCallbacks& cb,
                       const SweepState* resume = nullptr, Solver* snap = nullptr);

}  // namespace fibernet
