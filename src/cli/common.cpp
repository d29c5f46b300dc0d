#include "common.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "fibernet/network/network_io.hpp"
#include "fibernet/scene/scene_options.hpp"
#include "fibernet/scene/scene_toml.hpp"
#include "fibernet/solve/solver_registry.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet_version.hpp"

namespace fibernet::cli {

void Progress::start(const Network& net, const NetworkEnergy& e, const Scene& s) const {
    if (!on_) return;
    std::fprintf(stderr, "%s: %zu fibers, %d unknowns; equilibrium at %s gamma = %g (%s) ...\n", command_.c_str(),
                 net.fibers.size(), e.num_dofs(), to_string(s.strain).c_str(), s.gamma, s.solver.name.c_str());
}

void Progress::solved(const SolveResult& r) const {
    if (!on_) return;
    std::fprintf(stderr, "%s: equilibrium %s after %d iterations (max|g| %.2e), %.2f s\n", command_.c_str(),
                 to_string(r.status).c_str(), r.iterations, r.grad_max, r.timings.total);
}

void Progress::line(const std::string& what, const std::chrono::steady_clock::time_point& t0) const {
    if (on_) std::fprintf(stderr, "%s: %s, %.2f s in all\n", command_.c_str(), what.c_str(), seconds_since(t0));
}

// Not an existing path of another kind (a device such as /dev/null is fine), a regular file that
// can be opened for writing, a directory that lets us create the file (or the temporary renamed over it), and no
// file named twice (the later write would destroy the earlier one; path.tmp is write_file_atomic's temporary).
void check_outputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
    namespace fs = std::filesystem;
    std::vector<std::pair<std::string, fs::path>> files;  // flag, absolute path of each regular (or new) file
    for (const auto& [flag, path] : outputs) {
        if (path.empty()) continue;
        const std::string what = "command line: " + flag + " '" + path + "'";
        struct stat st;
        if (stat(path.c_str(), &st) == 0) {
            if (S_ISDIR(st.st_mode)) throw InputError(what + " is a directory");
            if (!S_ISREG(st.st_mode)) {
                if (access(path.c_str(), W_OK) != 0) throw InputError(what + " cannot be written (" + std::strerror(errno) + ")");
                continue;
            }
            const int fd = open(path.c_str(), O_WRONLY | O_CLOEXEC);  // no O_TRUNC: the file stays as it is
            if (fd < 0) throw InputError(what + " cannot be opened for writing (" + std::strerror(errno) + ")");
            close(fd);
        }
        std::error_code ec;
        const fs::path abs = fs::weakly_canonical(fs::absolute(path), ec);
        const fs::path p = ec ? fs::absolute(path).lexically_normal() : abs;
        for (const auto& [other_flag, q] : files) {
            if (p == q) throw InputError(what + " is also given as " + other_flag + ": give each output its own path");
            if (p.string() == q.string() + ".tmp" || p.string() + ".tmp" == q.string())
                throw InputError(what + " and " + other_flag + " are a file and its temporary '.tmp': give each "
                                 "output its own path");
        }
        files.push_back({flag, p});
        // The probe where write_file_atomic puts its temporary: beside the path as given (a symlinked file's own
        // directory, not its target's).
        const fs::path dir = fs::absolute(path).parent_path();
        std::string probe = (dir / ".fibernet-probe-XXXXXX").string();
        const int fd = mkstemp(probe.data());
        if (fd < 0)
            throw InputError(what + ": cannot create a file in directory '" + dir.string() + "' (" +
                             std::strerror(errno) + ")");
        close(fd);
        unlink(probe.c_str());
    }
}

CLI::Validator seed_check() {
    return CLI::Validator(
        [](std::string& v) {
            std::uint64_t x = 0;
            const char* end = v.data() + v.size();
            const auto r = std::from_chars(v.data(), end, x);
            return r.ec == std::errc() && r.ptr == end ? std::string() : "seed " + v + " is not an integer in [0, 2^64)";
        },
        "SEED");
}

void SceneFlags::add(CLI::App* app, bool with_load, bool with_wet) {
    opts.push_back(app->add_option("scene", scene_file, "scene file (TOML, see docs/formats.md); flags override it")
                       ->check(CLI::ExistingFile));
    const Scene defaults;
    for (const SceneOption& o : scene_options()) {
        if (o.flag.empty()) continue;
        if ((o.table == "load" || o.table == "solver") && !with_load) continue;
        if (o.table == "wet" && !with_wet) continue;
        std::string doc = o.doc;
        const std::string shown = o.literal(defaults);  // no default shown for a switch or an empty text
        if (o.kind != OptionKind::Boolean && shown != "\"\"") doc += " (default " + shown + ")";
        const std::string names = o.negation.empty() ? o.flag : o.flag + ",!" + o.negation;
        CLI::Option* cli = o.kind == OptionKind::Boolean ? app->add_flag(names, switches[o.flag], doc)
                                                         : app->add_option(o.flag, values[o.flag], doc);
        if (o.kind == OptionKind::Real) cli->type_name("NUMBER");
        if (o.kind == OptionKind::Integer) cli->type_name("INT");
        if (o.kind == OptionKind::Choice) cli->type_name("WORD");
        if (o.kind == OptionKind::Seed) cli->check(seed_check());
        if (o.existing_file) cli->check(CLI::ExistingFile);
        opts.push_back(cli);
        if (o.key == "a")  // --prune after the model's flags, as in a scene's [model]
            opts.push_back(app->add_option("--prune", prune,
                                           "drop load-free parts: dangling, nonspanning, ends (docs/moduli.md)"));
    }
}

bool SceneFlags::given(const std::string& name) const {
    for (auto* o : opts)
        if (o->check_name(name)) return o->count() > 0;
    return false;
}

Scene SceneFlags::resolve(bool complete) const {
    Scene s = scene_file.empty() ? Scene{} : load_scene(scene_file);
    const std::string who = "command line";
    bool flags = false;
    for (const SceneOption& o : scene_options()) {
        if (o.flag.empty() || !given(o.flag)) continue;
        flags = true;
        if (o.kind == OptionKind::Boolean) o.boolean(s) = o.flag_sets_false ? !switches.at(o.flag) : switches.at(o.flag);
        else o.set_from_text(s, values.at(o.flag), who);
    }
    if (given("--prune")) {
        flags = true;
        for (const auto& p : prune) {
            if (p == "dangling") s.prune.dangling = true;
            else if (p == "nonspanning") s.prune.nonspanning = true;
            else if (p == "ends") s.discretization.trim_ends = true;
            else throw InputError("command line: --prune " + p + " is unknown (expected dangling, nonspanning or ends)");
        }
    }
    if (flags) s.source = scene_file.empty() ? who : scene_file + " with command-line overrides";
    // A saved network brings its own box and fibers: generation flags would be silently ignored.
    if (!s.network_file.empty())
        for (const char* g : {"--L", "--q", "--pl", "--seed", "--open"})
            if (given(g))
                throw InputError(std::string("command line: ") + g + " has no effect on a saved network ('" +
                                 s.network_file + "' gives the box and the fibers); remove " + g);
    // Asked for by name, elimination must act (a scene file's key, on by default, is ignored by solvers without it).
    if (given("--eliminate") && s.solver.eliminate && !solver_capabilities(s.solver.name).eliminate)
        throw InputError("command line: --eliminate needs a solver with nonlinear elimination (newton); solver is '" +
                         s.solver.name + "'");
    if (complete) s.check(), record_scene(s);
    else s.check_values();
    return s;
}

SolverOptions dry_solver_options(const Scene& s) {
    SolverOptions so;
    so.tol = s.solver.tol, so.max_iter = s.solver.max_iter, so.eliminate = s.solver.eliminate;
    so.median_floor = true;  // docs/solvers.md "Newton's shift floor"
    return so;
}

nlohmann::json to_json(const NetworkStats& s) {
    return {{"fibers", s.fibers},
            {"crossings", s.crossings},
            {"crosslinks", s.crosslinks},
            {"crossings_per_fiber", s.crossings_per_fiber},
            {"crosslinks_per_fiber", s.crosslinks_per_fiber},
            {"components", s.components},
            {"largest_component", s.largest_component}};
}

nlohmann::json to_json(const ModelSummary& s) {
    return {{"nodes", s.nodes},           {"dofs", s.dofs},
            {"segments", s.segments},     {"hinges", s.hinges},
            {"supernodes", s.supernodes}, {"fibers", s.fibers},
            {"shortest_segment", s.shortest_segment}, {"longest_segment", s.longest_segment},
            {"mean_segment", s.mean_segment}};
}

std::string file_bytes(const std::string& path, const std::string& what) {
    std::ifstream is(path, std::ios::binary);
    std::ostringstream os;
    if (!is || !(os << is.rdbuf())) throw InputError(what + " '" + path + "' cannot be read");
    return os.str();
}

bool parse_decimal(const std::string& text, double& v) {
    if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
    char* end = nullptr;
    v = std::strtod(text.c_str(), &end);
    return !*end && std::isfinite(v);
}

std::string json_text(const nlohmann::json& j, int indent) {
    // Strings that are not UTF-8 (a Latin-1 file name) are written with U+FFFD in their place, not refused.
    return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

nlohmann::json*& json_capture() {
    static nlohmann::json* capture = nullptr;
    return capture;
}

bool& capture_provenance() {
    static bool with = false;
    return with;
}

namespace {
std::optional<std::string>& recorded_scene() {
    static std::optional<std::string> toml;
    return toml;
}

}  // namespace

std::string shell_quoted(const std::string& w) {
    if (!w.empty() && w.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=/.,:@%") ==
                          std::string::npos)
        return w;
    std::string q = "'";
    for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

void forget_scene() { recorded_scene().reset(); }

void record_scene(const Scene& s) {
    // A scan's sample: the scan records its own scenes.
    if (!json_capture() || capture_provenance()) recorded_scene() = to_toml(s);
}

nlohmann::json units_json() {
    return {{"length", "seed unit ls = lf / 10 (a fiber has length fiber_length = 10; network files use lf)"},
            {"energy", "bending energy of a unit length bent to unit curvature (kappa / ls)"},
            {"stress", "energy / length^2 (2D: force per unit length)"},
            {"modulus", "energy / length^2 (2D), as stress"},
            {"angle", "rad"},
            {"time", "s (wall clock)"}};
}

nlohmann::json provenance() {
    std::string line = "fibernet";
    for (const auto& w : command_argv()) line += " " + shell_quoted(w);
    nlohmann::json p = {{"command", line},
                        {"fibernet", {{"version", FIBERNET_VERSION}, {"commit", FIBERNET_GIT_COMMIT}}},
                        {"units", units_json()}};
    if (recorded_scene()) p["scene_toml"] = *recorded_scene();
    return p;
}

void write_csv_sidecar(const std::string& csv, const nlohmann::json& parameters, const nlohmann::json& columns) {
    const nlohmann::json side = {{"table", csv},
                                 {"format", "CSV with a header row; numbers with 17 significant digits"},
                                 {"columns", columns},
                                 {"parameters", parameters},
                                 {"provenance", provenance()}};
    write_file_atomic(csv + ".json", json_text(side, 2) + "\n");
}

void emit_json(const nlohmann::json& j, const std::string& path) {
    nlohmann::json out = j;
    const bool captured = path.empty() && json_capture();
    // A scan's sample leaves the provenance to the scan's manifest.
    if (out.is_object() && !out.contains("provenance") && (!captured || capture_provenance()))
        out["provenance"] = provenance();
    if (captured) {
        *json_capture() = std::move(out);
        return;
    }
    const std::string text = json_text(out, 2) + "\n";
    if (path.empty()) std::cout << text, flush_stdout();
    else write_file_atomic(path, text);
}

void flush_stdout() {
    errno = 0;
    std::cout.flush();
    if (!std::cout || std::fflush(stdout) != 0)
        throw OutputError(std::string("cannot write the results to standard output (") +
                          (errno ? std::strerror(errno) : "the write failed") + ")");
}

SignalScope::SignalScope(void (*handler)(int)) {
    struct sigaction sa {};
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, nullptr, &old_int_);
    sigaction(SIGTERM, nullptr, &old_term_);
    if (old_int_.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, nullptr);
    if (old_term_.sa_handler != SIG_IGN) sigaction(SIGTERM, &sa, nullptr);
}

SignalScope::~SignalScope() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
}

std::function<void(const std::string&)>& progress_sink() {
    static std::function<void(const std::string&)> sink;
    return sink;
}

std::atomic<bool>& stop_requested() {
    static std::atomic<bool> stop{false};
    return stop;
}

void progress_line(const std::string& line) {
    if (progress_sink()) progress_sink()(line);
    else std::cerr << line << "\n";
}

std::vector<std::string>& command_argv() {
    static std::vector<std::string> argv;
    return argv;
}

int& exit_code() {
    static int code = 0;
    return code;
}

nlohmann::json prune_rules(const Scene& s) {
    nlohmann::json j = nlohmann::json::array();
    if (s.prune.dangling) j.push_back("dangling");
    if (s.prune.nonspanning) j.push_back("nonspanning");
    if (s.discretization.trim_ends) j.push_back("ends");
    return j;
}

nlohmann::json scene_parameters(const Scene& s) {
    nlohmann::json j = s.network_file.empty()
                           ? nlohmann::json{{"L", s.mikado.L}, {"q", s.mikado.q}, {"pl", s.mikado.pl},
                                            {"seed", s.mikado.seed}, {"periodic", s.mikado.periodic}}
                           : nlohmann::json{{"network_file", s.network_file}};
    j["scheme"] = to_string(s.discretization.scheme);
    j["n_seg"] = s.discretization.n_seg, j["h"] = s.discretization.h, j["a"] = s.discretization.aspect_ratio;
    return j;
}

void refuse_periodic(const Scene& s, const Network& net, const std::string& needs) {
    if (!net.periodic) return;
    throw InputError(s.source + ": the box is periodic; " + needs + " (" +
                     (s.network_file.empty() ? std::string("add --open")
                                             : "the network file '" + s.network_file + "' has a periodic box") +
                     ")");
}

void refuse_trimmed_ends(const Scene& s, const std::string& command, const std::string& why) {
    if (s.discretization.trim_ends)
        throw InputError(s.source + ": prune \"ends\" is not valid for `fibernet " + command + "`: " + why);
}

}  // namespace fibernet::cli
