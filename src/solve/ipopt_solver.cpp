#include "fibernet/solve/ipopt_solver.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>
#include <cmath>
#include <cstring>
#include <limits>

#include "fibernet/solve/solver_loop.hpp"
#include "solver_util.hpp"

namespace fibernet {

void IpoptParams::check(const std::string& where) const {
    check_value(print_level >= 0 && print_level <= 12, print_level, where, "print_level", "must lie in [0, 12]");
    if (!linear_solver.empty() && linear_solver != "mumps" && linear_solver != "ma27" && linear_solver != "ma57" &&
        linear_solver != "ma86" && linear_solver != "ma97" && linear_solver != "pardiso" && linear_solver != "wsmp")
        throw InputError(where + ": linear_solver = " + linear_solver +
                         " is not an Ipopt linear solver (mumps, ma27, ma57, ma86, ma97, pardiso, wsmp)");
}

IpoptSolver::IpoptSolver(const SolverOptions& opt, const IpoptParams& p) : opt_(opt), p_(p) {
    opt_.check(name());
    p_.check(name());
}

SolverCapabilities IpoptSolver::capabilities() const {
    SolverCapabilities c;
    c.hessian = p_.exact_hessian;
    return c;
}

namespace {
using Ipopt::Index;
using Ipopt::Number;

class Problem : public Ipopt::TNLP {
public:
    Problem(SolverRun& run, const Eigen::VectorXd& q0)
        : run_(run), f_(run.objective()), q0_(q0), H_(f_.hessian_pattern()), g_(q0.size()), gh_(q0.size()) {}

    Eigen::VectorXd x_final;
    bool have_final = false, time_stop = false;
    Ipopt::SolverReturn final_status = Ipopt::UNASSIGNED;
    double assembly_seconds = 0;

    bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag, IndexStyleEnum& style) override {
        n = static_cast<Index>(q0_.size()), m = 0, nnz_jac_g = 0;
        nnz_h_lag = static_cast<Index>(H_.nonZeros());
        style = C_STYLE;
        return true;
    }
    bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index, Number*, Number*) override {
        for (Index i = 0; i < n; ++i) x_l[i] = -2e19, x_u[i] = 2e19;  // beyond nlp_{lower,upper}_bound_inf: free
        return true;
    }
    bool get_starting_point(Index n, bool init_x, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
        if (init_x) Eigen::Map<Eigen::VectorXd>(x, n) = q0_;
        return true;
    }
    bool eval_f(Index n, const Number* x, bool new_x, Number& obj) override {
        if (!evaluate(n, x, new_x)) return false;
        obj = fx_;
        return true;
    }
    bool eval_grad_f(Index n, const Number* x, bool new_x, Number* grad) override {
        if (!evaluate(n, x, new_x)) return false;
        Eigen::Map<Eigen::VectorXd>(grad, n) = g_;
        return true;
    }
    bool eval_g(Index, const Number*, bool, Index, Number*) override { return true; }
    bool eval_jac_g(Index, const Number*, bool, Index, Index, Index*, Index*, Number*) override { return true; }
    bool eval_h(Index n, const Number* x, bool, Number obj_factor, Index, const Number*, bool, Index nele,
                Index* iRow, Index* jCol, Number* values) override {
        if (!values) {  // structure: lower triangle = transposed upper pattern
            Index k = 0;
            for (int j = 0; j < H_.outerSize(); ++j)
                for (Eigen::SparseMatrix<double>::InnerIterator it(H_, j); it; ++it, ++k)
                    iRow[k] = static_cast<Index>(it.col()), jCol[k] = static_cast<Index>(it.row());
            return k == nele;
        }
        xv_ = Eigen::Map<const Eigen::VectorXd>(x, n);
        detail::Clock c;
        const double e = f_.hessian(xv_, gh_, H_, false);
        assembly_seconds += c.seconds();
        if (!std::isfinite(e)) return false;
        const double* hv = H_.valuePtr();
        for (Index k = 0; k < nele; ++k) values[k] = obj_factor * hv[k];
        for (Index k = 0; k < nele; ++k)
            if (!std::isfinite(values[k])) return false;
        return true;
    }
    void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* x, const Number*, const Number*, Index,
                           const Number*, const Number*, Number, const Ipopt::IpoptData*,
                           Ipopt::IpoptCalculatedQuantities*) override {
        final_status = status;
        if (x) x_final = Eigen::Map<const Eigen::VectorXd>(x, n), have_final = true;
    }
    bool intermediate_callback(Ipopt::AlgorithmMode, Index iter, Number obj, Number, Number inf_du, Number, Number,
                               Number, Number, Number, Index, const Ipopt::IpoptData*,
                               Ipopt::IpoptCalculatedQuantities*) override {
        run_.tick(iter, obj, inf_du);
        if (run_.out_of_time()) {
            time_stop = true;
            return false;
        }
        return true;
    }

private:
    // Value and gradient at x, cached for the last x.
    bool evaluate(Index n, const Number* x, bool new_x) {
        if (new_x || !cached_ || std::memcmp(x, xc_.data(), sizeof(double) * n) != 0) {
            xc_ = Eigen::Map<const Eigen::VectorXd>(x, n);
            fx_ = f_.gradient(xc_, g_);
            ok_ = std::isfinite(fx_) && g_.allFinite();
            cached_ = true;
        }
        return ok_;
    }

    SolverRun& run_;
    Objective& f_;
    Eigen::VectorXd q0_;
    Eigen::SparseMatrix<double> H_;
    Eigen::VectorXd g_, gh_, xc_, xv_;
    double fx_ = 0;
    bool cached_ = false, ok_ = false;
};

const char* status_name(Ipopt::ApplicationReturnStatus s) {
    switch (s) {
        case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
        case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
        case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
        case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
        case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
        case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
        case Ipopt::Restoration_Failed: return "Restoration_Failed";
        case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
        case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
        case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
        case Ipopt::Invalid_Option: return "Invalid_Option";
        case Ipopt::Insufficient_Memory: return "Insufficient_Memory";
        default: return "other Ipopt failure";
    }
}
}  // namespace

SolveResult IpoptSolver::minimize(Objective& f_in, Eigen::VectorXd& q) {
    SolverRun run(name(), opt_, f_in, q);
    SolveResult& r = run.result();
    // Every exit reports the returned state evaluated afresh, not Ipopt's word for it.
    auto finish = [&](SolveStatus st, const std::string& msg) {
        return run.finish_verified(st, msg, q, SolveStatus::Stalled);
    };
    {
        Eigen::VectorXd g(q.size());
        const double f0 = run.objective().gradient(q, g);
        if (!std::isfinite(f0) || !g.allFinite()) return finish(SolveStatus::NonFinite, "non-finite energy or gradient at the start");
        if (detail::max_abs(g) <= opt_.tol || q.size() == 0) return finish(SolveStatus::Converged, "max|g| <= tol at the start");
    }

    Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
    auto& o = *app->Options();
    o.SetStringValue("sb", "yes");
    o.SetIntegerValue("print_level", p_.print_level);
    o.SetNumericValue("tol", opt_.tol);
    o.SetNumericValue("dual_inf_tol", opt_.tol);
    o.SetIntegerValue("acceptable_iter", 0);
    o.SetStringValue("nlp_scaling_method", "none");
    o.SetIntegerValue("max_iter", opt_.max_iter);
    if (opt_.max_seconds > 0) o.SetNumericValue("max_cpu_time", opt_.max_seconds);
    o.SetStringValue("hessian_approximation", p_.exact_hessian ? "exact" : "limited-memory");
    if (!p_.linear_solver.empty()) o.SetStringValue("linear_solver", p_.linear_solver);
    if (app->Initialize("") != Ipopt::Solve_Succeeded) return finish(SolveStatus::Failed, "Ipopt failed to initialize");

    Ipopt::SmartPtr<Problem> prob = new Problem(run, q);
    const Ipopt::ApplicationReturnStatus st = app->OptimizeTNLP(Ipopt::SmartPtr<Ipopt::TNLP>(GetRawPtr(prob)));
    r.timings.assembly = prob->assembly_seconds;
    if (Ipopt::IsValid(app->Statistics())) r.iterations = app->Statistics()->IterationCount();
    r.factorizations = r.iterations;  // at least one KKT factorization per iteration (inertia correction adds more)
    if (prob->have_final) q = prob->x_final;
    const std::string msg = std::string("Ipopt ") + status_name(st);
    switch (st) {
        case Ipopt::Solve_Succeeded:
        case Ipopt::Solved_To_Acceptable_Level: return finish(SolveStatus::Converged, msg);
        case Ipopt::Search_Direction_Becomes_Too_Small: return finish(SolveStatus::Stalled, msg);
        case Ipopt::Maximum_Iterations_Exceeded:
        case Ipopt::Maximum_CpuTime_Exceeded: return finish(SolveStatus::IterationLimit, msg);
        case Ipopt::User_Requested_Stop:
            return finish(prob->time_stop ? SolveStatus::IterationLimit : SolveStatus::Failed,
                          prob->time_stop ? msg + " (time limit reached)" : msg);
        case Ipopt::Restoration_Failed: return finish(SolveStatus::LineSearchFailed, msg);
        case Ipopt::Invalid_Number_Detected: return finish(SolveStatus::NonFinite, msg);
        default: return finish(SolveStatus::Failed, msg);
    }
}

}  // namespace fibernet
