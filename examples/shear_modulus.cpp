// fibernet as a library: the linear shear and bulk moduli of a Mikado network at a shear strain gamma, what
// `fibernet modulus --L L --q Q --pl PL --seed S --gamma G` computes, in a few calls
// (scene -> network -> model -> energy -> solver -> results). Build: examples/CMakeLists.txt.
//   shear_modulus [L=5] [q=8] [pl=1] [seed=1] [gamma=0]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/mechanics/stress.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/newton.hpp"

int main(int argc, char** argv) try {
    using namespace fibernet;
    MikadoParams p;  // box side and density in fiber lengths, periodic box
    p.L = argc > 1 ? std::atof(argv[1]) : 5;
    p.q = argc > 2 ? std::atof(argv[2]) : 8;
    p.pl = argc > 3 ? std::atof(argv[3]) : 1;
    p.seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1;
    const double gamma = argc > 5 ? std::atof(argv[5]) : 0;
    p.check("the command line");  // throws InputError naming a bad value

    const Network net = generate_mikado(p);
    const Model model = discretize(net, DiscretizationParams{});  // seed scheme, a = 10
    const NetworkEnergy energy(model);

    SolverOptions so;
    so.tol = 1e-10;  // max|g| at the equilibrium
    NewtonSolver newton(so);
    const Eigen::Matrix2d F = deformation(StrainKind::Shear, gamma);
    const Equilibrium eq = relax(energy, F, newton);
    if (!eq.converged()) {  // never use an unconverged state as an answer
        std::fprintf(stderr, "not converged: %s\n", eq.result.message.c_str());
        return 1;
    }
    // The shear and bulk moduli from one factorization, as `fibernet modulus` computes them (the same modes and
    // options, so the two programs give the same numbers). The state is an equilibrium to the tolerance Newton
    // accepted (so.tol, or its round-off floor when that is larger).
    const Stress st = stress(energy, eq.q, F);
    ModuliOptions mo;
    mo.equilibrium_tol = std::max({mo.equilibrium_tol, so.tol, eq.result.grad_max});
    const auto moduli =
        linear_moduli(energy, eq.q, F, {shear_mode(F, st.area), bulk_mode(F, st.area)}, mo, nullptr, newton.factorization());
    for (const Modulus& M : moduli)
        if (!M.ok) {
            std::fprintf(stderr, "the linear solve for %s failed\n", M.name.c_str());
            return 1;
        }
    const Modulus &G = moduli[0], &K = moduli[1];
    std::printf("fibers %zu  energy %.10g  G %.17g  G_error %.3g  G_affine %.17g  G/G_affine %.6g  K %.17g  K_error %.3g\n",
                net.fibers.size(), eq.energy, G.value, G.error, G.affine, G.value / G.affine, K.value, K.error);
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "shear_modulus: %s\n", e.what());
    return 2;
}
