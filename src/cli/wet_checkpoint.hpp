#pragma once
// Checkpoints of `fibernet wet`'s smooth-model relaxation, and the start state that continues one (docs/wet.md,
// "Checkpoints and --start-state"; docs/formats.md). A 1e4-fiber wet relaxation runs for hours, and an interrupt used to
// lose the beta in progress. With -o DIR and --checkpoint-seconds S > 0, the relaxation's current iterate is written at
// most every S seconds as DIR/checkpoint_<k>.txt (a model file: exact) with DIR/checkpoint_<k>.json beside it (what it
// is, how far the relaxation got, the run's parameters, the command that continues it). A relaxation that ends
// unconverged leaves its last state there too. --start-state FILE starts the wet relaxation from such a state: the
// smooth energy is a function of the positions alone, so the continued relaxation minimizes the same energy from
// there. Its path may differ from the uninterrupted run's (Newton's shift and its Hessian pattern start afresh), so
// the equilibrium reached may too, as between any two paths on a nonconvex landscape (docs/wet.md).
#include <Eigen/Core>
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fibernet/model/model.hpp"

namespace fibernet::cli {

// A start state read and checked against this run's model and box deformation (InputError naming the file and the
// difference otherwise).
struct StartState {
    Eigen::VectorXd q;        // the dry energy's coordinates (displacements of the free nodes)
    std::string path;         // as given
    std::string canonical;    // its canonical path (never removed by the run's cleanup)
    nlohmann::json record;    // file, FNV-1a hash, iterations and seconds of the runs before (from its .json, if any)
    long iterations_before = 0;
    double seconds_before = 0;
};
StartState read_start_state(const std::string& path, const Model& m, const Eigen::Matrix2d& F);

class WetCheckpoints {
public:
    // dir: the output directory with its trailing '/' (empty: no checkpoints); every: seconds between two (0: none).
    // record: the run's parameters, echoed in each checkpoint's JSON; argv: this command's arguments (command_argv()),
    // from which the command that continues a checkpoint is built. `guard(write)` runs the writing (the CLI holds its
    // interrupt handler off meanwhile, so that an interrupt never leaves half a checkpoint).
    // progress: a line on stderr per checkpoint written.
    WetCheckpoints(std::string dir, double every, const Model& m, const Eigen::Matrix2d& F, nlohmann::json record,
                   const std::vector<std::string>& argv, const StartState* start, bool progress,
                   std::function<void(const std::function<void()>&)> guard);
    bool enabled() const { return !dir_.empty() && every_ > 0; }
    // Beta k's relaxation starts: its clock and count.
    void begin(size_t k, double beta);
    // An accepted iterate (SolverOptions::observe): written once `every` seconds have passed since the last write (or
    // the start).
    void observe(const Eigen::VectorXd& q, double energy, double grad_max);
    // A state between the local solves of an iteration (SolverOptions::observe_within): written on the same clock, with
    // its energy evaluated then and its max|g| unknown (null in the JSON; "within_iteration": true).
    void observe_within(const Eigen::VectorXd& q, const std::function<double()>& energy);
    // The relaxation of beta k ended unconverged: its last state is written as the checkpoint; returns the state file's
    // name in the directory ("" without checkpoints).
    std::string keep_last(const Eigen::VectorXd& q, double energy, double grad_max);
    // The relaxation of beta k converged and its state_<k>.txt is written: its checkpoint files go. The caller holds the
    // interrupt handler off.
    void discard() const;  // also a start state of the same name that this run overwrote
    // Removes checkpoint_*.txt / .json from an earlier run in the directory, except the start state and its JSON.
    void remove_stale() const;

private:
    // grad_max empty: a state within an iteration, whose gradient was not evaluated.
    void write(const Eigen::VectorXd& q, double energy, std::optional<double> grad_max, bool last);
    bool kept(const std::string& file) const;  // the start state or its JSON

    std::string dir_;
    double every_;
    const Model& m_;
    Eigen::Matrix2d F_;
    nlohmann::json record_;
    std::string hint_;
    const StartState* start_;
    bool progress_;
    std::function<void(const std::function<void()>&)> guard_;
    size_t k_ = 0;
    double beta_ = 0;
    long iterations_ = 0;
    bool written_ = false;  // this run wrote a checkpoint (over the start state, if it had the same name)
    std::chrono::steady_clock::time_point t0_, last_;
};

}  // namespace fibernet::cli
