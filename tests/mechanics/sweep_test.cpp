#include <catch2/catch.hpp>
#include <atomic>
#include <cmath>
#include <cstdint>

#include "fibernet/mechanics/sweep.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
Model sweep_model(double q = 7, double a = 10, double L = 3, std::uint64_t seed = 4, double h = 2.5) {
    MikadoParams mp;
    mp.L = L, mp.q = q, mp.pl = 1, mp.seed = seed;
    DiscretizationParams d;
    d.scheme = Scheme::Even, d.h = h, d.aspect_ratio = a;
    return discretize(generate_mikado(mp), d);
}

std::vector<SweepRow> sweep_rows(const NetworkEnergy& e, const SweepParams& p, SweepOutcome* out = nullptr,
                                 int stop_after = -1, const SweepState* resume = nullptr, SweepState* last = nullptr,
                                 int max_iter = 500, int snap_iter = 0) {
    SolverOptions so;
    so.max_iter = max_iter;
    auto solver = make_solver("newton", so);
    so.max_iter = snap_iter;
    auto snap = snap_iter > 0 ? make_solver("newton", so) : nullptr;  // max_iter = 0 is refused
    std::vector<SweepRow> rows;
    std::atomic<bool> stop{false};
    SweepCallbacks cb;
    cb.stop = &stop;
    cb.on_step = [&](const SweepRow& r, const SweepState& s) {
        rows.push_back(r);
        if (last) *last = s;
        if (r.step == stop_after) stop = true;
    };
    SweepOutcome o = run_sweep(e, p, *solver, cb, resume, snap.get());
    if (out) *out = o;
    return rows;
}
}  // namespace

TEST_CASE("sweep: the differential modulus K matches finite differences of the stress", "[mechanics][sweep]") {
    Model m = sweep_model();
    NetworkEnergy e(m);
    SweepParams p;
    p.t_max = 0.3, p.step = p.min_step = p.max_step = 1e-3;  // fixed step for central differences
    p.t_max = 0.012;
    SweepOutcome o;
    const auto rows = sweep_rows(e, p, &o);
    REQUIRE(o.completed);
    REQUIRE(rows.size() == 13);
    for (size_t n = 1; n + 1 < rows.size(); ++n) {
        const double fd = (rows[n + 1].stress_path - rows[n - 1].stress_path) / (rows[n + 1].t - rows[n - 1].t);
        INFO("gamma = " << rows[n].t);
        CHECK(rows[n].K == Approx(fd).epsilon(1e-4));
        // For simple shear the path stress is sigma_xy.
        CHECK(rows[n].stress_path == Approx(rows[n].sigma(0, 1)).epsilon(1e-10));
    }
    CHECK(rows.back().K > 0);
}

TEST_CASE("sweep: a resumed sweep matches an uninterrupted one exactly", "[mechanics][sweep]") {
    Model m = sweep_model();
    NetworkEnergy e(m);
    SweepParams p;
    p.t_max = 0.2, p.step = 0.01, p.max_step = 0.05;
    const auto full = sweep_rows(e, p);
    REQUIRE(full.size() > 4);
    SweepOutcome o;
    SweepState state;
    const auto first = sweep_rows(e, p, &o, 2, nullptr, &state);
    REQUIRE(o.interrupted);
    REQUIRE(first.size() == 3);
    const auto rest = sweep_rows(e, p, &o, -1, &state);
    REQUIRE(o.completed);
    REQUIRE(first.size() + rest.size() == full.size());
    for (size_t n = 0; n < full.size(); ++n) {
        const SweepRow& r = n < first.size() ? first[n] : rest[n - first.size()];
        CHECK(r.step == full[n].step);
        CHECK(r.t == full[n].t);
        CHECK(r.stress_path == full[n].stress_path);
        CHECK(r.K == full[n].K);
        CHECK(r.energy == full[n].energy);
    }
}

TEST_CASE("sweep: compression through buckling keeps every accepted step converged", "[mechanics][sweep]") {
    Model m = sweep_model(8, 30);
    NetworkEnergy e(m);
    SweepParams p;
    p.kind = StrainKind::UniaxialX;
    p.t_max = -0.08, p.step = 0.01, p.max_step = 0.02;
    SweepOutcome o;
    const auto rows = sweep_rows(e, p, &o);
    INFO(o.message);
    CHECK((o.completed || !o.message.empty()));
    REQUIRE(rows.size() > 2);
    // Newton accepts max|g| at its round-off floor (absolute coordinates, ~1e-9 here; docs/moduli.md); an
    // unconverged state would be orders of magnitude above.
    for (const auto& r : rows) CHECK(r.grad_max <= 1e-8);
    // Compressed fibers bend: the bending share of the energy grows along the sweep.
    CHECK(rows.back().bend > 0);
}

TEST_CASE("sweep: a snap-through beyond the solver's budget is crossed with the snap budget", "[mechanics][sweep][slow]") {
    // Shear of a 4 x 4 network to 40%: fibers buckle in cascades; measured with `fibernet sweep --L 4 --q 8
    // --scheme even --gamma-max 0.5 --min-step 1e-3 --max-iter 20`, steps at the smallest size need 100s of iterations.
    Model m = sweep_model(8, 10, 4, 1, 1.0);
    NetworkEnergy e(m);
    SweepParams p;
    p.t_max = 0.4, p.step = 0.01, p.max_step = 0.05, p.min_step = 1e-3;
    SweepOutcome tight, snapped;
    const int budget = 20;
    sweep_rows(e, p, &tight, -1, nullptr, nullptr, budget);
    INFO(tight.message);
    CHECK(!tight.completed);  // some step needs more than `budget` Newton iterations even at the smallest step
    const auto rows = sweep_rows(e, p, &snapped, -1, nullptr, nullptr, budget, 100 * budget);
    INFO(snapped.message);
    CHECK(snapped.completed);
    int over = 0;
    for (const auto& r : rows) {
        CHECK(r.grad_max <= 1e-8);  // every accepted step converged
        over += r.iterations > budget;
    }
    CHECK(over > 0);  // and the snap budget was used
}

TEST_CASE("sweep: bad parameters name the value", "[mechanics][sweep][input]") {
    SweepParams p;
    p.t_max = 0;
    CHECK_THROWS_WITH(p.check("cli"), Catch::Contains("gamma_max = 0"));
    p = {};
    p.step = -1;
    CHECK_THROWS_WITH(p.check("cli"), Catch::Contains("step = -1"));
    p = {};
    p.min_step = 1;
    CHECK_THROWS_AS(p.check("cli"), InputError);
    // A compression that flips or collapses the box; shear has det F = 1 at any strain.
    p = {};
    p.kind = StrainKind::Isotropic, p.t_max = -1;
    CHECK_THROWS_WITH(p.check("cli"), Catch::Contains("gamma_max = -1 flips or collapses the box on the isotropic path"));
    p.t_max = -2;  // (1 + t)^2 > 0 there: det F alone would let the sweep run through the collapse at t = -1
    CHECK_THROWS_WITH(p.check("cli"), Catch::Contains("gamma_max = -2 flips or collapses"));
    p.kind = StrainKind::UniaxialY, p.t_max = -1.5;
    CHECK_THROWS_WITH(p.check("cli"), Catch::Contains("gamma_max = -1.5 flips or collapses"));
    p.kind = StrainKind::Shear;
    CHECK_NOTHROW(p.check("cli"));
}
