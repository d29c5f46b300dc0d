// Mobility and events (issue 6, part 2): bridges follow their crossing across nodes without an energy jump, rupture
// continuously off a fiber end, form at new crossings and contacts; the outer loop terminates and reports.
#include <catch2/catch.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/wet/wet_run.hpp"
#include "wet_fixtures.hpp"

using namespace fibernet;
using namespace wetfix;

namespace {
const Eigen::Matrix2d I2 = Eigen::Matrix2d::Identity();

// q with fiber f's nodes moved by (dx, dy) (seed units) from q0.
Eigen::VectorXd moved(const NetworkEnergy& e, Eigen::VectorXd q, int f, double dx, double dy) {
    for (int n : e.model().chains[f].nodes) q[e.dof(n, 0)] += dx, q[e.dof(n, 1)] += dy;
    return q;
}

double capillary(const NetworkEnergy& e, const Eigen::VectorXd& q, const std::vector<Bridge>& b, const WetParams& p) {
    double s = 0;
    for (double v : WetEnergy(e, I2, b, p).bridge_energies(q)) s += v;
    return s;
}

struct Drag {
    std::vector<double> E;     // capillary energy after each update
    double max_switch = 0;     // largest |E(new set) - E(old set)| at one state
    double max_step = 0;       // largest |E_k+1 - E_k|
    WetEvents events;
};

// Drags fiber f by (dx, dy) per step; updates the bridges at every state (no formation).
Drag drag(const NetworkEnergy& e, Eigen::VectorXd q, std::vector<Bridge>& bridges, int f, double dx, double dy, int steps,
          const WetParams& p) {
    Drag d;
    ActiveSetOptions opt;
    opt.form_new = false;
    for (int i = 0; i <= steps; ++i) {
        const Eigen::VectorXd qi = moved(e, q, f, i * dx, i * dy);
        const double before = capillary(e, qi, bridges, p);
        const WetEvents ev = update_bridges(e, qi, I2, bridges, opt);
        d.events.moves += ev.moves, d.events.ruptures += ev.ruptures;
        const double after = capillary(e, qi, bridges, p);
        d.max_switch = std::max(d.max_switch, std::abs(after - before));
        if (!d.E.empty()) d.max_step = std::max(d.max_step, std::abs(after - d.E.back()));
        d.E.push_back(after);
    }
    return d;
}
// Fiber 1 along x from 10 to 20 (nodes at integers), kinked by 15 deg at x = 13; fiber 2 at 60 deg crosses it at 12.5.
struct KinkedCrossing {
    Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.25, 1.5, 60, 1, 0.45}}, 3);
    Model m = model_of(net);
    Eigen::VectorXd pos = kinked(m);

    static Eigen::VectorXd kinked(const Model& m) {
        Eigen::VectorXd pos = m.x;
        const double kink = 15 * M_PI / 180;
        for (int n : m.chains[0].nodes) {
            const double x = pos[2 * n] - 13, y = pos[2 * n + 1] - 15;
            if (x > 1e-9)
                pos[2 * n] = 13 + std::cos(kink) * x - std::sin(kink) * y,
                pos[2 * n + 1] = 15 + std::sin(kink) * x + std::cos(kink) * y;
        }
        return pos;
    }
};
}  // namespace

TEST_CASE("active set: a bridge dragged across a kinked node moves without an energy jump", "[wet][events]") {
    const KinkedCrossing k;
    const Network& net = k.net;
    const Model& m = k.m;
    NetworkEnergy e(m);
    const Eigen::VectorXd& pos = k.pos;
    Eigen::VectorXd q = e.dofs(pos);
    std::vector<Bridge> bridges = wet_crossings(net, m, e.positions(q, I2), m.box.B0(), {});
    REQUIRE(bridges.size() == 1);
    CHECK(bridges[0].k1 == 2);
    WetParams p;
    p.beta = 1;
    const Drag d = drag(e, q, bridges, 1, 0.0047, 0, 213, p);  // steps miss the node itself
    REQUIRE(bridges.size() == 1);
    CHECK(bridges[0].k1 == 3);       // it moved to the next segment of fiber 1
    CHECK(d.events.moves >= 1);
    CHECK(d.max_switch < 1e-12);     // moving the bridge changes no energy
    // Without blending the move would jump by beta l |cos^2 60 - cos^2 45| = 0.25; the blended path is smooth.
    CHECK(d.E.front() == Approx(-0.25).epsilon(1e-9));
    CHECK(d.E.back() == Approx(-0.5).epsilon(1e-9));
    CHECK(d.max_step < 0.04 * 0.25);  // the 0.25 change is spread over the blend zone (2 delta = 0.5, 100 steps)
}

TEST_CASE("active set: a bridge moves only a margin past a node (hysteresis against ping-pong)", "[wet][events]") {
    // As above: fiber 1 kinked at x = 13 (segments of 1: blend half-width delta = 0.25), fiber 2 at 60 deg crossing at
    // 12.5 and dragged along x, so the crossing moves with it. move_margin = 0.1: a move needs 0.025 past the node.
    const KinkedCrossing k;
    const Network& net = k.net;
    const Model& m = k.m;
    NetworkEnergy e(m);
    const Eigen::VectorXd& pos = k.pos;
    const Eigen::VectorXd q = e.dofs(pos);
    std::vector<Bridge> bridges = wet_crossings(net, m, e.positions(q, I2), m.box.B0(), {});
    REQUIRE(bridges.size() == 1);
    REQUIRE(bridges[0].k1 == 2);
    ActiveSetOptions opt;
    opt.form_new = false;
    REQUIRE(opt.move_margin == 0.1);
    auto home_after = [&](double dx) {
        update_bridges(e, moved(e, q, 1, dx, 0), I2, bridges, opt);
        REQUIRE(bridges.size() == 1);
        return bridges[0].k1;
    };
    CHECK(home_after(0.5 + 0.01) == 2);  // past the node by less than the margin: stays
    CHECK(home_after(0.5 + 0.04) == 3);  // beyond it: moves
    CHECK(home_after(0.5 + 0.01) == 3);  // back within the margin: stays on the new home
    CHECK(home_after(0.5 - 0.01) == 3);
    CHECK(home_after(0.5 - 0.04) == 2);  // back beyond the margin: moves back
    // With no margin the same states move the bridge each time the node is crossed.
    opt.move_margin = 0;
    CHECK(home_after(0.5 + 0.01) == 3);
    CHECK(home_after(0.5 - 0.01) == 2);
}

TEST_CASE("active set: a bridge moved onto a bridged pair merges, after a global or a local round", "[wet][events]") {
    // The kinked crossing above with a second bridge already on the next pair (segment 3 of fiber 1): the first one
    // moving there makes two on one pair, and the first in the list is kept. After a local round (moved nodes given)
    // only the keys of moved bridges are compared; both ways must agree.
    const KinkedCrossing k;
    const Model& m = k.m;
    NetworkEnergy e(m);
    const Eigen::VectorXd q = e.dofs(k.pos);
    std::vector<Bridge> start = wet_crossings(k.net, m, e.positions(q, I2), m.box.B0(), {});
    REQUIRE(start.size() == 1);
    REQUIRE(start[0].k1 == 2);
    REQUIRE(start[0].crossing >= 0);
    Bridge next = start[0];
    next.k1 = 3, next.crossing = -1;
    start.push_back(next);
    ActiveSetOptions opt;
    opt.form_new = false;
    const std::vector<char> all(m.num_nodes(), 1);
    for (const std::vector<char>* moved_nodes : {static_cast<const std::vector<char>*>(nullptr), &all}) {
        std::vector<Bridge> b = start;
        WetEvents ev = update_bridges(e, moved(e, q, 1, 0.5 + 0.01, 0), I2, b, opt, nullptr, false, moved_nodes);
        CHECK(ev.moves == 0);  // within the margin: both stay
        CHECK(ev.merged == 0);
        CHECK(b.size() == 2);
        ev = update_bridges(e, moved(e, q, 1, 0.5 + 0.04, 0), I2, b, opt, nullptr, false, moved_nodes);
        CHECK(ev.moves == 1);
        CHECK(ev.merged == 1);
        REQUIRE(b.size() == 1);
        CHECK(b[0].k1 == 3);
        CHECK(b[0].crossing == start[0].crossing);  // the first one, moved
    }
}

TEST_CASE("active set: sliding along a straight fiber keeps the capillary energy", "[wet][events]") {
    // Fiber 2 translated along its own axis: its crossing slides along fiber 2 across nodes (equal segments).
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.55, 1.5, 70, 1, 0.45}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    const Eigen::VectorXd q = e.dofs(m.x);
    std::vector<Bridge> bridges = wet_crossings(net, m, m.x, m.box.B0(), {});
    WetParams p;
    p.beta = 2;
    const double c = std::cos(70 * M_PI / 180), s = std::sin(70 * M_PI / 180);
    const Drag d = drag(e, q, bridges, 1, 0.01 * c, 0.01 * s, 150, p);
    CHECK(d.events.moves >= 1);
    for (double E : d.E) CHECK(E == Approx(d.E.front()).epsilon(1e-12));
}

TEST_CASE("active set: a bridge sliding off a fiber end fades out and ruptures", "[wet][events]") {
    // Fiber 2 crosses fiber 1 at x = 10.5, then is dragged to x = 9.5, past fiber 1's start at x = 10.
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.05, 1.5, 60, 1, 0.45}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    std::vector<Bridge> bridges = wet_crossings(net, m, m.x, m.box.B0(), {});
    REQUIRE(bridges.size() == 1);
    WetParams p;
    p.beta = 1;
    const Drag d = drag(e, e.dofs(m.x), bridges, 1, -0.005, 0, 200, p);
    CHECK(d.events.ruptures == 1);
    CHECK(bridges.empty());
    CHECK(d.max_switch < 1e-12);   // the bridge's weight was zero when it ruptured
    CHECK(d.E.front() == Approx(-0.25));
    CHECK(d.E[100] == Approx(-0.125));  // crossing at the fiber end: half the weight
    CHECK(d.max_step < 0.02 * 0.25);
}

TEST_CASE("active set: the segment crossing search finds exactly the brute-force crossings", "[wet][events]") {
    // Every pair of segments of different fibers, at every periodic image -1..1, against the cell search; dense and
    // sparse networks (the sparse one, 800 fibers in a box of 40 fiber lengths, where the cell grid is capped at ~4 cells per
    // segment), periodic sheared and open.
    struct Case {
        double L, q;
        bool periodic;
    };
    for (const Case& c : {Case{4, 6, true}, Case{4, 6, false}, Case{40, 0.5, true}, Case{40, 0.5, false}}) {
        MikadoParams mp;
        mp.L = c.L, mp.q = c.q, mp.pl = 0.5, mp.seed = 3, mp.periodic = c.periodic;
        const Model m = model_of(generate_mikado(mp), 10);
        NetworkEnergy e(m);
        Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
        if (c.periodic) F(0, 1) = 0.2;
        const Eigen::Matrix2d B = F * m.box.B0();
        const Eigen::VectorXd x = e.positions(perturb(e.affine_map(e.dofs(m.x), I2, F), 0.3, 5), F);
        std::vector<int> fiber(m.segments.size()), pos(m.segments.size());
        for (size_t f = 0; f < m.chains.size(); ++f)
            for (size_t k = 0; k < m.chains[f].segments.size(); ++k)
                fiber[m.chains[f].segments[k]] = static_cast<int>(f), pos[m.chains[f].segments[k]] = static_cast<int>(k);
        std::set<std::array<int, 4>> brute, found;
        for (size_t a = 0; a < m.segments.size(); ++a)
            for (size_t b = a + 1; b < m.segments.size(); ++b) {
                const Segment &sa = m.segments[a], &sb = m.segments[b];
                // A crosslink's segments meet at its shared node: a pin, not a crossing for a bridge.
                if (fiber[a] == fiber[b] || sa.i == sb.i || sa.i == sb.j || sa.j == sb.i || sa.j == sb.j) continue;
                const Eigen::Vector2d Pa = x.segment<2>(2 * sa.i), Pb = x.segment<2>(2 * sb.i);
                const Eigen::Vector2d Da = x.segment<2>(2 * sa.j) - Pa + B * sa.shift.cast<double>();
                const Eigen::Vector2d Db = x.segment<2>(2 * sb.j) - Pb + B * sb.shift.cast<double>();
                const int r = c.periodic ? 1 : 0;
                for (int i = -r; i <= r; ++i)
                    for (int j = -r; j <= r; ++j) {
                        const Eigen::Vector2d Q = Pb + B * Eigen::Vector2d(i, j);
                        const double den = Da.x() * Db.y() - Da.y() * Db.x();
                        if (den == 0) continue;
                        const Eigen::Vector2d w = Q - Pa;
                        const double t = (w.x() * Db.y() - w.y() * Db.x()) / den, u = (w.x() * Da.y() - w.y() * Da.x()) / den;
                        if (t >= 0 && t < 1 && u >= 0 && u < 1) {
                            std::array<int, 4> k{fiber[a], pos[a], fiber[b], pos[b]};
                            if (k[0] > k[2]) std::swap(k[0], k[2]), std::swap(k[1], k[3]);
                            brute.insert(k);
                        }
                    }
            }
        for (const Bridge& br : segment_crossings(m, x, B)) {
            std::array<int, 4> k{br.f1, br.k1, br.f2, br.k2};
            if (k[0] > k[2]) std::swap(k[0], k[2]), std::swap(k[1], k[3]);
            found.insert(k);
        }
        INFO("L " << c.L << ", q " << c.q << (c.periodic ? ", periodic" : ", open") << ": " << brute.size()
                  << " brute-force crossings");
        std::ostringstream diff;
        for (const auto& k : brute)
            if (!found.count(k)) diff << " missed " << k[0] << "/" << k[1] << "-" << k[2] << "/" << k[3];
        for (const auto& k : found)
            if (!brute.count(k)) diff << " extra " << k[0] << "/" << k[1] << "-" << k[2] << "/" << k[3];
        INFO(diff.str());
        CHECK(brute.size() > 10);
        CHECK(found == brute);
    }
}

TEST_CASE("active set: a new crossing gets a bridge", "[wet][events]") {
    // Fiber 3 (parallel to fiber 2) ends short of fiber 1 until it is dragged across it.
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.5, 1.5, 60, 1, 0.45}, {1.5, 1.2, 90, 1, 1.0}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    std::vector<Bridge> bridges = wet_crossings(net, m, m.x, m.box.B0(), {});
    REQUIRE(bridges.size() == 1);
    const Eigen::VectorXd q = moved(e, e.dofs(m.x), 2, 0.3, 3.5);
    const WetEvents ev = update_bridges(e, q, I2, bridges);
    CHECK(ev.formed == 1);
    REQUIRE(bridges.size() == 2);
    const Bridge& b = bridges[1];
    CHECK(b.f1 == 0);
    CHECK(b.f2 == 2);
    const BridgeElement el = resolve(m, b);
    const CrossingPosition cp = crossing_position(el, element_coordinates(el, e.positions(q, I2), m.box.B0()));
    CHECK(cp.inside(0));
    CHECK(cp.inside(1));
}

TEST_CASE("active set: zipped fibers hold one bridge per segment pair, adhesion -beta per unit overlap", "[wet][bundle]") {
    // Two parallel fibers 0.05 apart (in contact: fiber diameter 2/a = 0.2), fiber 2 shifted along by `offset`.
    for (int nseg : {10, 20, 40})
        for (double offset : {0.33, 0.5, 0.71}) {
            const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.5 + offset, 1.505, 0, 1, 0.5}}, 3);
            const Model m = model_of(net, nseg);
            NetworkEnergy e(m);
            std::vector<Bridge> bridges;
            const WetEvents ev = update_bridges(e, e.dofs(m.x), I2, bridges);
            WetParams p;
            p.beta = 3;
            const double overlap = 10 * (1 - offset);
            const double E = capillary(e, e.dofs(m.x), bridges, p);
            INFO("n_seg " << nseg << ", offset " << offset << ": " << bridges.size() << " bridges, E / (beta overlap) = "
                          << E / (p.beta * overlap));
            CHECK(ev.formed == static_cast<int>(bridges.size()));
            CHECK(std::abs(E / (-p.beta * overlap) - 1) < 0.05);
        }
}

namespace {
// The most other fibers any one segment holds bridges with.
int max_partners(const std::vector<Bridge>& bridges) {
    std::map<std::pair<int, int>, std::set<int>> along;
    for (const Bridge& b : bridges) along[{b.f1, b.k1}].insert(b.f2), along[{b.f2, b.k2}].insert(b.f1);
    size_t most = 0;
    for (const auto& [seg, fibers] : along) most = std::max(most, fibers.size());
    return static_cast<int>(most);
}
int bridges_with(const std::vector<Bridge>& bridges, int f) {
    return static_cast<int>(std::count_if(bridges.begin(), bridges.end(), [&](const Bridge& b) { return b.f1 == f || b.f2 == f; }));
}
}  // namespace

TEST_CASE("active set: the bundle-partner cap bounds how many fibers a segment adheres along", "[wet][bundle]") {
    // Four parallel fibers 0.05 seed units apart (all within the fiber diameter 0.2 of each other), shifted along x
    // so no two ends coincide: without a cap every segment zips with all three others (2D stacking).
    std::vector<Line> stack;
    for (int i = 0; i < 4; ++i) stack.push_back({1.5 + 0.03 * i, 1.5 + 0.005 * i, 0, 1, 0.5});
    // The bridges that form on `lines`; with `late` the last fiber first lies 5 seed units away and arrives after
    // the others have zipped.
    auto run = [&](const std::vector<Line>& lines, int cap, WetEvents* events = nullptr, bool late = false) {
        const Network net = network_of(lines, 3);
        const Model m = model_of(net);
        NetworkEnergy e(m);
        std::vector<Bridge> bridges;
        ActiveSetOptions opt;
        opt.bundle_partners = cap;
        const Eigen::VectorXd q = e.dofs(m.x);
        if (late) update_bridges(e, moved(e, q, static_cast<int>(lines.size()) - 1, 0, 5), I2, bridges, opt);
        const WetEvents ev = update_bridges(e, q, I2, bridges, opt);
        if (events) *events = ev;
        return bridges;
    };
    WetEvents ev;
    const std::vector<Bridge> free = run(stack, 0, &ev);
    CHECK(max_partners(free) == 3);
    CHECK(ev.capped == 0);
    for (int cap : {1, 2}) {
        INFO("cap " << cap);
        const std::vector<Bridge> b = run(stack, cap, &ev);
        CHECK(max_partners(b) == cap);
        CHECK(ev.capped > 0);
        CHECK(ev.formed == static_cast<int>(b.size()));
        CHECK(b.size() < free.size());
    }
    CHECK(run(stack, 3).size() == free.size());  // a cap the stack does not reach changes nothing

    // A fifth fiber across the stack: at 5 deg (aligned: a crossing within the contact angle) it gets no bridge where
    // the cap is full; at 60 deg it crosses, and point crossings are not bundles: one bridge per stack fiber.
    for (double angle : {5.0, 60.0}) {
        INFO("crossing at " << angle << " deg");
        std::vector<Line> lines = stack;
        lines.push_back({1.55, 1.5075, angle, 1, 0.5});
        const std::vector<Bridge> uncapped = run(lines, 0, nullptr, true), capped = run(lines, 1, nullptr, true);
        CHECK(bridges_with(uncapped, 4) >= 4);
        if (angle < 10) CHECK(bridges_with(capped, 4) == 0);
        else CHECK(bridges_with(capped, 4) == bridges_with(uncapped, 4));
    }
}

namespace {
// A stand-in solver that plays a script of states and statuses (IterationLimit: a cut round), then alternates
// between the last two states, reporting convergence. With two states and no statuses it alternates from the start,
// so the bridge set it leaves behind alternates too, which the loop must report as cycling.
class Scripted : public Solver {
public:
    Scripted(std::vector<Eigen::VectorXd> q, std::vector<SolveStatus> st) : q_(std::move(q)), st_(std::move(st)) {}
    std::string name() const override { return "scripted"; }
    SolverOptions& options() override { return opt_; }
    SolverCapabilities capabilities() const override { return {}; }
    std::unique_ptr<Solver> clone() const override { return std::make_unique<Scripted>(*this); }
    SolveResult minimize(Objective&, Eigen::VectorXd& q) override {
        const size_t n = q_.size(), k = k_ < n ? k_ : n - 2 + (k_ - n) % 2;
        q = q_[k];
        SolveResult r;
        r.status = k_ < st_.size() ? st_[k_] : SolveStatus::Converged;
        r.grad_max = 0;
        ++k_;
        return r;
    }

private:
    std::vector<Eigen::VectorXd> q_;
    std::vector<SolveStatus> st_;
    size_t k_ = 0;
    SolverOptions opt_;
};
}  // namespace

TEST_CASE("active set: a bridge set that repeats is reported as cycling", "[wet][events]") {
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.45, 1.5, 60, 1, 0.45}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    const Eigen::VectorXd q0 = e.dofs(m.x);
    Scripted solver({moved(e, q0, 1, -2, 0), moved(e, q0, 1, -1, 0)}, {});  // crossing at x = 12.5, then 13.5
    WetParams p;
    p.beta = 1;
    Eigen::VectorXd q = q0;
    ActiveSetOptions opt;
    opt.form_new = false;
    opt.max_freezes = 0;  // report the first repeat
    const ActiveSetResult r = relax_wet(e, I2, p, wet_crossings(net, m, m.x, m.box.B0(), {}), solver, q, opt);
    CHECK(r.cycling);
    CHECK(!r.stable);
    CHECK(r.rounds == 3);
    CHECK(r.message.find("cycling") != std::string::npos);
    CHECK(r.message.find("fibers 0/1") != std::string::npos);  // names the toggling bridge
    CHECK(r.events.moves >= 3);
    CHECK(r.cycles_broken == 0);

    // The freeze budget grows with the set: one more per bridges_per_freeze bridges (here 1 per bridge).
    Scripted solver1({moved(e, q0, 1, -2, 0), moved(e, q0, 1, -1, 0)}, {});
    Eigen::VectorXd q1 = q0;
    opt.bridges_per_freeze = 1;
    const ActiveSetResult r1 = relax_wet(e, I2, p, wet_crossings(net, m, m.x, m.box.B0(), {}), solver1, q1, opt);
    CHECK(r1.cycles_broken == 1);
    CHECK(r1.cycling);

    // By default the repeat is broken by freezing the pair's bridge; this stand-in solver still never reaches an
    // equilibrium (it alternates whatever the energy), so the loop ends cycling after the frozen round repeats.
    Scripted solver2({moved(e, q0, 1, -2, 0), moved(e, q0, 1, -1, 0)}, {});
    Eigen::VectorXd q2 = q0;
    ActiveSetOptions opt2;
    opt2.form_new = false;
    const ActiveSetResult r2 = relax_wet(e, I2, p, wet_crossings(net, m, m.x, m.box.B0(), {}), solver2, q2, opt2);
    CHECK(r2.cycles_broken == 1);
    CHECK(r2.frozen_pairs == 1);
    CHECK(r2.cycling);
    CHECK(!r2.stable);
    CHECK(r2.rounds < opt2.max_rounds);

    // A cycle broken in the last allowed round still ends with a message saying the rounds ran out.
    Scripted solver3({moved(e, q0, 1, -2, 0), moved(e, q0, 1, -1, 0)}, {});
    Eigen::VectorXd q3 = q0;
    ActiveSetOptions opt3;
    opt3.form_new = false;
    opt3.max_rounds = 3;  // the repeat is found (and broken) in round 3
    const ActiveSetResult r3 = relax_wet(e, I2, p, wet_crossings(net, m, m.x, m.box.B0(), {}), solver3, q3, opt3);
    CHECK(r3.cycles_broken == 1);
    CHECK(!r3.stable);
    CHECK(r3.message == "no stable bridge set after 3 rounds (3 global; last solve: converged)");
}

TEST_CASE("active set: a cycle after cut rounds that changed nothing is named and broken", "[wet][events]") {
    // A, A (two cut rounds, the second leaving the set as it was), B, A (finished): the set after the last round
    // repeats an earlier one. The toggling bridge must be named from what changed, not from two identical recorded
    // sets (which named nothing and made the cycle final at once).
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.45, 1.5, 60, 1, 0.45}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    const Eigen::VectorXd q0 = e.dofs(m.x), A = moved(e, q0, 1, -2, 0), B = moved(e, q0, 1, -1, 0);
    using S = SolveStatus;
    Scripted solver({A, A, B, A, B}, {S::IterationLimit, S::IterationLimit, S::Converged, S::Converged});
    WetParams p;
    p.beta = 1;
    Eigen::VectorXd q = q0;
    ActiveSetOptions opt;
    opt.form_new = false;
    opt.round_iterations = 5;
    const ActiveSetResult r = relax_wet(e, I2, p, wet_crossings(net, m, m.x, m.box.B0(), {}), solver, q, opt);
    INFO(r.message);
    CHECK(r.cycles_broken == 1);
    CHECK(r.frozen_pairs == 1);
}

TEST_CASE("active set: bridges of a frozen fiber pair are kept as they are", "[wet][events]") {
    // How relax_wet breaks a cycle (active_set.hpp). On the benchmark networks (bench/run_wet_seeds.sh) the frozen
    // runs end stable; here: the update leaves a frozen pair's bridge where it is.
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.45, 1.5, 60, 1, 0.45}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    Eigen::VectorXd q = e.dofs(m.x);
    std::vector<Bridge> bridges = wet_crossings(net, m, m.x, m.box.B0(), {});
    REQUIRE(bridges.size() == 1);
    const FiberPairs frozen{{0, 1}};
    // Dragged far past the node, a frozen bridge stays where it is; an unfrozen one moves.
    std::vector<Bridge> kept = bridges, free = bridges;
    ActiveSetOptions opt;
    opt.form_new = false;
    const Eigen::VectorXd far = moved(e, q, 1, 0.6, 0);
    CHECK(update_bridges(e, far, I2, kept, opt, &frozen).moves == 0);
    CHECK(kept[0].k1 == bridges[0].k1);
    CHECK(update_bridges(e, far, I2, free, opt).moves >= 1);
}

TEST_CASE("active set: a nearly parallel pair out of contact ruptures only at an equilibrium", "[wet][events]") {
    // Fibers at 3 deg, 0.5 seed units apart at their middles (contact: 2/a = 0.2), lines crossing beyond both ends. A
    // cut round leaves such pairs mid-motion (being pulled parallel): rupturing them there made them cross, re-form
    // and rupture again round after round; only a settled state (an equilibrium of the set) ruptures them.
    const Network net = network_of({{1.5, 1.5, 0, 1, 0.5}, {1.5, 1.55, 3, 1, 0.5}}, 3);
    const Model m = model_of(net);
    NetworkEnergy e(m);
    Bridge b;
    b.f1 = 0, b.f2 = 1, b.k1 = 5, b.k2 = 5;
    for (bool settled : {false, true}) {
        std::vector<Bridge> bridges{b};
        const WetEvents ev = update_bridges(e, e.dofs(m.x), I2, bridges, ActiveSetOptions{}, nullptr, settled);
        INFO("settled " << settled);
        CHECK(ev.ruptures == (settled ? 1 : 0));
        CHECK(bridges.size() == (settled ? 0u : 1u));
        CHECK(ev.formed == 0);
    }
}

TEST_CASE("active set: a cycle of cut global rounds with quiet local rounds between them is found and broken",
          "[wet][events][slow]") {
    // On this network a bridge ruptured and re-formed on alternate global rounds, each cut at round_iterations, with a
    // local round between them that changed nothing. The quiet local round reset the next global round's cap, so no
    // global round was solved to the end and the repeat was never judged: the loop ran until its round limit
    // (1300+ rounds) and ended not stable. Now the set that toggled back keeps its global round uncapped, the repeat
    // is found after that finished solve, and the toggling pair is frozen (1000 fibers: about 9 s).
    const Network net = mikado(10, 10, 0.8, 4);
    const Model m = model_of(net, 10);
    WetRunOptions opt;
    opt.params.beta = 0.1;
    opt.moduli = false;
    opt.solver_options.tol = 1e-10;
    opt.solver_options.max_iter = 500;
    opt.active_set.max_rounds = 100;  // the run needs about 20 global rounds (79 in all); the old loop used up all 100
    const WetRun r = run_wet(net, m, Eigen::Matrix2d::Identity(), opt);
    INFO(r.active.message << " (" << r.active.rounds << " rounds, " << r.active.local_rounds << " local)");
    // Whether this run meets the toggling pair depends on its path (a cut round's state, to round-off); the
    // mechanism itself is pinned by the scripted cases above. What must hold on any CPU: the loop ends stable, well
    // before its round limit (the old loop ran 1300+).
    CHECK(r.active.stable);
    CHECK(r.active.rounds < 300);
}
