#pragma once
// Every solver `--solver` can name, in one table: name, one line of documentation and a factory with the solver's
// default parameters (its capabilities come from the solver itself, Solver::capabilities()). Adding a solver is one
// row here (src/solve/solver_registry.cpp).
//   newton (newton.hpp); lbfgs, lbfgs-hessian (lbfgs.hpp); nlopt-lbfgs, nlopt-tnewton, nlopt-var2
//   (nlopt_solver.hpp); ipopt (ipopt_solver.hpp); fire (fire.hpp); cg (cg.hpp).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fibernet/solve/solver.hpp"

namespace fibernet {

struct SolverEntry {
    std::string name;
    std::string doc;
    std::function<std::unique_ptr<Solver>(const SolverOptions&)> make;
};

// The table, in a fixed order (newton first).
const std::vector<SolverEntry>& solver_registry();
// The registered names, in the table's order.
std::vector<std::string> solver_names();
// The entry of `name`; throws InputError naming an unknown solver and listing the known ones.
const SolverEntry& solver_entry(const std::string& name);
// The capabilities of the solver `name` with default options (for a scene checked before any solver is made).
SolverCapabilities solver_capabilities(const std::string& name);

}  // namespace fibernet
