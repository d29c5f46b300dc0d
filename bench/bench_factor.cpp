// CHOLMOD on wet Hessians (issue 6): cost of the symbolic analysis (done again whenever the bridge set, and so the
// Hessian pattern, changes) against one numeric factorization, and of a failed (indefinite) factorization, on a
// Mikado network of N fibers wetted at all crossings after a short capillary relaxation.
//   bench_factor [N=1000] [q=10] [reps=5] [seed=1]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/cholmod_ldl.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/wet/wetting.hpp"

using namespace fibernet;

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

int main(int argc, char** argv) {
    const int N = argc > 1 ? std::atoi(argv[1]) : 1000;
    const double density = argc > 2 ? std::atof(argv[2]) : 10;
    const int reps = argc > 3 ? std::atoi(argv[3]) : 5;
    const unsigned seed = argc > 4 ? static_cast<unsigned>(std::atoi(argv[4])) : 1u;
    MikadoParams mp;
    mp.q = density, mp.pl = 0.5, mp.seed = seed;
    mp.L = std::sqrt(N / density);
    const Network net = generate_mikado(mp);
    DiscretizationParams dp;
    const Model m = discretize(net, dp);
    NetworkEnergy dry(m);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    Eigen::VectorXd q = dry.dofs(m.x);
    WetParams p;
    p.beta = 0.01;
    WetEnergy W(dry, I, wet_crossings(net, m, dry.positions(q, I), m.box.B0(), WettingRule{}), p);
    SolverOptions so;
    so.max_iter = 10;
    NewtonSolver(so).minimize(W, q);  // a state under capillary load (indefinite Hessian)
    Eigen::SparseMatrix<double> H = W.hessian_pattern();
    Eigen::VectorXd g;
    W.hessian(q, g, H, false);
    double dm = 0;
    for (int j = 0; j < H.cols(); ++j) dm += std::abs(H.coeff(j, j));
    dm /= H.cols();
    double t_an = 1e300, t_ok = 1e300, t_fail = 1e300;
    bool fail_ok = false;
    for (int r = 0; r < reps; ++r) {
        CholmodLLT llt;
        auto t0 = Clock::now();
        llt.analyze(H);
        t_an = std::min(t_an, seconds_since(t0));
        t0 = Clock::now();
        fail_ok = !llt.factorize(H, 1e-8 * dm);
        t_fail = std::min(t_fail, seconds_since(t0));
        t0 = Clock::now();
        const bool ok = llt.factorize(H, 0.2 * dm);
        t_ok = std::min(t_ok, seconds_since(t0));
        if (!ok) std::fprintf(stderr, "warning: H + 0.2 mean diag did not factor\n");
    }
    // The simplicial LDL^T of the indefinite H + 1e-8 mean diag (Newton's first rung) and its modified solve.
    double t_ldl_an = 1e300, t_ldl = 1e300, t_ldl_solve = 1e300;
    int negative = 0;
    for (int r = 0; r < reps; ++r) {
        CholmodLDL ldl;
        auto t0 = Clock::now();
        ldl.analyze(H);
        t_ldl_an = std::min(t_ldl_an, seconds_since(t0));
        t0 = Clock::now();
        if (!ldl.factorize(H, 1e-8 * dm)) std::fprintf(stderr, "warning: LDL^T of H + 1e-8 mean diag failed\n");
        t_ldl = std::min(t_ldl, seconds_since(t0));
        negative = ldl.negative_pivots();
        t0 = Clock::now();
        const Eigen::VectorXd d = ldl.solve_modified(g, 1e-8 * dm);
        t_ldl_solve = std::min(t_ldl_solve, seconds_since(t0));
    }
    std::printf("{\"fibers\": %zu, \"dofs\": %ld, \"nnz_upper\": %ld, \"analysis_s\": %.4f, \"factorization_s\": %.4f, "
                "\"indefinite\": %s, \"failed_factorization_s\": %.4f, \"ldl_analysis_s\": %.4f, \"ldl_factorization_s\": %.4f, "
                "\"ldl_solve_s\": %.4f, \"ldl_negative_pivots\": %d}\n",
                net.fibers.size(), static_cast<long>(H.rows()), static_cast<long>(H.nonZeros()), t_an, t_ok,
                fail_ok ? "true" : "false", t_fail, t_ldl_an, t_ldl, t_ldl_solve, negative);
}
