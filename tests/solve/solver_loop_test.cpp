// The solver loop (solver_loop.hpp): the stop tests, the iteration and evaluation counts, the finish, and the fresh
// evaluation that decides a backend's status, with a scripted method on a quadratic whose state is known exactly.
#include <catch2/catch.hpp>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <limits>
#include <thread>
#include <vector>

#include "fibernet/solve/solver_loop.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
// f = 1/2 |x|^2 (g = x), with a Hessian pattern of its diagonal.
class Quadratic : public Objective {
public:
    explicit Quadratic(int n) : P_(n, n) {
        for (int i = 0; i < n; ++i) P_.insert(i, i) = 0;
        P_.makeCompressed();
    }
    int size() const override { return static_cast<int>(P_.rows()); }
    double value(const Eigen::VectorXd& q) override { return 0.5 * q.squaredNorm(); }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        g = q;
        return value(q);
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool) override {
        H = P_;
        for (int i = 0; i < size(); ++i) H.coeffRef(i, i) = 1;
        return gradient(q, g);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return P_; }

private:
    Eigen::SparseMatrix<double> P_;
};

// Halves q every iteration; every `idle`-th iteration does not move (Step::again); stops with `stop_status` at
// iteration `stop_at` (moved or not, as `stop_moves` says).
class Halving : public IterativeMethod {
public:
    int idle = 0, stop_at = -1;
    bool stop_moves = false;
    SolveStatus stop_status = SolveStatus::Stalled;
    int calls = 0;
    double sleep = 0;

    Step start(SolverRun& run, Eigen::VectorXd& q) override {
        e_ = run.objective().gradient(q, g_);
        return Step::again();
    }
    Step iterate(SolverRun& run, Eigen::VectorXd& q, int k) override {
        ++calls;
        if (sleep > 0) std::this_thread::sleep_for(std::chrono::duration<double>(sleep));
        if (k == stop_at && !stop_moves) return Step::stop(stop_status, "scripted stop");
        if (idle > 0 && calls % idle == 0) return Step::again();
        q *= 0.5;
        e_ = run.objective().gradient(q, g_);
        if (k == stop_at) return Step::stop(stop_status, "scripted stop after a move", true);
        return Step::moved();
    }
    double energy() const override { return e_; }
    double grad_max() const override { return g_.lpNorm<Eigen::Infinity>(); }
    void complete(SolveResult& r, const Step& last, const Eigen::VectorXd&) override {
        completed = last.done;
        r.local_solves = 7;  // a method's own field, kept by the finish
    }
    bool completed = false;

private:
    double e_ = 0;
    Eigen::VectorXd g_;
};
}  // namespace

TEST_CASE("solver loop: converges at max|g| <= tol, counting only the iterations that moved", "[solve][loop]") {
    Quadratic f(3);
    SolverOptions o;
    o.tol = 1e-3;
    Halving m;
    m.idle = 3;  // every third call does not move
    Eigen::VectorXd q = Eigen::VectorXd::Constant(3, 1.0);
    SolverRun run("halving", o, f, q);
    const SolveResult r = run_iterations(run, m, q);
    CHECK(r.status == SolveStatus::Converged);
    CHECK(r.solver == "halving");
    // 1 -> 2^-10 < 1e-3 takes 10 moves; the idle calls are not iterations.
    CHECK(r.iterations == 10);
    CHECK(m.calls == 14);  // calls 3, 6, 9 and 12 were idle
    CHECK(q[0] == std::ldexp(1.0, -10));
    CHECK(r.grad_max == std::ldexp(1.0, -10));
    CHECK(r.energy == 1.5 * std::ldexp(1.0, -20));
    CHECK(r.evaluations == 1 + 10);  // the start and one per move, counted by the run's objective
    CHECK(m.completed);
    CHECK(r.local_solves == 7);
    CHECK(r.timings.total >= 0);
}

TEST_CASE("solver loop: observe sees each accepted iterate, the last one the returned state", "[solve][loop]") {
    Quadratic f(2);
    SolverOptions o;
    o.tol = 1e-3;
    std::vector<double> seen_q, seen_e, seen_g;
    o.observe = [&](const Eigen::VectorXd& q, double e, double g) {
        seen_q.push_back(q[0]), seen_e.push_back(e), seen_g.push_back(g);
    };
    Halving m;
    m.idle = 3;  // idle calls are not iterates
    Eigen::VectorXd q = Eigen::VectorXd::Constant(2, 1.0);
    SolverRun run("halving", o, f, q);
    const SolveResult r = run_iterations(run, m, q);
    REQUIRE(r.status == SolveStatus::Converged);
    REQUIRE(static_cast<int>(seen_q.size()) == r.iterations);
    for (size_t k = 0; k < seen_q.size(); ++k) {
        CHECK(seen_q[k] == std::ldexp(1.0, -static_cast<int>(k) - 1));
        CHECK(seen_e[k] == seen_q[k] * seen_q[k]);  // 1/2 |q|^2 with two equal entries
        CHECK(seen_g[k] == seen_q[k]);
    }
    CHECK(seen_q.back() == q[0]);
    CHECK(seen_e.back() == r.energy);
}

namespace {
// What `body` writes to stderr (fd 2), through a temporary file.
template <class Body>
std::string stderr_of(Body body) {
    std::fflush(stderr);
    std::FILE* tmp = std::tmpfile();
    const int saved = dup(2);
    dup2(fileno(tmp), 2);
    body();
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
    std::rewind(tmp);
    std::string out;
    for (int c; (c = std::fgetc(tmp)) != EOF;) out += static_cast<char>(c);
    std::fclose(tmp);
    return out;
}
}  // namespace

TEST_CASE("solver loop: progress within the local solves, at most once a second, with what is left", "[solve][loop]") {
    Quadratic f(2);
    SolverOptions o;
    o.progress = true;
    const Eigen::VectorXd q = Eigen::VectorXd::Constant(2, 1.0);
    SolverRun run("newton", o, f, q);
    // Before the first second: nothing (the line is rate-limited from the solve's start).
    CHECK(stderr_of([&] { run.tick_within(3, 2, 10, 0.5); }).empty());
    std::this_thread::sleep_for(std::chrono::milliseconds(1050));
    // 4 of 10 solved in 2 s: about 3 s more.
    const std::string line = stderr_of([&] { run.tick_within(3, 4, 10, 2.0); });
    CHECK(line.rfind("newton: it 3  local solves 4 of 10  t 1.", 0) == 0);
    CHECK(line.find("(about 3 s more for them)\n") != std::string::npos);
    CHECK(stderr_of([&] { run.tick_within(3, 5, 10, 2.5); }).empty());  // within the same second
    // Neither verbose nor progress: silent.
    SolverOptions quiet;
    SolverRun silent("newton", quiet, f, q);
    std::this_thread::sleep_for(std::chrono::milliseconds(1050));
    CHECK(stderr_of([&] { silent.tick_within(0, 1, 2, 1.0); }).empty());
}

TEST_CASE("solver loop: the iteration budget and the time budget end a solve, named", "[solve][loop]") {
    Quadratic f(2);
    SolverOptions o;
    o.tol = 1e-12;
    o.max_iter = 5;
    Halving m;
    Eigen::VectorXd q = Eigen::VectorXd::Ones(2);
    SolverRun run("halving", o, f, q);
    SolveResult r = run_iterations(run, m, q);
    CHECK(r.status == SolveStatus::IterationLimit);
    CHECK(r.iterations == 5);
    CHECK(r.message.find("iteration limit 5") != std::string::npos);
    CHECK(!r.converged());

    o.max_iter = 1000000, o.max_seconds = 0.05;
    Halving slow;
    slow.sleep = 0.02;
    q = Eigen::VectorXd::Ones(2);
    SolverRun timed("halving", o, f, q);
    r = run_iterations(timed, slow, q);
    CHECK(r.status == SolveStatus::IterationLimit);
    CHECK(r.message == "time limit reached");
    CHECK(r.iterations >= 1);
    CHECK(r.iterations < 1000);
    CHECK(r.timings.total >= 0.05);
}

TEST_CASE("solver loop: a method's stop ends the solve, counting the move it made", "[solve][loop]") {
    Quadratic f(2);
    SolverOptions o;
    o.tol = 1e-12;
    for (bool moves : {false, true}) {
        Halving m;
        m.stop_at = 4, m.stop_moves = moves;
        Eigen::VectorXd q = Eigen::VectorXd::Ones(2);
        SolverRun run("halving", o, f, q);
        const SolveResult r = run_iterations(run, m, q);
        CHECK(r.status == SolveStatus::Stalled);
        CHECK(r.iterations == (moves ? 5 : 4));
        CHECK(q[0] == std::ldexp(1.0, moves ? -5 : -4));
    }
}

TEST_CASE("solver loop: a start of the wrong size is refused, naming both sizes", "[solve][loop]") {
    Quadratic f(3);
    const Eigen::VectorXd q = Eigen::VectorXd::Ones(2);
    CHECK_THROWS_AS(SolverRun("halving", SolverOptions{}, f, q), InputError);
    CHECK_THROWS_WITH(SolverRun("halving", SolverOptions{}, f, q),
                      Catch::Matchers::Contains("2 entries") && Catch::Matchers::Contains("3"));
}

TEST_CASE("solver loop: finish_verified decides the status from the returned state", "[solve][loop]") {
    Quadratic f(2);
    SolverOptions o;
    o.tol = 1e-6;
    Eigen::VectorXd q = Eigen::VectorXd::Constant(2, 1e-3);  // max|g| = 1e-3 > tol
    {
        SolverRun run("backend", o, f, q);
        const SolveResult r = run.finish_verified(SolveStatus::Converged, "backend says so", q, SolveStatus::Stalled);
        CHECK(r.status == SolveStatus::Stalled);  // a claim above tol is not taken
        CHECK(r.grad_max == 1e-3);
        CHECK(r.evaluations == 1);
    }
    q.setConstant(1e-8);
    {
        SolverRun run("backend", o, f, q);
        const SolveResult r = run.finish_verified(SolveStatus::Failed, "backend gave up", q, SolveStatus::Stalled);
        CHECK(r.status == SolveStatus::Converged);  // the state is an equilibrium whatever the backend said
    }
    q[0] = std::numeric_limits<double>::quiet_NaN();
    {
        SolverRun run("backend", o, f, q);
        const SolveResult r = run.finish_verified(SolveStatus::Converged, "backend says so", q, SolveStatus::Stalled);
        CHECK(r.status == SolveStatus::NonFinite);
    }
}

TEST_CASE("solver loop: the counted objective forwards the restriction uncounted", "[solve][loop]") {
    Quadratic f(2);
    CountedObjective c(f);
    Eigen::VectorXd q = Eigen::VectorXd::Ones(2), g;
    c.value(q), c.gradient(q, g);
    Eigen::SparseMatrix<double> H = c.hessian_pattern();
    c.hessian(q, g, H, false);
    CHECK(c.evaluations == 3);
    CHECK(c.restriction(q, {0}) == nullptr);  // Quadratic offers none
    CHECK(c.evaluations == 3);
}
