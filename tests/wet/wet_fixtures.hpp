#pragma once
// Small hand-made networks for the wet tests.
#include <catch2/catch.hpp>
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "../energy/fd.hpp"
#include "fibernet/energy/capillary.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/util/parallel.hpp"
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

// The fibers' rest length in the model (the free box's stress scale is beta times it per box area).
inline double total_length(const Model& m) {
    double l = 0;
    for (const Segment& s : m.segments) l += s.l0;
    return l;
}

// The symmetric matrix whose upper triangle is `upper`, dense (for small test networks).
inline Eigen::MatrixXd dense(const Eigen::SparseMatrix<double>& upper) {
    const Eigen::MatrixXd U(upper);
    return Eigen::MatrixXd(U.selfadjointView<Eigen::Upper>());
}

// Two crossing fibers (issue 6 tests): fiber 1 along x held fixed, fiber 2 at angle alpha through its midpoint
// (both crossing mid-segment for odd n_seg) and pinned at both ends.
struct TwoFiber {
    Network net;
    Model m;
};

inline TwoFiber two_fibers(double alpha_deg, int n_seg) {
    TwoFiber t;
    t.net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.5, 1.5, alpha_deg, 1, 0.5}}, 3);
    t.m = model_of(t.net, n_seg);
    t.m.fixed.assign(t.m.num_nodes(), 0);
    for (int n : t.m.chains[0].nodes) t.m.fixed[n] = 1;
    t.m.fixed[t.m.chains[1].nodes.front()] = t.m.fixed[t.m.chains[1].nodes.back()] = 1;
    return t;
}

// The direction angle of segment k of fiber f at q.
inline double segment_angle(const NetworkEnergy& e, const Eigen::VectorXd& q, int f, int k) {
    const Eigen::VectorXd x = e.positions(q, Eigen::Matrix2d::Identity());
    const FiberChain& ch = e.model().chains[f];
    const Eigen::Vector2d d = x.segment<2>(2 * ch.nodes[k + 1]) - x.segment<2>(2 * ch.nodes[k]);
    return std::atan2(d.y(), d.x());
}

// The gradient g and Hessian H of a wet energy W at q, and those of its capillary part (W less the dry energy D, whose
// much stiffer terms would hide an error in it), against central differences of values and gradients. Returns the
// dense Hessians of W and of its capillary part.
template <class Energy>
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> check_against_differences(Energy& W, Energy& D, const Eigen::VectorXd& q) {
    auto full = [](Energy& E, const Eigen::VectorXd& v, Eigen::VectorXd& g) {
        Eigen::SparseMatrix<double> H = E.hessian_pattern();
        E.hessian(v, g, H, false);
        return dense(H);
    };
    Eigen::VectorXd g, gd;
    const Eigen::MatrixXd Hf = full(W, q, g), Hcap = Hf - full(D, q, gd);
    auto val = [&](const Eigen::VectorXd& v) { return W.value(v); };
    auto grad = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd r;
        W.gradient(v, r);
        return r;
    };
    auto capval = [&](const Eigen::VectorXd& v) { return W.value(v) - D.value(v); };
    auto capgrad = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd a, b;
        W.gradient(v, a), D.gradient(v, b);
        return Eigen::VectorXd(a - b);
    };
    const double h = 1e-6;
    CHECK(fdtest::rel_err(g, fdtest::fd_gradient(val, q, h)) < 1e-6);
    CHECK(fdtest::rel_err(Hf, fdtest::fd_jacobian(grad, q, h)) < 1e-6);
    CHECK(fdtest::rel_err(g - gd, fdtest::fd_gradient(capval, q, h), 1e-3) < 1e-6);
    CHECK(fdtest::rel_err(Hcap, fdtest::fd_jacobian(capgrad, q, h), 1e-3) < 1e-5);
    return {Hf, Hcap};
}

// W's value, energy, gradient and Hessian at q on one thread and on three: the same bits (sums in a fixed order).
template <class Energy>
void check_same_on_threads(Energy& W, const Eigen::VectorXd& q) {
    auto evaluate = [&](int threads, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, double& v) {
        set_thread_count(threads);
        H = W.hessian_pattern();
        const double e = W.hessian(q, g, H, false);
        v = W.value(q);
        return e;
    };
    Eigen::VectorXd g1, g3;
    Eigen::SparseMatrix<double> H1, H3;
    double v1 = 0, v3 = 0;
    const double e1 = evaluate(1, g1, H1, v1), e3 = evaluate(3, g3, H3, v3);
    set_thread_count(0);
    CHECK(e1 == e3);
    CHECK(v1 == v3);
    CHECK((g1.array() == g3.array()).all());
    REQUIRE(H1.nonZeros() == H3.nonZeros());
    CHECK(std::equal(H1.valuePtr(), H1.valuePtr() + H1.nonZeros(), H3.valuePtr()));
}

inline Network mikado(double L, double q, double pl, std::uint64_t seed) {
    MikadoParams p;
    p.L = L, p.q = q, p.pl = pl, p.seed = seed;
    return generate_mikado(p);
}

// A tabulated capillary law unlike the default -cos^2 (a bump at 45 deg), for the finite-difference checks of both
// wet models' tabulated regime.
inline CapillaryLaw tabulated_law() {
    std::vector<double> a, v;
    for (int i = 0; i <= 18; ++i) {
        const double r = 5.0 * i * M_PI / 180;
        a.push_back(5.0 * i), v.push_back(-std::cos(r) * std::cos(r) + 0.1 * std::sin(2 * r) * std::sin(2 * r));
    }
    return CapillaryLaw::tabulated(a, v, "test table");
}

// A small random network (seed scheme, 4 segments per fiber) with every fifth node fixed (a clamp), for the
// fixed-node terms of the strain derivatives (a fixed node sits at F x_ref); clamped_box() is a general F for it.
inline Model clamped_network() {
    Model m = model_of(mikado(2.5, 4, 0.5, 7), 4);
    m.fixed.assign(m.num_nodes(), 0);
    for (int i = 0; i < m.num_nodes(); i += 5) m.fixed[i] = 1;
    return m;
}
inline Eigen::Matrix2d clamped_box() {
    Eigen::Matrix2d F;
    F << 1.05, 0.2, -0.1, 0.95;
    return F;
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
