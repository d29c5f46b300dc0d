#pragma once
// FIRE 2.0, the Fast Inertial Relaxation Engine (Guenole, Noehring, Vaid, Houlle, Xie, Prakash, Bitzek,
// Comput. Mater. Sci. 173, 109584 (2020), Algorithm 2): damped dynamics with unit masses, semi-implicit Euler,
// velocity mixing v <- (1 - alpha) v + alpha |v| F/|F|, and a half step back when the power P = F.v turns
// negative. Defaults are those of the paper and of LAMMPS `min_style fire` (delaystep 20, dtgrow 1.1,
// dtshrink 0.5, alpha0 0.25, alphashrink 0.99, tmax 10, tmin 0.02, vdfmax 2000, halfstepback yes,
// initialdelay yes, dmax 0.1). FIRE is the baseline the seed and LAMMPS use; it sees only the gradient
// (and the Hessian once, to pick the default time step).
//
// Time step: dt = 0 picks dt0 = 1 / sqrt(lambda_G), lambda_G the Gershgorin bound on the largest eigenvalue of
// the Hessian at the start: explicit dynamics is stable for dt < 2 / sqrt(lambda_max), and FIRE grows dt
// (up to dt_max = 10 dt0) and cuts it back where that overshoots.
// A step into +inf/NaN energy is undone like an uphill step (v = 0, dt halved).
#include <memory>
#include <string>

#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct FireParams {
    double dt = 0;              // initial time step, 0 = automatic (see above)
    double dt_max_factor = 10;  // dt_max = factor * dt0
    double dt_min_factor = 0.02;// dt_min = factor * dt0
    double f_inc = 1.1;         // dt growth after n_delay steps with P > 0
    double f_dec = 0.5;         // dt shrink when P <= 0
    double alpha0 = 0.25;       // mixing parameter at (re)start
    double f_alpha = 0.99;      // alpha shrink factor
    int n_delay = 20;           // steps with P > 0 before dt grows
    int n_neg_max = 2000;       // consecutive P <= 0 steps before giving up (Stalled)
    bool initial_delay = true;  // no dt shrink during the first n_delay steps
    bool half_step_back = true; // x -= dt v / 2 when P <= 0
    double max_move = 0.1;      // largest displacement of a coordinate per step (seed units), 0 = unlimited
    int max_nonfinite = 60;     // consecutive steps into non-finite energy before NonFinite

    void check(const std::string& where) const;
};

class FireSolver : public Solver {
public:
    FireSolver(const SolverOptions& opt, const FireParams& p = {});
    std::string name() const override { return "fire"; }
    SolverOptions& options() override { return opt_; }
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override;
    SolverCapabilities capabilities() const override;
    std::unique_ptr<Solver> clone() const override { return std::make_unique<FireSolver>(opt_, p_); }

private:
    SolverOptions opt_;
    FireParams p_;
};

}  // namespace fibernet
