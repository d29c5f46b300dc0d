#pragma once
// Small hand-made networks for the wet tests.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cmath>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/util/random.hpp"
#include "fibernet/wet/wetting.hpp"

namespace wetfix {
using namespace fibernet;

struct Line {
    double x, y, theta_deg, length;  // a fiber through (x, y) (network units: fiber lengths) ...
    double s_at;                     // ... at arc position s_at (fraction of its length)
};

inline Network network_of(const std::vector<Line>& lines, double L, bool periodic = true, bool crosslink = false) {
    Network net;
    net.L = L, net.periodic = periodic;
    for (const auto& l : lines) {
        Fiber f;
        f.theta = l.theta_deg * M_PI / 180, f.length = l.length;
        f.start = Eigen::Vector2d(l.x, l.y) - l.s_at * l.length * f.direction();
        net.fibers.push_back(f);
    }
    net.crossings = find_crossings(net);
    for (auto& c : net.crossings) c.crosslink = crosslink;
    return net;
}

inline Model model_of(const Network& net, int n_seg = 10, double a = 10) {
    DiscretizationParams d;
    d.n_seg = n_seg, d.aspect_ratio = a;
    return discretize(net, d);
}

inline Eigen::VectorXd perturb(Eigen::VectorXd q, double amp, std::uint64_t seed) {
    Rng rng(seed);
    for (int i = 0; i < q.size(); ++i) q[i] += amp * (2 * rng.uniform() - 1);
    return q;
}

// The symmetric matrix whose upper triangle is `upper`, dense (for small test networks).
inline Eigen::MatrixXd dense(const Eigen::SparseMatrix<double>& upper) {
    const Eigen::MatrixXd U(upper);
    return Eigen::MatrixXd(U.selfadjointView<Eigen::Upper>());
}

inline Network mikado(double L, double q, double pl, std::uint64_t seed) {
    MikadoParams p;
    p.L = L, p.q = q, p.pl = pl, p.seed = seed;
    return generate_mikado(p);
}

// Passes each call to Newton with the options the loop set, and records them.
class Recording : public Solver {
public:
    explicit Recording(SolverOptions o) : opt_(o), inner_(o) {}
    std::string name() const override { return "newton"; }
    SolverOptions& options() override { return opt_; }
    SolverCapabilities capabilities() const override { return inner_.capabilities(); }
    std::unique_ptr<Solver> clone() const override { return inner_.clone(); }  // a thread's solver: not recorded
    SolveResult minimize(Objective& f, Eigen::VectorXd& q) override {
        caps.push_back(opt_.max_iter);
        warm.push_back(opt_.warm_start);
        ldl.push_back(opt_.ldl);
        inner_.options() = opt_;
        const SolveResult r = inner_.minimize(f, q);
        iterations.push_back(r.iterations);
        return r;
    }
    std::vector<int> caps, iterations;
    std::vector<bool> warm, ldl;

private:
    SolverOptions opt_;
    NewtonSolver inner_;
};

}  // namespace wetfix
