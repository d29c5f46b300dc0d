// Any element term's derivatives against central differences on its own local coordinates and along the strain
// (element_term.hpp): the check a new term reuses. Applied to the stretch and bend terms of a sheared periodic
// network with clamped nodes, one segment in the softcore and one hinge bent past 90 deg.
#include <catch2/catch.hpp>
#include <cmath>

#include "fd.hpp"
#include "fibernet/energy/bend.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/stretch.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/random.hpp"

using namespace fibernet;

namespace {
struct Setup {
    Model m;
    std::vector<int> dof;
    Eigen::Matrix2d F, dF;
    Eigen::VectorXd u;
    std::size_t soft = 0, folded = 0;  // the compressed segment and the folded hinge
};

Setup setup() {
    MikadoParams p;
    p.L = 3.2, p.q = 3, p.pl = 0.7, p.seed = 3;
    DiscretizationParams d;
    d.scheme = Scheme::Seed, d.n_seg = 4, d.h = 3.0, d.aspect_ratio = 10;
    Setup s{discretize(generate_mikado(p), d), {}, {}, {}, {}};
    s.m.fixed.assign(s.m.num_nodes(), 0);
    for (int i = 0; i < s.m.num_nodes(); i += 7) s.m.fixed[i] = 1;
    int n = 0;
    for (int i = 0; i < s.m.num_nodes(); ++i)
        for (int c = 0; c < 2; ++c) s.dof.push_back(s.m.fixed[i] ? -1 : n++);
    s.F << 1.05, 0.3, -0.1, 0.95;
    s.dF << 0.2, 1, -0.3, 0.1;
    Rng rng(5);
    s.u.setZero(2 * s.m.num_nodes());
    for (int i = 0; i < s.u.size(); ++i) s.u[i] = 0.15 * (2 * rng.uniform() - 1);
    // A segment inside the box with free nodes compressed to 3 % (softcore); a hinge inside the box with free nodes
    // and none of that segment's folded: its node k moved back past node i.
    auto free = [&](int i) { return !s.m.fixed[i]; };
    while (!(s.m.segments[s.soft].shift.isZero() && free(s.m.segments[s.soft].i) && free(s.m.segments[s.soft].j)))
        ++s.soft;
    const Segment& g = s.m.segments[s.soft];
    auto apart = [&](const Hinge& h) {
        for (int v : {h.i, h.j, h.k})
            if (v == g.i || v == g.j || !free(v)) return false;
        return h.shift1.isZero() && h.shift2.isZero();
    };
    while (!apart(s.m.hinges[s.folded])) ++s.folded;
    const Eigen::Vector2d di = s.m.x.segment<2>(2 * g.i) + s.u.segment<2>(2 * g.i);
    const Eigen::Vector2d dj = s.m.x.segment<2>(2 * g.j) + s.u.segment<2>(2 * g.j);
    s.u.segment<2>(2 * g.j) = di + 0.03 * (dj - di) - s.m.x.segment<2>(2 * g.j);
    const Hinge& h = s.m.hinges[s.folded];
    s.u.segment<2>(2 * h.k) += 1.6 * (s.m.x.segment<2>(2 * h.i) - s.m.x.segment<2>(2 * h.k));
    return s;
}

// Checks elements [0, count) of term t at u: gradient and Hessian against differences of the value and gradient
// in the element's node coordinates, and dE/dt, d2E/dt2, d2E/dq dt against differences along F + t dF (fixed nodes
// move with F: u = (F - I) x_ref for them).
void check_term(const ElementTerm& t, const Setup& s, std::size_t count, std::size_t special) {
    const int M = 2 * t.valence();
    const double h = 1e-6;
    std::vector<std::size_t> elements = {special};
    for (std::size_t e = 0; e < std::min(count, t.size()); ++e) elements.push_back(e);
    for (std::size_t e : elements) {
        int nodes[kMaxElementCoords / 2];
        t.nodes(e, nodes);
        auto at = [&](const Eigen::VectorXd& local, double dt, ElementResult& r, const ElementWant& w) {
            Eigen::VectorXd u = s.u;
            const Eigen::Matrix2d F = s.F + dt * s.dF;
            for (int i = 0; i < s.m.num_nodes(); ++i)
                if (s.dof[2 * i] < 0) u.segment<2>(2 * i) = (F - Eigen::Matrix2d::Identity()) * s.m.x.segment<2>(2 * i);
            for (int a = 0; a < M; ++a) u[2 * nodes[a / 2] + a % 2] += local[a];
            const ElementFrame frame(s.m, s.dof, u, F, s.dF, w.strain, false);
            t.evaluate(e, frame, w, r);
        };
        ElementWant all;
        all.gradient = all.hessian = all.strain = true;
        ElementResult r0;
        const Eigen::VectorXd zero = Eigen::VectorXd::Zero(M);
        at(zero, 0, r0, all);
        auto value = [&](const Eigen::VectorXd& l) { ElementResult r; at(l, 0, r, {}); return r.energy; };
        auto grad = [&](const Eigen::VectorXd& l) {
            ElementResult r;
            ElementWant w;
            w.gradient = true;
            at(l, 0, r, w);
            return Eigen::VectorXd(r.gradient.head(M));
        };
        INFO(t.name() << " element " << e);
        CHECK(fdtest::rel_err(r0.gradient.head(M), fdtest::fd_gradient(value, zero, h), 1e-3) < 1e-6);
        CHECK(fdtest::rel_err(r0.hessian.topLeftCorner(M, M), fdtest::fd_jacobian(grad, zero, h), 1e-3) < 1e-5);
        // Along the strain: fixed nodes move with F, free ones stay (the strain derivatives are at fixed q).
        auto along = [&](double dt, ElementResult& r) {
            ElementWant w = all;
            w.hessian = false;
            at(zero, dt, r, w);
        };
        ElementResult rp, rm;
        along(h, rp), along(-h, rm);
        const double scale = std::max({std::abs(r0.energy), std::abs(r0.dE_dt), 1e-3});
        CHECK(std::abs((rp.energy - rm.energy) / (2 * h) - r0.dE_dt) < 1e-6 * scale);
        CHECK(std::abs((rp.dE_dt - rm.dE_dt) / (2 * h) - r0.d2E_dt2) < 1e-5 * std::max(std::abs(r0.d2E_dt2), scale));
        const Eigen::VectorXd gt = (rp.gradient.head(M) - rm.gradient.head(M)) / (2 * h);
        CHECK(fdtest::rel_err(r0.d2E_dqdt.head(M), gt, 1e-3) < 1e-5);
    }
}
}  // namespace

TEST_CASE("element terms: stretch and bend derivatives against differences", "[energy][element]") {
    const Setup s = setup();
    const StretchTerm stretch(s.m, StretchLaw{});
    const BendTerm bend(s.m);
    check_term(stretch, s, 60, s.soft);
    check_term(bend, s, 60, s.folded);
    // The regimes the setup forces are there.
    const ElementFrame frame(s.m, s.dof, s.u, s.F, s.dF, false, false);
    Eigen::Vector2d d, c;
    const Segment& g = s.m.segments[s.soft];
    frame.edge(g.i, g.j, g.shift, rest_vector(s.m, g.d0, g.i, g.j, g.shift), d, c);
    CHECK(d.norm() / g.l0 - 1 < StretchLaw{}.eps_star);
    const Hinge& h = s.m.hinges[s.folded];
    Eigen::Vector2d d1, d2;
    frame.edge(h.i, h.j, h.shift1, rest_vector(s.m, h.d10, h.i, h.j, h.shift1), d1, c);
    frame.edge(h.j, h.k, h.shift2, rest_vector(s.m, h.d20, h.j, h.k, h.shift2), d2, c);
    CHECK(d1.dot(d2) < 0);
}

TEST_CASE("element terms: the energy's terms are its split", "[energy][element]") {
    const Setup s = setup();
    const NetworkEnergy e(s.m);
    EnergyEval ev;
    const Eigen::VectorXd q = e.dofs(s.m.x + s.u);
    e.evaluate(q, s.F, s.dF, kValue, ev);
    REQUIRE(e.term_names() == std::vector<std::string>{"stretch", "bend"});
    REQUIRE(ev.terms.size() == 2);
    CHECK(ev.terms[0] == ev.stretch);
    CHECK(ev.terms[1] == ev.bend);
    CHECK(ev.energy == ev.stretch + ev.bend);
}
