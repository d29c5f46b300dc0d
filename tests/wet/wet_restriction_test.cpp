// WetEnergy::restriction (wet_restriction.cpp): the wet energy of a set of coordinates alone is the whole energy's
// restricted to them (gradient, Hessian, value changes), refused for a set that splits a node, and Newton with
// nonlinear elimination on it ends at a minimum of the whole wet energy (not always plain Newton's: see below).
#include <catch2/catch.hpp>
#include <Eigen/Eigenvalues>

#include "fibernet/solve/newton.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {
struct Wetted {
    Network net = mikado(2.5, 6, 0.5, 5);
    Model m = model_of(net, 8);
    NetworkEnergy dry{m};
    Eigen::Matrix2d F;
    Eigen::VectorXd q;
    std::unique_ptr<WetEnergy> W;

    explicit Wetted(double beta, double amp = 0.02) {
        F << 1.02, 0.08, 0.0, 0.99;  // sheared, across periodic images
        q = perturb(dry.affine_map(dry.dofs(m.x), Eigen::Matrix2d::Identity(), F), amp, 3);
        WetParams p;
        p.beta = beta;
        W = std::make_unique<WetEnergy>(dry, F, segment_crossings(m, dry.positions(q, F), F * m.box.B0()), p);
    }
    // The coordinates of every k-th node with both coordinates free.
    std::vector<int> coords_of_nodes(int k) const {
        std::vector<int> c;
        for (int v = 0; v < m.num_nodes(); v += k)
            if (dry.dof(v, 0) >= 0 && dry.dof(v, 1) >= 0) c.push_back(dry.dof(v, 0)), c.push_back(dry.dof(v, 1));
        std::sort(c.begin(), c.end());
        return c;
    }
};
}  // namespace

TEST_CASE("wet restriction: the whole energy's gradient, Hessian and value changes on the set", "[wet][region]") {
    Wetted w(0.7);
    REQUIRE(w.W->bridges().size() >= 5);
    const std::vector<int> coords = w.coords_of_nodes(3);
    REQUIRE(coords.size() > 20);
    std::unique_ptr<Objective> R = w.W->restriction(w.q, coords);
    REQUIRE(R);
    REQUIRE(R->size() == static_cast<int>(coords.size()));
    Eigen::VectorXd g, ga;
    Eigen::SparseMatrix<double> H = w.W->hessian_pattern(), Ha = R->hessian_pattern();
    w.W->hessian(w.q, g, H, false);
    Eigen::VectorXd qa(coords.size());
    for (size_t k = 0; k < coords.size(); ++k) qa[k] = w.q[coords[k]];
    R->hessian(qa, ga, Ha, false);
    const Eigen::MatrixXd Hf = dense(H), Hr = dense(Ha);
    double dg = 0, dH = 0;
    for (size_t i = 0; i < coords.size(); ++i) {
        dg = std::max(dg, std::abs(ga[i] - g[coords[i]]));
        for (size_t j = 0; j < coords.size(); ++j) dH = std::max(dH, std::abs(Hr(i, j) - Hf(coords[i], coords[j])));
    }
    CHECK(dg <= 1e-12 * g.cwiseAbs().maxCoeff());
    CHECK(dH <= 1e-12 * Hf.cwiseAbs().maxCoeff());
    const Eigen::VectorXd qa2 = perturb(qa, 0.01, 9);
    Eigen::VectorXd q2 = w.q;
    for (size_t k = 0; k < coords.size(); ++k) q2[coords[k]] = qa2[k];
    CHECK(R->value(qa2) - R->value(qa) == Approx(w.W->value(q2) - w.W->value(w.q)).margin(1e-10));
}

TEST_CASE("wet restriction: a set holding one coordinate of a node is not offered", "[wet][region]") {
    Wetted w(0.7);
    std::vector<int> coords = w.coords_of_nodes(3);
    coords.erase(coords.begin() + 1);  // the second coordinate of the first node
    CHECK(w.W->restriction(w.q, coords) == nullptr);
    CHECK(w.W->restriction(w.q, w.coords_of_nodes(3)) != nullptr);
}

namespace {
struct Pair {
    SolveResult plain, eliminated;
    Eigen::VectorXd q_plain, q_eliminated;
};
Pair solve_both(Wetted& w, double tol) {
    SolverOptions o;
    o.tol = tol, o.max_iter = 500;
    Pair p{{}, {}, w.q, w.q};
    p.plain = NewtonSolver(o).minimize(*w.W, p.q_plain);
    o.eliminate = true;
    o.elimination.hops = 1, o.elimination.max_fraction = 0.5;  // places small enough for this small network
    p.eliminated = NewtonSolver(o).minimize(*w.W, p.q_eliminated);
    return p;
}
// Negative eigenvalues of the wet Hessian at q beyond round-off (the null modes, translations, stay near zero).
int negative_curvatures(WetEnergy& W, const Eigen::VectorXd& q) {
    Eigen::SparseMatrix<double> H = W.hessian_pattern();
    Eigen::VectorXd g;
    W.hessian(q, g, H, false);
    const Eigen::MatrixXd D = dense(H);
    const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(D).eigenvalues();
    int neg = 0;
    for (int i = 0; i < ev.size(); ++i) neg += ev[i] < -1e-6 * D.cwiseAbs().maxCoeff();
    return neg;
}
}  // namespace

TEST_CASE("wet restriction: Newton with elimination ends at a minimum of the whole wet energy", "[wet][region][relax]") {
    for (double amp : {0.0, 0.02}) {
        Wetted w(0.3, amp);
        const double e0 = w.W->value(w.q);
        const Pair p = solve_both(w, 1e-9);
        INFO("start perturbed by " << amp << ": plain " << to_string(p.plain.status) << " " << p.plain.iterations
                                   << ", eliminate " << to_string(p.eliminated.status) << " " << p.eliminated.iterations
                                   << " with " << p.eliminated.local_solves << " local solves");
        REQUIRE(p.plain.converged());
        REQUIRE(p.eliminated.converged());
        CHECK(p.eliminated.local_solves > 0);
        // An equilibrium of the whole energy, checked afresh on every coordinate, below the start, and a minimum
        // (no negative curvature), not a saddle.
        Eigen::VectorXd g;
        w.W->gradient(p.q_eliminated, g);
        CHECK(g.lpNorm<Eigen::Infinity>() <= std::max(1e-9, p.eliminated.grad_floor));
        CHECK(p.eliminated.energy < e0);
        CHECK(negative_curvatures(*w.W, p.q_eliminated) == 0);
        // Which minimum a path reaches is its own: this wet energy has several (docs/solvers.md, "Nonlinear
        // elimination"), and here elimination ends higher than plain Newton.
    }
}
