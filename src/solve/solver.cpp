#include "fibernet/solve/solver.hpp"

#include "fibernet/solve/solver_registry.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

void SolverOptions::check(const std::string& where) const {
    check_value(tol > 0, tol, where, "tol", "must be > 0");
    check_value(max_iter > 0, max_iter, where, "max_iter", "must be > 0");
    check_value(max_seconds >= 0, max_seconds, where, "max_seconds", "must be >= 0 (0 = no limit)");
    check_value(max_step >= 0, max_step, where, "max_step", "must be >= 0 (0 = no cap)");
    if (ldl && projected) throw InputError(where + ": ldl and projected exclude each other (choose one first rung)");
    elimination.check(where);
}

std::unique_ptr<Solver> make_solver(const std::string& name, const SolverOptions& opt) {
    return solver_entry(name).make(opt);
}

}  // namespace fibernet
