#pragma once
// The solver suite of issue 5 (everything but Newton), by `--solver` name:
//   lbfgs, lbfgs-hessian (lbfgs.hpp), nlopt-lbfgs, nlopt-tnewton, nlopt-var2 (nlopt_solver.hpp),
//   ipopt (ipopt_solver.hpp), fire (fire.hpp), cg (cg.hpp).
// make_solver() (solver.hpp) asks this first; each solver is built with its default parameters.
#include <memory>
#include <string>
#include <vector>

#include "fibernet/solve/solver.hpp"

namespace fibernet {

// nullptr if `name` is not a suite solver. Throws InputError on bad options.
std::unique_ptr<Solver> make_suite_solver(const std::string& name, const SolverOptions& opt);
// The names make_suite_solver knows, in a fixed order.
const std::vector<std::string>& suite_solver_names();

}  // namespace fibernet
