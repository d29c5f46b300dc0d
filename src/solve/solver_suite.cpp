#include "fibernet/solve/solver_suite.hpp"

#include "fibernet/solve/cg.hpp"
#include "fibernet/solve/fire.hpp"
#include "fibernet/solve/ipopt_solver.hpp"
#include "fibernet/solve/lbfgs.hpp"
#include "fibernet/solve/nlopt_solver.hpp"

namespace fibernet {

const std::vector<std::string>& suite_solver_names() {
    static const std::vector<std::string> names = {"lbfgs",      "lbfgs-hessian", "nlopt-lbfgs", "nlopt-tnewton",
                                                   "nlopt-var2", "ipopt",         "fire",        "cg"};
    return names;
}

std::unique_ptr<Solver> make_suite_solver(const std::string& name, const SolverOptions& opt) {
    if (name == "lbfgs") return std::make_unique<LbfgsSolver>(opt);
    if (name == "lbfgs-hessian") {
        LbfgsParams p;
        p.hessian_h0 = true;
        return std::make_unique<LbfgsSolver>(opt, p);
    }
    if (name == "nlopt-lbfgs") return std::make_unique<NloptSolver>(NloptMethod::Lbfgs, opt);
    if (name == "nlopt-tnewton") return std::make_unique<NloptSolver>(NloptMethod::TNewton, opt);
    if (name == "nlopt-var2") return std::make_unique<NloptSolver>(NloptMethod::Var2, opt);
    if (name == "ipopt") return std::make_unique<IpoptSolver>(opt);
    if (name == "fire") return std::make_unique<FireSolver>(opt);
    if (name == "cg") return std::make_unique<CgSolver>(opt);
    return nullptr;
}

}  // namespace fibernet
