// Cost of the blended bridge element (bridge.hpp): a Mikado network (seed scheme, so every crossing is a node and its
// bridge sits in a blend zone) wetted at all crossings, node positions perturbed so the weights vary. Times, per call,
// bridge_element_energy alone over all bridges (gradient only; gradient and Hessian) against the Jet<16> reference
// evaluation, and the whole WetEnergy Hessian. Old and new alternate in each repetition (the machine is shared);
// the best of the repetitions is reported, with the largest difference between the two evaluations.
//   bench_bridge_eval [N=300] [q=10] [amp=0.02 (x mean segment length)] [reps=7] [seed=1]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/random.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/wet/wetting.hpp"

using namespace fibernet;

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

using Eval = double (*)(const BridgeElement&, const Vector16d&, double, const CapillaryLaw&, Vector16d*, Matrix16d*,
                        bool);

// One pass over all elements; returns a checksum so the work is not optimized away.
double pass(Eval f, const std::vector<BridgeElement>& el, const std::vector<Vector16d>& X, const WetParams& p,
            bool hessian, bool psd) {
    Vector16d g;
    Matrix16d H;
    double sum = 0;
    for (size_t k = 0; k < el.size(); ++k) {
        sum += f(el[k], X[k], p.beta, p.law, &g, hessian ? &H : nullptr, psd);
        sum += g[0] + (hessian ? H(0, 0) : 0.0);
    }
    return sum;
}
}  // namespace

int main(int argc, char** argv) {
    const int N = argc > 1 ? std::atoi(argv[1]) : 300;
    const double density = argc > 2 ? std::atof(argv[2]) : 10;
    const double amp = argc > 3 ? std::atof(argv[3]) : 0.02;
    const int reps = argc > 4 ? std::atoi(argv[4]) : 7;
    const unsigned seed = argc > 5 ? static_cast<unsigned>(std::atoi(argv[5])) : 1u;

    MikadoParams mp;
    mp.q = density, mp.pl = 0.5, mp.seed = seed;
    mp.L = std::sqrt(N / density);
    const Network net = generate_mikado(mp);
    DiscretizationParams dp;
    dp.scheme = parse_scheme("seed");
    const Model m = discretize(net, dp);
    NetworkEnergy dry(m);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity(), B = m.box.B0();
    double lmean = 0;
    for (const auto& s : m.segments) lmean += s.l0;
    lmean /= static_cast<double>(m.segments.size());
    Eigen::VectorXd q = dry.dofs(m.x);
    Rng rng(seed + 1000);
    for (int i = 0; i < q.size(); ++i) q[i] += amp * lmean * (2 * rng.uniform() - 1);
    const Eigen::VectorXd x = dry.positions(q, I);

    WetParams p;
    p.beta = 0.01;
    WetEnergy W(dry, I, wet_crossings(net, m, dry.positions(dry.dofs(m.x), I), B, WettingRule{}), p);
    const std::vector<BridgeElement>& el = W.elements();
    std::vector<Vector16d> X;
    int in_zone = 0;
    for (const auto& e : el) {
        X.push_back(element_coordinates(e, x, B));
        const CrossingPosition c = crossing_position(e, X.back());
        bool z = false;
        for (int s = 0; s < 2; ++s)
            for (int n = 0; n < 2; ++n) z = z || std::abs(c.z[s][n]) < c.delta[s][n];
        in_zone += c.defined && z;
    }

    // Largest differences, new vs reference, relative to each element's largest entry.
    double dE = 0, dg = 0, dH = 0, dHp = 0;
    for (size_t k = 0; k < el.size(); ++k) {
        Vector16d g0, g1;
        Matrix16d H0, H1;
        for (bool psd : {false, true}) {
            const double e0 = bridge_element_energy_reference(el[k], X[k], p.beta, p.law, &g0, &H0, psd);
            const double e1 = bridge_element_energy(el[k], X[k], p.beta, p.law, &g1, &H1, psd);
            const double eh = (H1 - H0).cwiseAbs().maxCoeff() / std::max(H0.cwiseAbs().maxCoeff(), 1e-300);
            if (psd) dHp = std::max(dHp, eh);
            else {
                dE = std::max(dE, std::abs(e1 - e0) / std::max(std::abs(e0), 1e-300));
                dg = std::max(dg, (g1 - g0).cwiseAbs().maxCoeff() / std::max(g0.cwiseAbs().maxCoeff(), 1e-300));
                dH = std::max(dH, eh);
            }
        }
    }

    struct Row {
        const char* name;
        bool hessian, psd;
        double t_old = 1e300, t_new = 1e300;
    };
    Row rows[] = {{"element gradient", false, false}, {"element gradient+hessian", true, false},
                  {"element gradient+hessian psd", true, true}};
    double sink = 0;
    const int inner = std::max(1, static_cast<int>(20000 / std::max<size_t>(el.size(), 1)));
    for (int r = 0; r < reps; ++r)
        for (Row& row : rows) {
            auto t0 = Clock::now();
            for (int i = 0; i < inner; ++i)
                sink += pass(bridge_element_energy_reference, el, X, p, row.hessian, row.psd);
            row.t_old = std::min(row.t_old, seconds_since(t0) / (inner * static_cast<double>(el.size())));
            t0 = Clock::now();
            for (int i = 0; i < inner; ++i) sink += pass(bridge_element_energy, el, X, p, row.hessian, row.psd);
            row.t_new = std::min(row.t_new, seconds_since(t0) / (inner * static_cast<double>(el.size())));
        }

    // The whole wet Hessian (dry part included), with this build's element.
    Eigen::VectorXd g;
    Eigen::SparseMatrix<double> H = W.hessian_pattern();
    double t_h = 1e300, t_hp = 1e300, t_dry = 1e300;
    WetParams p0 = p;
    p0.beta = 0;
    WetEnergy D(dry, I, W.bridges(), p0);
    Eigen::SparseMatrix<double> Hd = D.hessian_pattern();
    const int kh = std::max(1, static_cast<int>(200000 / std::max<long>(q.size(), 1)));
    for (int r = 0; r < reps; ++r) {
        auto t0 = Clock::now();
        for (int i = 0; i < kh; ++i) sink += W.hessian(q, g, H, false);
        t_h = std::min(t_h, seconds_since(t0) / kh);
        t0 = Clock::now();
        for (int i = 0; i < kh; ++i) sink += W.hessian(q, g, H, true);
        t_hp = std::min(t_hp, seconds_since(t0) / kh);
        t0 = Clock::now();
        for (int i = 0; i < kh; ++i) sink += D.hessian(q, g, Hd, false);
        t_dry = std::min(t_dry, seconds_since(t0) / kh);
    }

    std::printf("network: %zu fibers, %d nodes, %d dofs, %zu bridges (%d with a crossing in a blend zone)\n",
                net.fibers.size(), m.num_nodes(), static_cast<int>(q.size()), el.size(), in_zone);
    std::printf("new vs reference, max relative difference: energy %.2e, gradient %.2e, Hessian %.2e, "
                "psd Hessian %.2e\n", dE, dg, dH, dHp);
    for (const Row& row : rows)
        std::printf("%-30s reference %8.3f us/element   new %8.3f us/element   speedup %5.2fx\n", row.name,
                    1e6 * row.t_old, 1e6 * row.t_new, row.t_old / row.t_new);
    std::printf("WetEnergy::hessian (this build): %.3f ms, psd %.3f ms; dry part alone (beta = 0) %.3f ms\n", 1e3 * t_h,
                1e3 * t_hp, 1e3 * t_dry);
    std::printf("(checksum %g)\n", sink);
    return 0;
}
