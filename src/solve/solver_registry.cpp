#include "fibernet/solve/solver_registry.hpp"

#include "fibernet/solve/cg.hpp"
#include "fibernet/solve/fire.hpp"
#include "fibernet/solve/ipopt_solver.hpp"
#include "fibernet/solve/lbfgs.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/solve/nlopt_solver.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

namespace {
template <class S, class... A>
std::function<std::unique_ptr<Solver>(const SolverOptions&)> maker(A... a) {
    return [=](const SolverOptions& o) -> std::unique_ptr<Solver> { return std::make_unique<S>(a..., o); };
}
LbfgsParams hessian_h0() {
    LbfgsParams p;
    p.hessian_h0 = true;
    return p;
}
}  // namespace

const std::vector<SolverEntry>& solver_registry() {
    static const std::vector<SolverEntry> table = {
        {"newton", "exact sparse Hessian, CHOLMOD, shifted ladder and Armijo line search (newton.hpp)",
         maker<NewtonSolver>()},
        {"lbfgs", "limited-memory BFGS, strong Wolfe line search (lbfgs.hpp)",
         [](const SolverOptions& o) -> std::unique_ptr<Solver> { return std::make_unique<LbfgsSolver>(o); }},
        {"lbfgs-hessian", "L-BFGS with a factorized projected Hessian as H0 (lbfgs.hpp)",
         [](const SolverOptions& o) -> std::unique_ptr<Solver> {
             return std::make_unique<LbfgsSolver>(o, hessian_h0());
         }},
        {"nlopt-lbfgs", "NLopt's LD_LBFGS (nlopt_solver.hpp)", maker<NloptSolver>(NloptMethod::Lbfgs)},
        {"nlopt-tnewton", "NLopt's preconditioned truncated Newton (nlopt_solver.hpp)",
         maker<NloptSolver>(NloptMethod::TNewton)},
        {"nlopt-var2", "NLopt's shifted limited-memory variable metric (nlopt_solver.hpp)",
         maker<NloptSolver>(NloptMethod::Var2)},
        {"ipopt", "Ipopt's interior point with the exact Hessian, unconstrained (ipopt_solver.hpp)",
         maker<IpoptSolver>()},
        {"fire", "FIRE damped dynamics (fire.hpp)", maker<FireSolver>()},
        {"cg", "nonlinear conjugate gradients, Polak-Ribiere+ (cg.hpp)", maker<CgSolver>()},
    };
    return table;
}

std::vector<std::string> solver_names() {
    std::vector<std::string> names;
    for (const SolverEntry& e : solver_registry()) names.push_back(e.name);
    return names;
}

const SolverEntry& solver_entry(const std::string& name) {
    for (const SolverEntry& e : solver_registry())
        if (e.name == name) return e;
    std::string known;
    for (const SolverEntry& e : solver_registry()) known += (known.empty() ? "" : ", ") + e.name;
    throw InputError("solver '" + name + "' is unknown (known: " + known + ")");
}

SolverCapabilities solver_capabilities(const std::string& name) {
    return solver_entry(name).make(SolverOptions{})->capabilities();
}

}  // namespace fibernet
