// The model file keeps a state losslessly: a relaxed, strained state re-evaluates from the file at the max|g| its
// solve reported, since the state is read from the displacement columns, not from the rounded absolute positions.
#include <catch2/catch.hpp>
#include <sstream>

#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
double max_grad(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F) {
    EnergyEval ev;
    e.evaluate(q, F, Eigen::Matrix2d::Zero(), kGradient, ev);
    return ev.gradient.lpNorm<Eigen::Infinity>();
}
}  // namespace

TEST_CASE("model file: a relaxed sheared state re-evaluates at its reported max|g|", "[model][io]") {
    MikadoParams mp;
    mp.L = 6, mp.q = 8, mp.pl = 1, mp.seed = 5;
    DiscretizationParams dp;
    dp.scheme = Scheme::Even;
    const Model m = discretize(generate_mikado(mp), dp);
    const NetworkEnergy e(m);
    const Eigen::Matrix2d F = deformation(StrainKind::Shear, 0.05);
    SolverOptions so;
    so.tol = 1e-10;
    NewtonSolver newton(so);
    const Equilibrium eq = relax(e, F, newton);
    REQUIRE(eq.converged());

    std::stringstream file;
    write_model(file, m, e.displacements(eq.q, F), F);
    Eigen::VectorXd u;
    Eigen::Matrix2d F2;
    const Model r = read_model(file, "state.txt", &u, &F2);
    CHECK(F2 == F);
    for (size_t k = 0; k < m.segments.size(); ++k) CHECK(r.segments[k].d0 == m.segments[k].d0);
    const NetworkEnergy e2(r);
    const Eigen::VectorXd q2 = e2.dofs_of_displacements(u);
    CHECK(q2 == eq.q);
    // Same rest vectors, state and deformation: the same gradient, up to the order of a parallel sum. Rest vectors
    // taken from the rounded reference positions instead would move |g| by 4 a^2 ulp(L) / l0 (1e-9 on the shortest
    // segments here), and the state from x_ref + u by more.
    REQUIRE(summarize(r).shortest_segment < 0.05);  // the regime where it matters
    CHECK(max_grad(e2, q2, F2) <= eq.result.grad_max + 1e-12);
}

TEST_CASE("model file: a section count beyond the lines that follow is refused, not allocated", "[model][io][input]") {
    // Fuzzing found "nodes 1999999999" ending in std::bad_alloc (exit 3): entries are now appended as they are read.
    MikadoParams mp;
    mp.L = 2.5, mp.q = 4, mp.pl = 1, mp.seed = 1;
    const Model m = discretize(generate_mikado(mp), DiscretizationParams{});
    std::stringstream file;
    write_model(file, m);
    const std::string text = file.str();
    {
        std::istringstream is(text);
        CHECK(read_model(is, "m.txt").segments.size() == m.segments.size());
    }
    // What each reads instead of the entries it was promised: the next section's line, or the file's end.
    const std::pair<const char*, const char*> sections[] = {{"nodes", "node x = 'segments'"},
                                                            {"segments", "segment node i = 'hinges'"},
                                                            {"hinges", "hinge node i = 'supernodes'"},
                                                            {"supernodes", "unexpected end of file, expected supernode"}};
    for (const auto& [section, message] : sections) {
        const std::string key = std::string("\n") + section + " ";
        const size_t at = text.find(key);
        REQUIRE(at != std::string::npos);
        const size_t end = text.find('\n', at + 1);
        std::istringstream is(text.substr(0, at) + key + "1999999999" + text.substr(end));
        INFO(section);
        try {
            read_model(is, "m.txt");
            FAIL("accepted");
        } catch (const InputError& e) {
            INFO(e.what());
            CHECK(std::string(e.what()).find("m.txt:") != std::string::npos);
            CHECK(std::string(e.what()).find(message) != std::string::npos);
        }
    }
}
