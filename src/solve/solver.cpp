#include "fibernet/solve/solver.hpp"

#include "fibernet/solve/newton.hpp"
#include "fibernet/solve/solver_suite.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

// The registry of solvers `--solver` can name. Add one `if` per solver.
std::unique_ptr<Solver> make_solver(const std::string& name, const SolverOptions& opt) {
    if (name == "newton") return std::make_unique<NewtonSolver>(opt);
    if (auto s = make_suite_solver(name, opt)) return s;  // issue 5: lbfgs, nlopt-*, ipopt, fire, cg
    std::string known = "newton";
    for (const auto& n : suite_solver_names()) known += ", " + n;
    throw InputError("solver '" + name + "' is unknown (known: " + known + ")");
}

}  // namespace fibernet
