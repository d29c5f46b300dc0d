// fibernet sweep: quasistatic strain sweep with an adaptive step (include/fibernet/mechanics/sweep.hpp).
// One CSV row per accepted step, flushed at once, and a checkpoint after every step: Ctrl-C (SIGINT/SIGTERM)
// stops after the step in progress, and --resume continues with results identical to an uninterrupted run.

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <vector>

#include "common.hpp"
#include "vtk_series.hpp"
#include "fibernet/mechanics/sweep.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/hash.hpp"

namespace fibernet::cli {

namespace {
extern "C" void on_signal(int) { stop_requested() = true; }

const char* kSweepHeader =
    "step,gamma,sigma_xx,sigma_xy,sigma_yy,stress_path,dsdgamma,dsdgamma_affine,energy,stretch,bend,iterations,factorizations,"
    "retries,grad_max,seconds";
constexpr size_t kColumns = 16;

// A progress line per step, with the time left if the rest of the strain goes at this run's mean pace so far
// (rearrangements make it a guess).
struct StepLines {
    double t_first, t_max;
    std::chrono::steady_clock::time_point t_run = std::chrono::steady_clock::now();
    StepLines(double first, double last) : t_first(first), t_max(last) {}
    void step(const SweepRow& r) const {
        std::ostringstream line;
        line << "sweep: step " << r.step << "  gamma = " << r.t << "  s = " << r.stress_path << "  ds/dgamma = " << r.K
             << "  iterations = " << r.iterations << "  retries = " << r.retries << "  " << r.seconds << " s";
        const double done = std::abs(r.t - t_first), left = std::abs(t_max - r.t);
        if (done > 0 && left > 0)
            line << std::fixed << std::setprecision(2) << "  ETA " << seconds_since(t_run) * left / done << " s";
        progress_line(line.str());
    }
};

// The CSV's columns, for its sidecar (docs/sweep.md).
nlohmann::json column_docs() {
    return {{"step", "accepted step, 0 = the reference"},
            {"gamma", "strain parameter t of F(t) = I + t dF"},
            {"sigma_xx", "Cauchy stress (energy / length^2)"},
            {"sigma_xy", "Cauchy stress (energy / length^2)"},
            {"sigma_yy", "Cauchy stress (energy / length^2)"},
            {"stress_path", "s = (1/A0) dE/dt (energy / length^2); sigma_xy for simple shear"},
            {"dsdgamma", "differential modulus ds/dt, exact (linear response; energy / length^2)"},
            {"dsdgamma_affine", "affine part of ds/dt, (1/A0) E_tt"},
            {"energy", "total energy (bending units)"},
            {"stretch", "stretching energy"},
            {"bend", "bending energy"},
            {"iterations", "solver iterations of the step"},
            {"factorizations", "Hessian factorizations of the step"},
            {"retries", "halved steps before this one was accepted"},
            {"grad_max", "max |gradient| at the accepted state"},
            {"seconds", "wall time of the step"}};
}

std::string csv_row(const SweepRow& r) {
    std::ostringstream os;
    os << std::setprecision(17) << r.step << ',' << r.t << ',' << r.sigma(0, 0) << ',' << r.sigma(0, 1) << ','
       << r.sigma(1, 1) << ',' << r.stress_path << ',' << r.K << ',' << r.K_affine << ',' << r.energy << ','
       << r.stretch << ',' << r.bend << ',' << r.iterations << ',' << r.factorizations << ',' << r.retries << ','
       << r.grad_max << ',' << std::setprecision(4) << r.seconds;
    return os.str();
}

// Everything that determines the rows: a checkpoint records it, and --resume refuses any difference.
nlohmann::json sweep_parameters(const Scene& s, const SweepParams& p) {
    nlohmann::json j = scene_parameters(s);
    if (!s.network_file.empty()) {  // the file's content, not only its name, makes the network
        j["network_file_fnv1a"] = fnv1a_bytes(file_bytes(s.network_file, "network file"));
        // The file by its canonical path: the same file named from another directory or as ./x.net is the same sweep.
        std::error_code ec;
        const std::filesystem::path canon = std::filesystem::weakly_canonical(s.network_file, ec);
        if (!ec) j["network_file"] = canon.string();
    }
    j["fiber_length"] = s.discretization.fiber_length;
    j["prune"] = prune_rules(s);
    j["strain"] = to_string(p.kind);
    j["solver"] = s.solver.name, j["tol"] = s.solver.tol, j["max_iter"] = s.solver.max_iter;
    j["gamma_max"] = p.t_max, j["step"] = p.step, j["min_step"] = p.min_step, j["max_step"] = p.max_step;
    j["good_iterations"] = p.good_iterations, j["max_iterations"] = p.max_iterations, j["grow"] = p.grow;
    return j;
}

// The flag that sets a recorded parameter, for messages.
std::string flag_of(const std::string& key) {
    static const std::map<std::string, std::string> flags = {
        {"L", "--L"},           {"q", "--q"},           {"pl", "--pl"},           {"seed", "--seed"},
        {"periodic", "--open"}, {"network_file", "--network"}, {"network_file_fnv1a", "--network (content)"},
        {"scheme", "--scheme"}, {"n_seg", "--nseg"},    {"h", "--h"},             {"a", "--a"},
        {"prune", "--prune"},   {"strain", "--strain"}, {"solver", "--solver"},   {"tol", "--tol"},
        {"max_iter", "--max-iter"}, {"gamma_max", "--gamma-max"}, {"step", "--step"}, {"min_step", "--min-step"},
        {"max_step", "--max-step"}};
    auto it = flags.find(key);
    return it == flags.end() ? "" : " (" + it->second + ")";
}

std::string shown(const nlohmann::json& v) { return v.is_null() ? "(none)" : v.is_string() ? v.get<std::string>() : json_text(v); }

// completed: the sweep reached gamma_max (a run without --resume may then start over; --resume adds nothing).
void write_checkpoint(const std::string& path, const nlohmann::json& params, int rows, const SweepState& s,
                      bool completed = false) {
    std::ostringstream os;
    os << std::setprecision(17) << "fibernet-sweep-checkpoint 2\nparameters " << json_text(params) << "\ncompleted "
       << (completed ? 1 : 0) << "\ndofs "
       << s.q.size() << "\nrows " << rows << "\nstep " << s.step << "\nt " << s.t << "\nnext_step " << s.next_step
       << "\nq\n";
    for (int i = 0; i < s.q.size(); ++i) os << s.q[i] << '\n';
    write_file_atomic(path, os.str());
}

struct Checkpoint {
    int dofs = 0, rows = 0;
    bool completed = false;
    SweepState state;
};

// Whether the checkpoint at `path` records a completed sweep (false for anything else, also unreadable files).
bool completed_checkpoint(const std::string& path) {
    std::ifstream is(path);
    std::string key, line;
    int version = 0, done = 0;
    return (is >> key >> version) && version == 2 && (is >> key) && key == "parameters" && std::getline(is, line) &&
           (is >> key >> done) && key == "completed" && done == 1;
}

// Refuses a checkpoint state that no sweep with these parameters writes (run_sweep): one row per step from step 0
// at t = 0, t between 0 and gamma_max, and a next step in (0, max_step], at least min_step before the end.
template <class Fail>
void check_sweep_state(const Checkpoint& c, const SweepParams& p, const Fail& fail) {
    const SweepState& s = c.state;
    if (c.rows < 1) fail("rows = " + std::to_string(c.rows) + " must be >= 1 (the first row is written with the checkpoint)");
    if (s.step != c.rows - 1)
        fail("step = " + std::to_string(s.step) + " must be rows - 1 = " + std::to_string(c.rows - 1) +
             " (steps are numbered from 0, one row each)");
    const double dir = p.t_max > 0 ? 1 : -1, done = dir * s.t;
    if (!std::isfinite(s.t) || done < 0 || done > std::abs(p.t_max) || (s.step == 0) != (s.t == 0))
        fail("t = " + show(s.t) + " is not a strain this sweep reaches after step " + std::to_string(s.step) +
             " (0 at step 0, else between 0 and gamma_max = " + show(p.t_max) + ")");
    const bool at_end = dir * (p.t_max - s.t) <= 1e-14;
    if (c.completed && !at_end) fail("completed = 1 contradicts t = " + show(s.t) + " short of gamma_max = " + show(p.t_max));
    if (!(s.next_step > 0 && s.next_step <= p.max_step && (at_end || s.next_step >= p.min_step)))
        fail("next_step = " + show(s.next_step) + " must be in [min_step, max_step] = [" + show(p.min_step) + ", " +
             show(p.max_step) + "]");
}

// Reads a checkpoint and refuses it unless it was written with this run's parameters (each difference is named).
Checkpoint read_checkpoint(const std::string& path, const nlohmann::json& params, const SweepParams& p) {
    std::ifstream is(path);
    if (!is) throw InputError("--resume: checkpoint '" + path + "' cannot be opened");
    auto fail = [&](const std::string& m) -> void { throw InputError(path + ": " + m); };
    std::string key, line;
    int version = 0;
    Checkpoint c;
    SweepState& s = c.state;
    if (!(is >> key >> version) || key != "fibernet-sweep-checkpoint") fail("not a sweep checkpoint");
    if (version == 1)
        fail("checkpoint version 1 does not record the sweep's parameters, so --resume cannot check them; remove it "
             "(and the CSV) and run the sweep again");
    if (version != 2) fail("checkpoint version " + std::to_string(version) + " is not supported (expected 2)");
    if (!(is >> key) || key != "parameters" || !std::getline(is, line)) fail("missing parameters");
    nlohmann::json recorded = nlohmann::json::parse(line, nullptr, false);
    if (!recorded.is_object()) fail("parameters are not a JSON object");
    for (auto it = params.begin(); it != params.end(); ++it) {
        const nlohmann::json was = recorded.contains(it.key()) ? recorded[it.key()] : nlohmann::json();
        if (json_text(was) != json_text(it.value()))  // as written: non-UTF-8 bytes replaced
            fail(it.key() + " = " + shown(was) + " differs from this run's " + shown(it.value()) + flag_of(it.key()));
    }
    for (auto it = recorded.begin(); it != recorded.end(); ++it)  // e.g. a network file against a generated network
        if (!params.contains(it.key()))
            fail(it.key() + " = " + shown(it.value()) + " is not a parameter of this run" + flag_of(it.key()));
    // `completed` (0 or 1) before dofs; a checkpoint written without it is an unfinished one.
    int done = 0;
    if (!(is >> key)) fail("missing dofs");
    if (key == "completed") {
        if (!(is >> done) || (done != 0 && done != 1)) fail("completed must be 0 or 1");
        if (!(is >> key)) fail("missing dofs");
    }
    c.completed = done == 1;
    if (key != "dofs" || !(is >> c.dofs) || c.dofs < 0) fail("missing dofs");
    if (!(is >> key >> c.rows) || key != "rows") fail("missing rows");
    if (!(is >> key >> s.step) || key != "step") fail("missing step");
    if (!(is >> key >> s.t) || key != "t") fail("missing t");
    if (!(is >> key >> s.next_step) || key != "next_step") fail("missing next_step");
    if (!(is >> key) || key != "q") fail("missing q");
    // Read value by value, not into a vector of the declared size: a corrupt count must not allocate it.
    std::vector<double> q;
    for (double v; static_cast<int>(q.size()) < c.dofs; q.push_back(v)) {
        std::string token;
        if (!(is >> token))
            fail("dofs = " + std::to_string(c.dofs) + ", but only " + std::to_string(q.size()) + " values of q follow");
        if (!parse_decimal(token, v))
            fail("q[" + std::to_string(q.size()) + "] = '" + token + "' is not a finite number");
    }
    s.q = Eigen::Map<const Eigen::VectorXd>(q.data(), static_cast<Eigen::Index>(q.size()));
    if (is >> key) fail("unexpected '" + key + "' after the " + std::to_string(c.dofs) + " values of q");
    check_sweep_state(c, p, fail);
    return c;
}

// Keeps the header and the first `rows` data rows (a row written after the last checkpoint is dropped), once they
// are what this sweep wrote: its header, steps 0, 1, ... in order, and the last one at the checkpoint's strain t.
// Returns the (step, gamma) of the rows kept.
std::vector<std::pair<int, double>> truncate_csv(const std::string& path, int rows, double t) {
    std::ifstream is(path);
    if (!is) throw InputError("--resume: output '" + path + "' cannot be opened");
    auto fail = [&](const std::string& m) { throw InputError("--resume: '" + path + "': " + m); };
    std::string line, kept;
    std::vector<std::pair<int, double>> steps;
    if (!std::getline(is, line) || line != kSweepHeader)
        fail(line.find("stress_path,K,K_affine,") != std::string::npos
                 ? "line 1 is the header of an earlier fibernet's sweep (columns K, K_affine, since renamed dsdgamma, "
                   "dsdgamma_affine): start the sweep again"
                 : "line 1 is not the sweep's CSV header");
    kept = line + "\n";
    for (int n = 0; n < rows; ++n) {
        if (!std::getline(is, line))
            fail("has " + std::to_string(n) + " rows, fewer than the checkpoint's " + std::to_string(rows));
        std::istringstream fields(line);
        std::vector<std::string> f;
        for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
        const std::string row = "row " + std::to_string(n + 1);
        if (f.size() != kColumns)
            fail(row + " has " + std::to_string(f.size()) + " fields, expected " + std::to_string(kColumns));
        if (f[0] != std::to_string(n)) fail(row + " is step '" + f[0] + "', expected " + std::to_string(n));
        double v = 0, gamma = 0;
        for (size_t k = 1; k < f.size(); ++k)  // every value the sweep writes is a finite number
            if (!parse_decimal(f[k], k == 1 ? gamma : v))
                fail(row + " field " + std::to_string(k + 1) + " is '" + f[k] + "', not a number the sweep writes");
        // The strains run from 0 (step 0) toward t, each beyond the last and short of t but the last row's, which is t
        // (below): a damaged row in the middle is refused.
        const double last = steps.empty() ? 0 : steps.back().second;
        const bool in_order = n == 0 ? gamma == 0 : t > 0 ? gamma > last && gamma < t : gamma < last && gamma > t;
        if (n + 1 < rows && !in_order)
            fail(row + " has gamma '" + f[1] + "', out of the sweep's order from 0 to the checkpoint's t = " + show(t));
        if (n + 1 == rows && gamma != t)  // 17 digits: the value round-trips exactly
            fail("row " + std::to_string(rows) + " has gamma '" + f[1] + "', the checkpoint's t = " + show(t));
        kept += line + "\n";
        steps.push_back({n, gamma});
    }
    write_file_atomic(path, kept);
    return steps;
}
}  // namespace

void register_sweep(CLI::App& app) {
    auto* cmd = app.add_subcommand("sweep", "quasistatic strain sweep: CSV row per step, checkpoint, --resume");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, true);
    auto p = std::make_shared<SweepParams>();
    auto out = std::make_shared<std::string>();
    auto ckpt = std::make_shared<std::string>();
    auto resume = std::make_shared<bool>(false);
    auto quiet = std::make_shared<bool>(false);
    auto vtk = std::make_shared<std::string>();
    cmd->add_option("--gamma-max", p->t_max, "final strain (negative: compression)")->required();
    cmd->add_option("--step", p->step, "first step (default 0.01)");
    cmd->add_option("--min-step", p->min_step, "smallest step before giving up (default 1e-6)");
    cmd->add_option("--max-step", p->max_step, "largest step (default 0.05)");
    cmd->add_option("-o,--output", *out, "CSV file, one row per accepted step (an existing one is replaced, unless --resume)")
        ->required();
    cmd->add_option("--checkpoint", *ckpt,
                    "checkpoint file (default OUTPUT.ckpt); one of an interrupted or failed sweep needs --resume");
    cmd->add_flag("--resume", *resume, "continue an interrupted sweep from its checkpoint (same parameters only)");
    cmd->add_flag("-q,--quiet", *quiet, "no progress lines on stderr");
    cmd->add_option("--vtk", *vtk, "also write each step's state to DIR/step_<n>.vtp and the series to DIR/series.pvd "
                                   "(ParaView; docs/formats.md)");
    // A sweep's strain comes from --gamma-max: hide the scene flag --gamma (kept registered, so that giving it
    // still gets the message below rather than CLI11's "not expected").
    cmd->get_option("--gamma")->group("");
    cmd->footer("Like `fibernet percolation --out`, the checkpoint of an unfinished sweep is refused without --resume "
                "(its sweep would be lost); a completed sweep, or an existing CSV without a checkpoint, is replaced.");
    cmd->callback([=] {
        stop_requested() = false;  // a fresh run (fibernet scan runs sweeps one after another in one process)
        Scene s = flags->resolve();
        if (flags->given("--gamma")) throw InputError("command line: sweep takes --gamma-max, not --gamma");
        p->kind = s.strain;
        p->check("command line");
        if (ckpt->empty()) *ckpt = *out + ".ckpt";
        check_outputs({{"-o", *out}, {"--checkpoint", *ckpt}, {"-o (sidecar)", *out + ".json"}});
        std::error_code ec;
        if (!*resume && std::filesystem::is_regular_file(*ckpt, ec) && !completed_checkpoint(*ckpt))
            throw InputError("command line: --checkpoint '" + *ckpt +
                             "' exists (an interrupted or failed sweep); add --resume to continue it with the same "
                             "parameters, or remove it");
        const nlohmann::json params = sweep_parameters(s, *p);
        Checkpoint c;
        if (*resume) c = read_checkpoint(*ckpt, params, *p);  // before any work: a mismatch costs nothing
        const SolverOptions so = dry_solver_options(s);
        auto solver = make_solver(s.solver.name, so);
        SolverOptions so_snap = so;  // the snap-through budget at the smallest step (docs/sweep.md)
        so_snap.max_iter = 10 * so.max_iter;
        auto snap = make_solver(s.solver.name, so_snap);
        Network net = scene_network(s);
        Model m = discretize(net, s.discretization);
        NetworkEnergy e(m);

        int rows = 0;
        const SweepState& start = c.state;
        VtkSeries series(*vtk);
        if (*resume) {
            if (c.dofs != e.num_dofs())
                throw InputError(*ckpt + ": dofs = " + std::to_string(c.dofs) + " differs from this model's " +
                                 std::to_string(e.num_dofs()));
            rows = c.rows;
            const auto kept = truncate_csv(*out, rows, start.t);
            if (series.on()) series.open(rows - 1, kept);
            if (!*quiet)
                std::cerr << (c.completed ? "sweep: the checkpoint's sweep is complete; nothing to add\n"
                                          : "sweep: resuming at step " + std::to_string(start.step) + ", gamma = " +
                                                show(start.t) + "\n");
        } else {
            if (series.on()) series.open(-1, {});
            write_file_atomic(*out, std::string(kSweepHeader) + "\n");
            write_csv_sidecar(*out, params, column_docs());
            std::remove(ckpt->c_str());  // a completed sweep's checkpoint must not outlive a new run that fails early
        }
        std::ofstream csv(*out, std::ios::app);
        if (!csv) throw InputError("cannot append to '" + *out + "'");
        SweepCallbacks cb;
        cb.stop = &stop_requested();
        SweepState last = start;
        nlohmann::json last_step = nullptr;  // the last row written by this run, for summaries (fibernet scan)
        const StepLines lines(start.t, p->t_max);
        cb.on_step = [&](const SweepRow& r, const SweepState& st) {
            last_step = {{"step", r.step},       {"gamma", r.t},          {"sigma_xx", r.sigma(0, 0)},
                         {"sigma_xy", r.sigma(0, 1)}, {"sigma_yy", r.sigma(1, 1)}, {"stress_path", r.stress_path},
                         {"dsdgamma", r.K},      {"dsdgamma_affine", r.K_affine}, {"energy", r.energy}};
            csv << csv_row(r) << '\n' << std::flush;
            if (!csv) throw OutputError("cannot append step " + std::to_string(r.step) + " to '" + *out + "'");
            if (series.on())
                series.add(r.step, r.t, e, st.q, deformation(p->kind, r.t),
                           {{}, {{"gamma", r.t}, {"stress_path", r.stress_path}, {"dsdgamma", r.K}, {"energy", r.energy}},
                            {}, {}});
            write_checkpoint(*ckpt, params, ++rows, st);
            last = st;
            if (!*quiet) lines.step(r);
        };
        // Ctrl-C and SIGTERM end the sweep after the step in progress, unless the caller ignores them (a background
        // job of a script inherits SIGINT ignored): that disposition is kept.
        SweepOutcome o;
        {
            const SignalScope signals(on_signal);
            o = run_sweep(e, *p, *solver, cb, *resume ? &start : nullptr, snap.get());
        }
        if (o.completed && rows > 0) write_checkpoint(*ckpt, params, rows, last, true);
        // A sweep that failed before its first row (the reference state's linear response) leaves no files: a CSV
        // of its header alone would read as a sweep with no steps.
        if (rows == 0) std::remove(out->c_str()), std::remove((*out + ".json").c_str());
        emit_json({{"status", o.completed ? "completed" : o.interrupted ? "interrupted" : "failed"},
                   {"message", o.message},
                   {"rows", rows},
                   {"output", rows > 0 ? nlohmann::json(*out) : nlohmann::json()},
                   {"checkpoint", rows > 0 ? nlohmann::json(*ckpt) : nlohmann::json()},
                   {"last_step", last_step},
                   {"model", to_json(summarize(m))}});
        if (o.interrupted) exit_code() = 130;
        else if (!o.completed) exit_code() = 1;
    });
}

}  // namespace fibernet::cli
