#include "fibernet/solve/linear_solver.hpp"

#include "fibernet/solve/cholmod_ldl.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

Eigen::MatrixXd LinearSolver::solve_many(const Eigen::MatrixXd& B) const {
    Eigen::MatrixXd X(B.rows(), B.cols());
    for (Eigen::Index j = 0; j < B.cols(); ++j) X.col(j) = solve(B.col(j));
    return X;
}

const std::vector<std::string>& linear_solver_names() {
    static const std::vector<std::string> names = {"cholmod-llt", "cholmod-ldl"};
    return names;
}

std::unique_ptr<LinearSolver> make_linear_solver(const std::string& name) {
    if (name == "cholmod-llt") return std::make_unique<CholmodLLT>();
    if (name == "cholmod-ldl") return std::make_unique<CholmodLDL>();
    std::string known;
    for (const auto& n : linear_solver_names()) known += (known.empty() ? "" : ", ") + n;
    throw InputError("linear solver '" + name + "' is unknown (known: " + known + ")");
}

}  // namespace fibernet
