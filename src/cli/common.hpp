#pragma once
// Shared pieces of the `fibernet` subcommands: the scene flags every command accepts, JSON output, output files.
#include <CLI/CLI.hpp>
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fibernet/model/model.hpp"
#include "fibernet/network/network.hpp"
#include "fibernet/scene/scene.hpp"

namespace fibernet::cli {

// Flags that set or override a scene: a positional scene file, network generation, discretization, load.
struct SceneFlags {
    std::string scene_file, network_file;
    double L = 0, q = 0, pl = 0, h = 0, a = 0, gamma = 0, tol = 0;
    std::uint64_t seed = 0;
    int n_seg = 0, max_iter = 0;
    bool open = false;
    std::string scheme, strain, solver;
    std::vector<std::string> prune;
    std::vector<CLI::Option*> opts;

    // with_load: also --gamma/--strain/--solver/--tol/--max-iter.
    void add(CLI::App* app, bool with_load);
    bool given(const std::string& name) const;
    Scene resolve() const;  // scene file (or defaults) overridden by the flags given
};

// Commands whose physics acts on fiber end arms (bridges, clamps, rods) refuse `prune ends` with an InputError.
void refuse_trimmed_ends(const Scene& s, const std::string& command, const std::string& why);

nlohmann::json to_json(const NetworkStats& s);
nlohmann::json prune_rules(const Scene& s);  // the pruning rules applied, e.g. ["dangling", "ends"]
// What generates the scene's network and model: L, q, pl, seed, periodic (or the network file), scheme, n_seg, h, a.
nlohmann::json scene_parameters(const Scene& s);
nlohmann::json to_json(const ModelSummary& s);

// Prints JSON to stdout (or to `path` atomically when non-empty).
void emit_json(const nlohmann::json& j, const std::string& path = "");

double seconds_since(const std::chrono::steady_clock::time_point& t0);

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

}  // namespace fibernet::cli
