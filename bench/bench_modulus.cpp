// Benchmark for issue 3 (not a test): one Mikado network (q = 8, pl = 1, a = 10) per run, so that peak memory
// (getrusage ru_maxrss) belongs to that network alone. Prints one tab-separated row:
//   L scheme fibers dofs t_assembly t_analyze t_factor t_modulus ratio newton_s newton_it newton_fact grad_max status
//   peak_MiB G G_ratio
// t_assembly: energy + gradient + Hessian at the reference; t_factor: one numeric CHOLMOD factorization (median of
// 3); t_analyze: the symbolic analysis (once per model); t_modulus: linear_moduli (G and K: assembly, analysis,
// one factorization, refinement solves) at the reference equilibrium; ratio = t_modulus / t_factor; newton_s: the
// equilibrium at gamma = 0.01 to max|g| <= 1e-10 (or the round-off floor), linear-response start included.
// Usage: bench_modulus L scheme [gamma] [prune]   (gamma = 0 skips the strained equilibrium; prune = none |
//        ends | dangling,ends: the model-reduction rules of docs/moduli.md, "Pruning")      (bench/run_modulus_bench.sh runs the table of docs/benchmarks.md)
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/prune.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/newton.hpp"

using namespace fibernet;
using Clock = std::chrono::steady_clock;
static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: bench_modulus L seed|even [gamma] [none|ends|dangling,ends]\n");
        return 2;
    }
    MikadoParams mp;
    mp.L = std::atof(argv[1]), mp.q = 8, mp.pl = 1, mp.seed = 1;
    DiscretizationParams dp;
    dp.scheme = parse_scheme(argv[2]);
    dp.aspect_ratio = 10;
    const double gamma = argc > 3 ? std::atof(argv[3]) : 0.01;
    const std::string rules = argc > 4 ? argv[4] : "none";
    dp.trim_ends = rules.find("ends") != std::string::npos;
    Network net = generate_mikado(mp);
    if (rules.find("dangling") != std::string::npos) net = prune(net, PruneOptions{true, false});
    const Model m = discretize(net, dp);
    NetworkEnergy e(m);
    const int n = e.num_dofs();
    const Eigen::VectorXd q0 = e.dofs(m.x);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();

    // Assembly (median of 3).
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    EnergyEval ev;
    std::vector<double> ta, tf;
    for (int k = 0; k < 3; ++k) {
        auto t = Clock::now();
        e.evaluate(q0, I, Eigen::Matrix2d::Zero(), kGradient | kHessian, ev, &H);
        ta.push_back(since(t));
    }
    // Symbolic analysis once, numeric factorization (median of 3) with the shift moduli use.
    CholmodLLT llt;
    auto t = Clock::now();
    llt.analyze(H);
    const double t_an = since(t);
    double dm = 0;
    for (int j = 0; j < n; ++j) dm += std::abs(H.coeff(j, j));
    dm /= std::max(n, 1);
    for (int k = 0; k < 3; ++k) {
        t = Clock::now();
        bool ok = false;
        for (double s = 1e-12 * dm; !ok && s < dm; s *= 100) ok = llt.factorize(H, s);
        tf.push_back(since(t));
    }
    std::sort(ta.begin(), ta.end());
    std::sort(tf.begin(), tf.end());

    // Modulus at the reference equilibrium (the straight reference state is stress-free).
    SolverOptions opt;
    opt.max_iter = 500;
    NewtonSolver newton(opt);
    const Equilibrium eq0 = relax(e, I, newton);
    // The symbolic analysis is once per model (t_analyze); the modulus reuses it, as `fibernet modulus` reuses
    // Newton's. (relax at F = I returns the rest state without a solve, so nothing has analyzed the pattern yet.)
    newton.factorization_for(e.hessian_pattern());
    t = Clock::now();
    ModuliInfo info;
    const auto mods = linear_moduli(e, eq0.q, I, {shear_mode(I, m.box.area()), bulk_mode(I, m.box.area())}, {}, &info,
                                    newton.factorization());
    const double t_mod = since(t);

    // Newton to 1e-10 at gamma (gamma = 0: skipped, printed as -1; for the largest networks).
    Equilibrium eq;
    if (gamma != 0) eq = relax(e, deformation(StrainKind::Shear, gamma), newton);
    else eq.result.timings.total = -1, eq.result.iterations = eq.result.factorizations = -1;

    rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    std::printf("%g\t%s\t%zu\t%d\t%.4f\t%.4f\t%.4f\t%.4f\t%.2f\t%.3f\t%d\t%d\t%.2e\t%s\t%.0f\t%.6g\t%.4g\n", mp.L,
                argv[2], net.fibers.size(), n, ta[1], t_an, tf[1], t_mod, t_mod / tf[1], eq.result.timings.total,
                eq.result.iterations, eq.result.factorizations, eq.result.grad_max, gamma == 0 ? "skipped" : to_string(eq.result.status).c_str(),
                ru.ru_maxrss / 1024.0, mods[0].value, mods[0].value / mods[0].affine);
    std::fprintf(stderr, "modulus breakdown: assembly %.4f analysis+factorization %.4f (one %.4f) solves %.4f affine %.4f\n",
                 info.seconds_assembly, info.seconds_factorization, info.seconds_one_factorization, info.seconds_solve,
                 info.seconds_affine);
    return 0;
}
