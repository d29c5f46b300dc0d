// Newton's ladder (newton_ladder.hpp): which rung gives the direction for a positive definite, an indefinite and a
// hopeless Hessian, from each starting level, and that every direction it returns is one of descent.
#include <catch2/catch.hpp>

#include "fibernet/solve/cholmod_ldl.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/newton_ladder.hpp"
#include "suite_fixtures.hpp"

using namespace fibernet;
using suite_test::Rosenbrock;

namespace {
struct Setup {
    Rosenbrock f{4};
    Eigen::VectorXd q, g;
    Eigen::SparseMatrix<double> H;
    bool projected = false;
    SolveResult r;
    CholmodLLT llt;
    CholmodLDL ldl;

    // At x the Rosenbrock Hessian is positive definite near the minimum and indefinite where x_{2i+1} > x_{2i}^2
    // + 1/200 (h00 = 1200 x^2 - 400 y + 2 < 0 on the valley's inside).
    explicit Setup(double x, double y) : q(f.size()) {
        for (int i = 0; i < f.size(); i += 2) q[i] = x, q[i + 1] = y;
        H = f.hessian_pattern();
        f.hessian(q, g, H, false);
    }
    LadderState state(double mu) { return LadderState{f, q, g, H, projected, mu, 100.0, 0, r}; }
};
}  // namespace

TEST_CASE("newton ladder: a positive definite Hessian takes rung 0 at the given shift", "[solve][newton]") {
    for (bool with_ldl : {false, true}) {
        Setup s(1.1, 1.2);
        NewtonLadder ladder(s.llt, with_ldl ? &s.ldl : nullptr);
        LadderState st = s.state(1e-8);
        Eigen::VectorXd d;
        double shift = -1;
        NewtonRung& rung = ladder.descend(st, 0, d, shift);
        CHECK(rung.level() == 0);
        CHECK(shift == 1e-8);
        CHECK(st.descent(d));
        CHECK(!rung.modified());  // no negative pivot: with LDL^T too this is the exact Newton direction
        CHECK(!s.projected);
        CHECK(s.r.factorizations == 1);
    }
}

TEST_CASE("newton ladder: an indefinite Hessian is modified, shifted or projected, by the rungs in turn",
          "[solve][newton]") {
    {  // with LDL^T: the modified factorization at the given shift
        Setup s(0.0, 0.5);
        NewtonLadder ladder(s.llt, &s.ldl);
        LadderState st = s.state(1e-8);
        st.dm = 1e4;  // a scale at which the shifted rung's escalation reaches the shift it needs (below)
        Eigen::VectorXd d;
        double shift = -1;
        NewtonRung& rung = ladder.descend(st, 0, d, shift);
        CHECK(&rung == ladder.modified_ldl());
        CHECK(rung.modified());
        CHECK(shift == 1e-8);
        CHECK(st.descent(d));
        // The retry pass skips the modified rung and starts the shifted one above the given shift.
        st.pass = 1;
        NewtonRung& again = ladder.descend(st, 0, d, shift);
        CHECK(&again != ladder.modified_ldl());
        CHECK(again.level() == 0);
        CHECK(shift > 198);
        CHECK(st.descent(d));
    }
    {  // without: the exact Hessian shifted until it factors (h00 = -198 needs a shift of 0.2 mean diag or less)
        Setup s(0.0, 0.5);
        NewtonLadder ladder(s.llt, nullptr);
        LadderState st = s.state(1e-8);
        st.dm = 1e4;  // a scale at which the escalation reaches the needed shift
        Eigen::VectorXd d;
        double shift = -1;
        NewtonRung& rung = ladder.descend(st, 0, d, shift);
        CHECK(rung.level() == 0);
        CHECK(shift > 198);
        CHECK(st.descent(d));
        CHECK(!s.projected);
    }
    {  // starting at level 1: the projected Hessian
        Setup s(0.0, 0.5);
        NewtonLadder ladder(s.llt, nullptr);
        LadderState st = s.state(1e-8);
        Eigen::VectorXd d;
        double shift = -1;
        NewtonRung& rung = ladder.descend(st, 1, d, shift);
        CHECK(rung.level() >= 1);
        CHECK(s.projected);
        CHECK(st.descent(d));
    }
}

TEST_CASE("newton ladder: the last rung is steepest descent, always available", "[solve][newton]") {
    Setup s(0.0, 0.5);
    NewtonLadder ladder(s.llt, nullptr);
    LadderState st = s.state(1e-8);
    Eigen::VectorXd d;
    double shift = -1;
    NewtonRung& rung = ladder.descend(st, 3, d, shift);
    CHECK(rung.level() == 3);
    CHECK(shift == 0);
    CHECK(d.isApprox(-s.g / st.dm));
    CHECK(s.r.factorizations == 0);
}

TEST_CASE("newton ladder: when the shift cap is too low for the exact Hessian, the projected rung takes over",
          "[solve][newton]") {
    Setup s(0.0, 0.5);
    NewtonLadder ladder(s.llt, nullptr);
    LadderState st = s.state(1e-8);  // mean diag 100: the exact rung stops at 0.2 x 100 = 20 < 198
    Eigen::VectorXd d;
    double shift = -1;
    NewtonRung& rung = ladder.descend(st, 0, d, shift);
    CHECK(rung.level() == 1);
    CHECK(s.projected);
    CHECK(st.descent(d));
}
