#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "fibernet/solve/line_search.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
// f(x) = sum_i w_i (x_i - c_i)^2 / 2 + +inf where x_0 > wall (a domain boundary).
class Bowl : public Objective {
public:
    Bowl(double wall = std::numeric_limits<double>::infinity()) : wall_(wall) {}
    int size() const override { return 2; }
    double value(const Eigen::VectorXd& x) override {
        if (x[0] > wall_) return std::numeric_limits<double>::infinity();
        return 0.5 * (x[0] - 3) * (x[0] - 3) + 50 * (x[1] + 1) * (x[1] + 1);
    }
    double gradient(const Eigen::VectorXd& x, Eigen::VectorXd& g) override {
        g.resize(2);
        g << x[0] - 3, 100 * (x[1] + 1);
        if (x[0] > wall_) g.setConstant(std::numeric_limits<double>::quiet_NaN());
        return value(x);
    }
    double hessian(const Eigen::VectorXd& x, Eigen::VectorXd& g, Eigen::SparseMatrix<double>&, bool) override {
        return gradient(x, g);
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return P_; }

private:
    double wall_;
    Eigen::SparseMatrix<double> P_{2, 2};
};

void check_wolfe(Bowl& f, const Eigen::VectorXd& x0, const Eigen::VectorXd& d, const LineSearchResult& r,
                 const Eigen::VectorXd& x, const Eigen::VectorXd& g, const LineSearchParams& p) {
    Eigen::VectorXd g0;
    const double f0 = f.gradient(x0, g0);
    REQUIRE(r.outcome == LineSearchOutcome::Ok);
    CHECK((x - (x0 + r.alpha * d)).norm() < 1e-14);
    CHECK(r.f == f.value(x));
    CHECK(r.f <= f0 + p.c1 * r.alpha * g0.dot(d));
    CHECK(std::abs(g.dot(d)) <= p.c2 * std::abs(g0.dot(d)));
}
}  // namespace

TEST_CASE("strong Wolfe line search: a step that satisfies both conditions", "[solve][line_search]") {
    Bowl f;
    Eigen::VectorXd x0(2), g0, x, g;
    x0 << 0, 0;
    const double f0 = f.gradient(x0, g0);
    const Eigen::VectorXd d = -g0;
    for (double c2 : {0.9, 0.1}) {
        LineSearchParams p;
        p.c2 = c2;
        StrongWolfeLineSearch ls(p);
        for (double a0 : {1e-6, 1e-2, 1.0, 100.0}) {
            INFO("c2 " << c2 << " alpha0 " << a0);
            const LineSearchResult r = ls.search(f, x0, f0, g0, d, a0, x, g);
            check_wolfe(f, x0, d, r, x, g, p);
        }
    }
}

TEST_CASE("line search backs off from +inf/NaN beyond a domain boundary", "[solve][line_search]") {
    Bowl f(0.5);  // the minimum along d lies beyond the wall
    Eigen::VectorXd x0(2), g0, x, g;
    x0 << 0, -1;
    const double f0 = f.gradient(x0, g0);
    const Eigen::VectorXd d = -g0;  // (3, 0)
    LineSearchParams p;
    StrongWolfeLineSearch ls(p);
    const LineSearchResult r = ls.search(f, x0, f0, g0, d, 1.0, x, g);
    REQUIRE(r.ok());
    CHECK(x[0] <= 0.5);
    CHECK(std::isfinite(r.f));
    CHECK(r.f < f0);
    CHECK(g.allFinite());
}

TEST_CASE("line search reports an ascent direction and a hopeless search", "[solve][line_search]") {
    Bowl f(0.0);  // every step along +x leaves the domain
    Eigen::VectorXd x0(2), g0, x, g;
    x0 << 0, -1;
    const double f0 = f.gradient(x0, g0);
    StrongWolfeLineSearch ls;
    const LineSearchResult up = ls.search(f, x0, f0, g0, g0, 1.0, x, g);
    CHECK(up.outcome == LineSearchOutcome::NotDescent);
    CHECK(x == x0);
    const LineSearchResult r = ls.search(f, x0, f0, g0, -g0, 1.0, x, g);
    CHECK_FALSE(r.ok());
    CHECK(r.outcome == LineSearchOutcome::NonFinite);
    CHECK(x == x0);
    CHECK(g == g0);
}
