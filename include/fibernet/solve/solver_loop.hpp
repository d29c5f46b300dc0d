#pragma once
// The one loop every solver runs (issue 23, item 1). A SolverRun owns what all solvers share: the clock and the time
// budget, the evaluation counts (its objective() counts every call), the once-a-second progress line, the stop tests
// at the head of each iteration, and the finish that fills the SolveResult. An iterative method (Newton, L-BFGS, CG,
// FIRE) supplies only its start and one iteration (IterativeMethod) and run_iterations() does the rest; a backend
// with a loop of its own (NLopt, Ipopt) uses the same SolverRun from its callbacks (tick, out_of_time) and finishes
// through finish_verified(), which evaluates the returned state afresh instead of taking the backend's word for it.
#include <Eigen/Core>
#include <chrono>
#include <string>

#include "fibernet/energy/objective.hpp"
#include "fibernet/solve/result.hpp"
#include "fibernet/solve/solver.hpp"

namespace fibernet {

// Forwards to an objective, counting value/gradient/Hessian evaluations.
class CountedObjective : public Objective {
public:
    explicit CountedObjective(Objective& f) : f_(f) {}
    int size() const override { return f_.size(); }
    double value(const Eigen::VectorXd& q) override;
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override;
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                   bool psd) override;
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return f_.hessian_pattern(); }
    long pattern_version() const override { return f_.pattern_version(); }
    std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) override {
        return f_.restriction(q, coords);  // not counted: the region's evaluations are its own solver's
    }
    int evaluations = 0;

private:
    Objective& f_;
};

// What one iteration (or the start) tells the loop: whether the iterate moved (the iteration counts), and whether
// the solve ends here, with which status.
struct Step {
    bool advanced = false;
    bool done = false;
    SolveStatus status = SolveStatus::Failed;
    std::string message;

    static Step moved() { return {true, false, SolveStatus::Failed, {}}; }
    static Step again() { return {false, false, SolveStatus::Failed, {}}; }  // no move; back to the stop tests
    static Step stop(SolveStatus s, std::string m, bool advanced = false) { return {advanced, true, s, std::move(m)}; }
};

class SolverRun {
public:
    // Throws InputError unless q has f's size; `name` labels progress lines and the result.
    SolverRun(std::string name, const SolverOptions& opt, Objective& f, const Eigen::VectorXd& q);
    CountedObjective& objective() { return f_; }
    const SolverOptions& options() const { return opt_; }
    SolveResult& result() { return r_; }
    double seconds() const;
    bool out_of_time() const { return opt_.max_seconds > 0 && seconds() >= opt_.max_seconds; }
    // The stop tests at the head of iteration k: max|g| <= tol, the iteration budget, the time budget.
    bool stop_test(int k, double grad_max, Step& out) const;
    // "<solver>: it <k>  E <e>  max|g| <g>  t <s>" on stderr at most once a second, with options().verbose.
    void tick(int k, double energy, double grad_max, const std::string& extra = "");
    // "<solver>: it <k>  local solves <done> of <total>  t <s>  (about <r> s more for them)" on the same clock (at most
    // once a second, with verbose or progress), for the local solves before a global step (the Schwarz sweep), which
    // at 1e4 fibers take minutes to hours with no iterate to report; `spent`: seconds spent in them so far.
    void tick_within(int k, int done, int total, double spent);
    // Fills the result (status, message, iterations, evaluations, energy, max|g|, total time) and prints the last line.
    SolveResult finish(SolveStatus status, const std::string& message, int iterations, double energy,
                       double grad_max);
    // finish() for the state q evaluated afresh: NonFinite if it is; Converged exactly when max|g| <= tol; a claimed
    // convergence above tol becomes `claimed_above_tol`. result().iterations is kept as the backend set it.
    SolveResult finish_verified(SolveStatus claimed, const std::string& message, const Eigen::VectorXd& q,
                                SolveStatus claimed_above_tol);

private:
    std::string name_;
    SolverOptions opt_;
    CountedObjective f_;
    SolveResult r_;
    std::chrono::steady_clock::time_point t0_;
    double next_tick_ = 1.0;
};

// A method whose iterations run_iterations() drives.
class IterativeMethod {
public:
    virtual ~IterativeMethod() = default;
    // Evaluates the start q; Step::moved() (or again()) to go on, or a stop (e.g. a non-finite start).
    virtual Step start(SolverRun& run, Eigen::VectorXd& q) = 0;
    // One iteration at q (k iterations done); on a move, q is the new iterate and energy()/grad_max() are its.
    virtual Step iterate(SolverRun& run, Eigen::VectorXd& q, int k) = 0;
    virtual double energy() const = 0;
    virtual double grad_max() const = 0;
    // A note for the progress line; empty by default.
    virtual std::string note() const { return {}; }
    // True if the method prints a line of its own every iteration (Newton, verbose): no once-a-second line then.
    virtual bool reports_every_iteration() const { return false; }
    // Adds what only this method reports to the result (last: the step that ended the solve), before the finish.
    virtual void complete(SolveResult& r, const Step& last, const Eigen::VectorXd& q) { (void)r, (void)last, (void)q; }
};

// start, then { stop tests; iterate; count; tick } until a stop: the loop of every iterative solver.
SolveResult run_iterations(SolverRun& run, IterativeMethod& method, Eigen::VectorXd& q);

}  // namespace fibernet
