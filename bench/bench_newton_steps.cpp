// Diagnostic (docs/moduli.md, "Where Newton's iterations go"; not a test): Newton with the exact Hessian, a tiny
// fixed shift and Armijo backtracking on a sheared Mikado network (q = 8, pl = 1, a = 10, seed 1, even scheme),
// printing per iteration the energy, max|g|, the step length and the node where the step is largest, with that
// node's reference position and its fiber(s). A run of iterations whose largest step sits on one node is a
// localized slow event (e.g. a load-free arm rotating with its pin). Stops at max|g| <= 1e-9 or when the line
// search stalls on round-off. Count the iterations per node with
//   build/bench_newton_steps 10 0.01 none | awk -F'\t' 'NR > 1 {c[$6]++} END {for (k in c) print k, c[k]}'

// Usage: bench_newton_steps L gamma [none|ends|dangling,ends] [max_iter]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/prune.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/cholmod_llt.hpp"

using namespace fibernet;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: bench_newton_steps L gamma [none|ends|dangling,ends] [max_iter]\n");
        return 2;
    }
    MikadoParams mp;
    mp.L = std::atof(argv[1]), mp.q = 8, mp.pl = 1, mp.seed = 1;
    const double gamma = std::atof(argv[2]);
    const std::string rules = argc > 3 ? argv[3] : "none";
    const int max_iter = argc > 4 ? std::atoi(argv[4]) : 500;
    DiscretizationParams dp;
    dp.scheme = Scheme::Even, dp.aspect_ratio = 10;
    dp.trim_ends = rules.find("ends") != std::string::npos;
    Network net = generate_mikado(mp);
    if (rules.find("dangling") != std::string::npos) net = prune(net, PruneOptions{true, false});
    const Model m = discretize(net, dp);
    const NetworkEnergy e(m);
    const int n = e.num_dofs();
    std::vector<int> node_of(n);
    for (int i = 0; i < m.num_nodes(); ++i)
        for (int c = 0; c < 2; ++c)
            if (e.dof(i, c) >= 0) node_of[e.dof(i, c)] = i;
    std::vector<std::string> fibers_of(m.num_nodes());
    for (size_t f = 0; f < m.chains.size(); ++f)
        for (int v : m.chains[f].nodes) fibers_of[v] += (fibers_of[v].empty() ? "" : ",") + std::to_string(f);

    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    F(0, 1) = gamma;
    Eigen::VectorXd q = affine_start(e, F), g(n), d(n);
    StrainedEnergy f(e, F);
    Eigen::SparseMatrix<double> H = f.hessian_pattern();
    CholmodLLT llt;
    llt.analyze(H);
    std::printf("it\tenergy\tmax_g\tmax_step\talpha\tnode\tx\ty\tfibers\n");
    for (int it = 0; it < max_iter; ++it) {
        const double fq = f.hessian(q, g, H, false);
        const double gmax = g.lpNorm<Eigen::Infinity>();
        if (gmax <= 1e-9) break;
        const double dm = H.diagonal().cwiseAbs().mean();
        for (double s = 1e-12 * dm; !llt.factorize(H, s); s *= 10) {}
        d = llt.solve(-g);
        int k = 0;
        const double dmax = d.cwiseAbs().maxCoeff(&k);
        double alpha = 1;
        for (int h = 0; h < 40; ++h, alpha *= 0.5) {
            const double ft = f.value(q + alpha * d);
            if (std::isfinite(ft) && ft <= fq + 1e-4 * alpha * g.dot(d)) break;
        }
        const int v = node_of[k];
        std::printf("%d\t%.12e\t%.3e\t%.3e\t%g\t%d\t%.2f\t%.2f\t%s\n", it, fq, gmax, alpha * dmax, alpha, v, m.x[2 * v],
                    m.x[2 * v + 1], fibers_of[v].c_str());
        q += alpha * d;
        if (alpha < 1e-6) {  // round-off: the fixed-shift step cannot lower the energy any more
            std::fprintf(stderr, "stalled at max|g| = %.3e (round-off; Newton proper is solve/newton.cpp)\n", gmax);
            break;
        }
    }
    return 0;
}
