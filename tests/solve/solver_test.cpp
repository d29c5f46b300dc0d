// Bad options throw InputError naming the bad value (LBFGSpp's check_param style).
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "fibernet/solve/cg.hpp"
#include "fibernet/solve/fire.hpp"
#include "fibernet/solve/ipopt_solver.hpp"
#include "fibernet/solve/lbfgs.hpp"
#include "fibernet/solve/line_search.hpp"
#include "fibernet/solve/nlopt_solver.hpp"
#include "fibernet/solve/solver_registry.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;
using Catch::Matchers::Contains;

TEST_CASE("bad SolverOptions are refused by every solver, naming the value", "[solve][options]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const auto& name : solver_names()) {
        INFO(name);
        SolverOptions o;
        o.tol = 0;
        CHECK_THROWS_WITH(make_solver(name, o), Contains(name) && Contains("tol = 0"));
        o.tol = nan;
        CHECK_THROWS_AS(make_solver(name, o), InputError);
        o = SolverOptions{};
        o.max_iter = 0;
        CHECK_THROWS_WITH(make_solver(name, o), Contains("max_iter = 0"));
        o = SolverOptions{};
        o.max_seconds = -1;
        CHECK_THROWS_WITH(make_solver(name, o), Contains("max_seconds = -1"));
        CHECK_NOTHROW(make_solver(name, SolverOptions{}));
    }
}

TEST_CASE("bad solver parameters are refused, naming the value", "[solve][options]") {
    const SolverOptions o;
    LbfgsParams lp;
    lp.m = 0;
    CHECK_THROWS_WITH(LbfgsSolver(o, lp), Contains("m = 0"));
    lp = {};
    lp.line_search.c2 = 1e-5;  // below c1
    CHECK_THROWS_WITH(LbfgsSolver(o, lp), Contains("line_search.c2 = 1.0000000000000001e-05"));
    lp = {};
    lp.shift = -1;
    CHECK_THROWS_WITH(LbfgsSolver(o, lp), Contains("shift = -1"));

    LineSearchParams ls;
    ls.c1 = 0.7;
    CHECK_THROWS_WITH(StrongWolfeLineSearch(ls), Contains("line_search.c1 = 0.69999999999999996"));
    ls = {};
    ls.max_evals = 1;
    CHECK_THROWS_AS(StrongWolfeLineSearch(ls), InputError);

    FireParams fp;
    fp.f_dec = 1.5;
    CHECK_THROWS_WITH(FireSolver(o, fp), Contains("f_dec = 1.5"));
    fp = {};
    fp.dt = -1;
    CHECK_THROWS_WITH(FireSolver(o, fp), Contains("dt = -1"));
    fp = {};
    fp.alpha0 = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(FireSolver(o, fp), Contains("alpha0 = inf"));

    CgParams cp;
    cp.restart_every = -2;
    CHECK_THROWS_WITH(CgSolver(o, cp), Contains("restart_every = -2"));
    cp = {};
    cp.line_search.c2 = 1;
    CHECK_THROWS_WITH(CgSolver(o, cp), Contains("line_search.c2 = 1"));

    NloptParams np;
    np.vector_storage = -1;
    CHECK_THROWS_WITH(NloptSolver(NloptMethod::Lbfgs, o, np), Contains("nlopt-lbfgs") && Contains("vector_storage = -1"));

    IpoptParams ip;
    ip.print_level = 13;
    CHECK_THROWS_WITH(IpoptSolver(o, ip), Contains("print_level = 13"));
    ip = {};
    ip.linear_solver = "magic";
    CHECK_THROWS_WITH(IpoptSolver(o, ip), Contains("linear_solver = magic"));
}
