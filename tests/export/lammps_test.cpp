// The LAMMPS export read by LAMMPS itself (Debian's `lmp`): `run 0` on an exported relaxed state gives the model's
// energy, its stretch and bend parts, and forces at the level that rounding the state to absolute positions allows.
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <unistd.h>

#include "fibernet/export/lammps.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"

using namespace fibernet;
namespace fs = std::filesystem;

namespace {

struct Thermo {
    double pe = NAN, ebond = NAN, eangle = NAN, fx = NAN, fy = NAN;
};

// The thermo line after the "Step PotEng E_bond E_angle ..." header of the log.
Thermo run_lammps(const fs::path& dir) {
    const std::string cmd = "cd '" + dir.string() + "' && " FIBERNET_LMP " -in net.in -log log.lammps -screen none";
    REQUIRE(std::system(cmd.c_str()) == 0);
    std::ifstream log(dir / "log.lammps");
    std::string line;
    Thermo t;
    while (std::getline(log, line))
        if (line.rfind("Step ", 0) == 0 && std::getline(log, line)) {
            std::istringstream ss(line);
            int step;
            ss >> step >> t.pe >> t.ebond >> t.eangle >> t.fx >> t.fy;
        }
    return t;
}

// How far the gradient can move when every coordinate moves by delta: max over rows of sum_j |H_ij| delta
// (first order; H from its upper triangle).
double gradient_shift_bound(const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F, double delta) {
    Eigen::SparseMatrix<double> H = e.hessian_pattern();
    EnergyEval ev;
    e.evaluate(q, F, Eigen::Matrix2d::Zero(), kHessian, ev, &H);
    Eigen::VectorXd rows = Eigen::VectorXd::Zero(q.size());
    for (int c = 0; c < H.outerSize(); ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(H, c); it; ++it) {
            rows[it.row()] += std::abs(it.value());
            if (it.row() != it.col()) rows[it.col()] += std::abs(it.value());
        }
    return rows.maxCoeff() * delta;
}

}  // namespace

TEST_CASE("LAMMPS run 0 on an exported relaxed state: the model's energy and forces", "[export][lammps]") {
    if (std::string(FIBERNET_LMP).empty()) FAIL("LAMMPS (lmp) was not found at configure time: install lammps");
    MikadoParams mp;
    mp.L = 4, mp.q = 8, mp.pl = 1, mp.seed = 1;
    DiscretizationParams dp;
    dp.scheme = Scheme::Even;
    const Model m = discretize(generate_mikado(mp), dp);
    const NetworkEnergy e(m);
    for (const auto& [kind, t] : {std::pair{StrainKind::Shear, 0.05}, std::pair{StrainKind::UniaxialX, 0.02}}) {
        CAPTURE(to_string(kind));
        const Eigen::Matrix2d F = deformation(kind, t);
        SolverOptions so;
        NewtonSolver newton(so);
        const Equilibrium eq = relax(e, F, newton);
        REQUIRE(eq.converged());
        const fs::path dir = fs::temp_directory_path() / ("fibernet_lammps_" + std::to_string(::getpid()));
        fs::create_directories(dir);
        {
            std::ofstream data(dir / "net.data"), input(dir / "net.in");
            const LammpsExport info = write_lammps(data, input, m, e.displacements(eq.q, F), F, "net.data", "test");
            CHECK(info.softcore_segments == 0);
        }
        const Thermo th = run_lammps(dir);
        fs::remove_all(dir);
        CHECK(th.pe == Approx(eq.energy).epsilon(1e-9));
        CHECK(th.ebond == Approx(eq.stretch).epsilon(1e-9));
        CHECK(th.eangle == Approx(eq.bend).epsilon(1e-9));
        // LAMMPS sees the state as absolute positions (each rounded, remapped into the box and differenced by
        // minimum image: a few ulps of the box size each), so its forces can differ from fibernet's gradient by
        // |H| times that. An error in the mapping (a wrong K, r0 or angle) would give forces of order the
        // stress, 1e-3 and more.
        const double delta = 8 * std::numeric_limits<double>::epsilon() * m.box.L * F.cwiseAbs().maxCoeff();
        const double floor = gradient_shift_bound(e, eq.q, F, delta);
        CAPTURE(floor, eq.result.grad_max);
        CHECK(std::max(th.fx, th.fy) <= eq.result.grad_max + floor);
        CHECK(floor < 1e-5);  // the check above means something
    }
}
