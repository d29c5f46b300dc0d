// The dry energy's assembly (issue 22: element terms, one assembler) against a committed reference: the energy, the
// stretch/bend split, the gradient, the Hessian's values and the strain derivatives, bit for bit as the hand-written
// loops computed them before the change, and bit for bit the same for any thread count.
//
// Bit for bit holds on any x86-64 machine for one compiler and its baseline (SSE2) code: the dry terms use no BLAS and
// no code chosen at run time, the build contracts no multiply-adds (-ffp-contract=off), and sqrt and division are
// correctly rounded. A build for wider vector units (-march with AVX) may let Eigen sum small products in another
// order: there the values are checked to 1e-13 instead. The reference was written by
// FIBERNET_WRITE_DRY_REFERENCE=1 build/test_energy "[assembly]" -s on the loops before the change (the commit that added this test).
#include <catch2/catch.hpp>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "fd.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/hash.hpp"
#include "fibernet/util/parallel.hpp"
#include "fibernet/util/random.hpp"

using namespace fibernet;

namespace {
Model reference_model(bool clamp) {
    MikadoParams p;
    p.L = 3.2, p.q = 3, p.pl = 0.7, p.seed = 3;
    DiscretizationParams d;
    d.scheme = Scheme::Seed, d.n_seg = 4, d.h = 3.0, d.aspect_ratio = 10;
    Model m = discretize(generate_mikado(p), d);
    if (clamp) {
        m.fixed.assign(m.num_nodes(), 0);
        for (int i = 0; i < m.num_nodes(); i += 5) m.fixed[i] = 1;
    }
    return m;
}

// A perturbed state with one segment (no box image) compressed to 3 % of its length: the softcore regime.
Eigen::VectorXd reference_state(const NetworkEnergy& e, const Eigen::Matrix2d& F) {
    Rng rng(11);
    Eigen::VectorXd q = e.dofs(e.model().x);
    for (int i = 0; i < q.size(); ++i) q[i] += 0.2 * (2 * rng.uniform() - 1);
    Eigen::VectorXd x = e.positions(q, F);
    for (const Segment& s : e.model().segments) {
        if (!s.shift.isZero() || e.dof(s.i, 0) < 0 || e.dof(s.j, 0) < 0) continue;
        x.segment<2>(2 * s.j) = x.segment<2>(2 * s.i) + 0.03 * (x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i));
        break;
    }
    return e.dofs(x);
}

std::uint64_t fold(std::uint64_t h, double v) {
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    return fnv1a(fnv1a(h, static_cast<std::uint32_t>(bits)), static_cast<std::uint32_t>(bits >> 32));
}

struct Fingerprint {
    std::uint64_t hash = kFnvOffset;
    double energy = 0;
};

Fingerprint evaluate(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                     const Eigen::Matrix2d& dF, unsigned want) {
    EnergyEval ev;
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    e.evaluate(q, F, dF, want, ev, (want & kHessian) ? &H : nullptr);
    Fingerprint f;
    f.energy = ev.energy;
    for (double v : {ev.energy, ev.stretch, ev.bend, ev.dE_dt, ev.d2E_dt2, ev.d2E_dt2_size}) f.hash = fold(f.hash, v);
    for (Eigen::Index i = 0; i < ev.gradient.size(); ++i) f.hash = fold(f.hash, ev.gradient[i]);
    for (Eigen::Index i = 0; i < ev.d2E_dqdt.size(); ++i) f.hash = fold(f.hash, ev.d2E_dqdt[i]);
    if (want & kHessian)
        for (Eigen::Index i = 0; i < H.nonZeros(); ++i) f.hash = fold(f.hash, H.valuePtr()[i]);
    return f;
}

struct Case {
    const char* name;
    bool clamp;
    unsigned want;
    std::uint64_t hash;
    const char* energy;  // hex float
};

// Value, gradient, Hessian (into H, on the energy's pattern) and strain derivatives at once.
EnergyEval evaluate_all(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                        const Eigen::Matrix2d& dF, Eigen::SparseMatrix<double>& H) {
    EnergyEval ev;
    H = e.hessian_pattern();
    e.evaluate(q, F, dF, kGradient | kHessian | kStrain, ev, &H);
    return ev;
}
}  // namespace

TEST_CASE("element assembly: the dry energy is bit for bit the committed reference", "[energy][assembly]") {
    const Case cases[] = {
        {"periodic, sheared, softcore: value, gradient, Hessian, strain", false, kGradient | kHessian | kStrain,
         0x6feb3aef1e74fa87ull, "0x1.60f7e029ab12bp+16"},
        {"comoving strain", false, kGradient | kStrain | kComoving, 0xedbeb14066a863d6ull, "0x1.60f7e029ab12bp+16"},
        {"PSD-projected Hessian", false, kGradient | kHessian | kProjectPSD, 0x6a0eeffc5ef6927aull, "0x1.60f7e029ab12bp+16"},
        {"clamped nodes, general F: all", true, kGradient | kHessian | kStrain, 0x57655fc49585c8ccull, "0x1.b303827fbc4fcp+21"},
        {"value only", false, kValue, 0x0fcdf7c3d84ddcb6ull, "0x1.60f7e029ab12bp+16"},
    };
    Eigen::Matrix2d F, dF;
    const bool write = std::getenv("FIBERNET_WRITE_DRY_REFERENCE") != nullptr;
    for (const Case& c : cases) {
        const Model m = reference_model(c.clamp);
        if (c.clamp) F << 1.05, 0.2, -0.1, 0.95, dF << 0.3, 1, -0.4, 0.2;
        else F << 1, 0.3, 0, 1, dF << 0, 1, 0, 0;
        const NetworkEnergy e(m);
        const Eigen::VectorXd q = reference_state(e, F);
        for (int threads : {1, 2, 3}) {
            set_thread_count(threads);
            const Fingerprint f = evaluate(e, q, F, dF, c.want);
            INFO(c.name << ", threads " << threads);
            if (write) {
                if (threads == 1) std::printf("        {\"%s\", ..., 0x%016" PRIx64 "ull, \"%a\"},\n", c.name, f.hash, f.energy);
                continue;
            }
#if defined(__AVX__)
            CHECK(f.energy == Approx(std::strtod(c.energy, nullptr)).epsilon(1e-13));
#else
            CHECK(f.energy == std::strtod(c.energy, nullptr));
            CHECK(f.hash == c.hash);
#endif
        }
    }
    set_thread_count(0);
}

TEST_CASE("element assembly: parallel assembly is bit for bit the serial one", "[energy][assembly]") {
    // Large enough (> 4096 elements) for the threads to split the elements and the gathers; the reference above is
    // assembled by one thread.
    MikadoParams p;
    p.L = 12, p.q = 5, p.pl = 0.6, p.seed = 4;
    DiscretizationParams d;
    d.scheme = Scheme::Seed, d.n_seg = 4, d.h = 3.0, d.aspect_ratio = 10;
    const Model m = discretize(generate_mikado(p), d);
    REQUIRE(m.segments.size() + m.hinges.size() > 4096);
    const NetworkEnergy e(m);
    Eigen::Matrix2d F, dF;
    F << 1, 0.1, 0, 1, dF << 0, 1, 0, 0;
    const Eigen::VectorXd q = reference_state(e, F);
    for (unsigned want : {unsigned(kGradient | kHessian | kStrain), unsigned(kGradient | kStrain | kComoving), 0u}) {
        set_thread_count(1);
        const Fingerprint serial = evaluate(e, q, F, dF, want);
        for (int threads : {2, 3, 5}) {
            set_thread_count(threads);
            const Fingerprint f = evaluate(e, q, F, dF, want);
            INFO("want " << want << ", threads " << threads);
            CHECK(f.hash == serial.hash);
            CHECK(f.energy == serial.energy);
        }
    }
    set_thread_count(0);
}

TEST_CASE("element assembly: a term with no elements (fibers of one segment, no hinges)", "[energy][assembly]") {
    // Two fibers that do not cross, one segment each: the bending term has no element, and its index arrays end
    // where the stretching term's end (or are empty). The sum is the stretching energy alone, with its derivatives.
    Network net;
    net.L = 3, net.periodic = true;
    Fiber a, b;
    a.start = {0.2, 0.5}, a.theta = 0.3;
    b.start = {0.4, 2.0}, b.theta = 2.0;
    net.fibers = {a, b};
    DiscretizationParams d;
    d.scheme = Scheme::Seed, d.n_seg = 1, d.aspect_ratio = 10;
    const Model m = discretize(net, d);
    REQUIRE(m.hinges.empty());
    REQUIRE(m.segments.size() == 2);
    const NetworkEnergy e(m);
    Eigen::Matrix2d F, dF;
    F << 1.02, 0.1, 0, 0.97, dF << 0, 1, 0, 0;
    Eigen::VectorXd q = e.dofs(e.model().x);
    Rng rng(5);
    for (int i = 0; i < q.size(); ++i) q[i] += 0.3 * (2 * rng.uniform() - 1);
    for (int threads : {1, 2}) {
        set_thread_count(threads);
        Eigen::SparseMatrix<double> H;
        const EnergyEval ev = evaluate_all(e, q, F, dF, H);
        INFO("threads " << threads);
        CHECK(ev.bend == 0);
        CHECK(ev.stretch > 0);
        CHECK(ev.energy == ev.stretch);
        const auto value = [&](const Eigen::VectorXd& x) {
            EnergyEval v;
            e.evaluate(x, F, dF, kValue, v, nullptr);
            return v.energy;
        };
        const Eigen::VectorXd g = fdtest::fd_gradient(value, q, 1e-6);
        CHECK((ev.gradient - g).cwiseAbs().maxCoeff() <= 1e-6 * g.cwiseAbs().maxCoeff());
        const auto gradient = [&](const Eigen::VectorXd& x) {
            EnergyEval v;
            e.evaluate(x, F, dF, kGradient, v, nullptr);
            return Eigen::VectorXd(v.gradient);
        };
        const Eigen::MatrixXd Hfd = fdtest::fd_jacobian(gradient, q, 1e-6);
        const Eigen::MatrixXd Hd = Eigen::MatrixXd(Eigen::MatrixXd(H).selfadjointView<Eigen::Upper>());
        CHECK((Hd - Hfd).cwiseAbs().maxCoeff() <= 1e-6 * Hfd.cwiseAbs().maxCoeff());
    }
    set_thread_count(0);
}

TEST_CASE("element assembly: a model with no elements at all (an empty network)", "[energy][assembly]") {
    // Every term empty: the assembler's index arrays hold nothing, and the sums are zero.
    Network net;
    net.L = 2, net.periodic = true;
    DiscretizationParams d;
    d.scheme = Scheme::Even, d.h = 1.0, d.aspect_ratio = 10;
    const Model m = discretize(net, d);
    REQUIRE(m.segments.empty());
    REQUIRE(m.hinges.empty());
    const NetworkEnergy e(m);
    Eigen::Matrix2d F, dF;
    F << 1, 0.1, 0, 1, dF << 0, 1, 0, 0;
    const Eigen::VectorXd q = e.dofs(e.model().x);
    REQUIRE(q.size() == 0);
    for (int threads : {1, 2}) {
        set_thread_count(threads);
        Eigen::SparseMatrix<double> H;
        const EnergyEval ev = evaluate_all(e, q, F, dF, H);
        INFO("threads " << threads);
        CHECK(ev.energy == 0);
        CHECK(ev.dE_dt == 0);
        CHECK(ev.gradient.size() == q.size());
        CHECK(H.nonZeros() == 0);
    }
    set_thread_count(0);
}
