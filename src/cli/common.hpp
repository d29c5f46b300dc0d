#pragma once
// Shared pieces of the `fibernet` subcommands: the scene flags every command accepts, JSON output, output files.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <csignal>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/model.hpp"
#include "fibernet/network/network.hpp"
#include "fibernet/scene/scene.hpp"
#include "fibernet/solve/result.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/util/stopwatch.hpp"

namespace fibernet::cli {

// Flags that set or override a scene: a positional scene file and the flags of the scene options
// (fibernet/scene/scene_options.hpp, where each is declared once), plus --prune.
struct SceneFlags {
    std::string scene_file;
    std::map<std::string, std::string> values;  // a flag's text, by flag ("--L")
    std::map<std::string, bool> switches;       // a Boolean option's flag (--open, --free-box)
    std::vector<std::string> prune;
    std::vector<CLI::Option*> opts;

    // with_load: also [load] and [solver] (--gamma, --strain, --solver, --tol, --max-iter); with_wet: [wet]'s flags.
    void add(CLI::App* app, bool with_load, bool with_wet = false);
    bool given(const std::string& name) const;
    // The scene file (or defaults) overridden by the flags given, checked (Scene::check); complete = false leaves the
    // combined check to a command that changes more (fibernet wet's thesis default pl), which then calls Scene::check.
    Scene resolve(bool complete = true) const;
};

// Progress lines on stderr for a one-shot command ("modulus: 96 fibers, 2480 DOF; ..."), off with --quiet.
class Progress {
public:
    Progress(std::string command, bool on) : command_(std::move(command)), on_(on) {}
    void start(const Network& net, const NetworkEnergy& e, const Scene& s) const;  // what is solved, and at what load
    void solved(const SolveResult& r) const;                                       // the equilibrium's outcome
    void line(const std::string& what, const std::chrono::steady_clock::time_point& t0) const;  // "<what>, 1.2 s"

private:
    std::string command_;
    bool on_;
};

// Checks every output path (flag, path; empty paths skipped) before any work, so that bad input costs nothing and
// leaves nothing: each must be writable and no file may be named twice. Throws InputError naming the flag.
void check_outputs(const std::vector<std::pair<std::string, std::string>>& outputs);

// A seed option's check: CLI11 wraps "-1" and saturates values past 2^64 - 1 into a uint64; digits in range only.
CLI::Validator seed_check();

// Commands that need an open box (clamps) refuse a periodic network; the message says what to change: --open for a
// generated network, or that the network file's box is periodic.
void refuse_periodic(const Scene& s, const Network& net, const std::string& needs);

// Commands whose physics acts on fiber end arms (bridges, clamps, rods) refuse `prune ends` with an InputError.
void refuse_trimmed_ends(const Scene& s, const std::string& command, const std::string& why);
// The dry solves' solver options (relax, modulus, sweep) from the scene's [solver] table.
SolverOptions dry_solver_options(const Scene& s);

nlohmann::json to_json(const NetworkStats& s);
nlohmann::json prune_rules(const Scene& s);  // the pruning rules applied, e.g. ["dangling", "ends"]
// What generates the scene's network and model: L, q, pl, seed, periodic (or the network file), scheme, n_seg, h, a.
nlohmann::json scene_parameters(const Scene& s);
nlohmann::json to_json(const ModelSummary& s);

// A number as fibernet writes it into its CSVs (decimal digits, sign, point, exponent; no nan, inf or hex), parsed
// whole: false for anything else (a mangled row read back on --resume).
bool parse_decimal(const std::string& text, double& v);
// JSON text (indent -1: one line); bytes that are not UTF-8 become U+FFFD instead of an exception.
std::string json_text(const nlohmann::json& j, int indent = -1);
// Prints JSON to stdout (or to `path` atomically when non-empty). While json_capture() points at a JSON value,
// what would go to stdout is stored there instead (fibernet scan runs a command per sample in its own process).
// A JSON object gets a "provenance" member: the command line as a shell reruns it, fibernet's version and commit, the
// units, and the whole scene the command resolved (scene_toml: `fibernet <command> that.toml` computes it again).
void emit_json(const nlohmann::json& j, const std::string& path = "");
// The scene a command computes, for the provenance of what it emits (SceneFlags::resolve records it; a command that
// changes the scene after resolving records it again).
void record_scene(const Scene& s);
void forget_scene();  // before a command runs in process after another
nlohmann::json provenance();
// CSV.json beside a CSV: what each column means and its unit, the parameters that determine the rows, provenance.
void write_csv_sidecar(const std::string& csv, const nlohmann::json& parameters, const nlohmann::json& columns);
nlohmann::json units_json();
nlohmann::json*& json_capture();
bool& capture_provenance();  // whether captured JSON gets its provenance too (the Python package: yes; scan: no)
// Flushes standard output; OutputError (exit 4) when it cannot be written.
void flush_stdout();
// The bytes of a file a result depends on (a network file, a law table), e.g. for its fingerprint (util/hash.hpp);
// InputError naming `what` and the path if it cannot be read.
std::string file_bytes(const std::string& path, const std::string& what);

// A progress line of a long command (sweep steps, wet betas): to stderr, or to the sink when one is set (the Python
// package's progress callback).
void progress_line(const std::string& line);
// Set to stop a long command after its step in progress (a sweep checks it): SIGINT/SIGTERM handlers and the Python
// package's progress callback set it; a command clears it when it starts.
std::atomic<bool>& stop_requested();
std::function<void(const std::string&)>& progress_sink();

// The command line as given (without the program name), set by main: recorded in results for provenance.
std::vector<std::string>& command_argv();
// A word of a command line as a POSIX shell reads it back (quoted where it needs to be).
std::string shell_quoted(const std::string& w);

// SIGINT and SIGTERM go to `handler` for the scope's life, unless the process started with one ignored (a shell
// script's background job gets SIGINT so: Ctrl-C meant for the script must not stop it); the previous
// dispositions come back at the end. Used by sweep and scan (wet has its own: it exits on SIGTERM whatever).
class SignalScope {
public:
    explicit SignalScope(void (*handler)(int));
    ~SignalScope();
    SignalScope(const SignalScope&) = delete;
    SignalScope& operator=(const SignalScope&) = delete;

private:
    struct sigaction old_int_ {}, old_term_ {};
};

// Process exit code a command sets when its computation did not succeed (1); main returns it.
int& exit_code();

using Registrar = std::function<void(CLI::App&)>;
// Each subcommand file defines one registrar (see main.cpp).
void register_generate(CLI::App& app);
void register_export(CLI::App& app);
void register_info(CLI::App& app);
void register_rigidity(CLI::App& app);
void register_compare(CLI::App& app);
void register_percolation(CLI::App& app);
void register_modulus(CLI::App& app);
void register_relax(CLI::App& app);
void register_wet(CLI::App& app);
void register_sweep(CLI::App& app);
void register_scan(CLI::App& app);

}  // namespace fibernet::cli
