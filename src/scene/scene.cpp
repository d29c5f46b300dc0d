#include "fibernet/scene/scene.hpp"

#include <array>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "fibernet/energy/capillary.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/scene/scene_options.hpp"
#include "fibernet/solve/solver_registry.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

void Scene::check() const {
    check_values();
    // Combinations, checked once command-line overrides are in (a scene's uniaxial gamma = -2 run with --strain shear
    // is a valid load). Every path's F = I + gamma dF is upper triangular: the box keeps its orientation iff both
    // diagonal entries stay positive (det F > 0 alone lets isotropic gamma = -3, F = -2 I, a half turn, through).
    const Eigen::Matrix2d F = deformation(strain, gamma);
    check_value(F(0, 0) > 0 && F(1, 1) > 0, gamma, source, "gamma",
                "flips or collapses the box on the " + to_string(strain) + " path (need gamma > -1)");
    if (wet.crossings != "fraction" && wet.fraction != 1)  // else silently ignored, yet reported in the summary
        throw InputError(source + ": [wet].fraction = " + show(wet.fraction) + " is used only with crossings = "
                         "fraction (crossings is '" + wet.crossings + "')");
    if (wet.crossings != "fraction" && wet.seed != 1)  // the seed of that draw, likewise (--wet-seed)
        throw InputError(source + ": [wet].seed = " + std::to_string(wet.seed) + " is used only with crossings = "
                         "fraction (crossings is '" + wet.crossings + "')");
    solver_entry(solver.name);  // an unknown solver is named here
    // The wet relaxation's elimination would otherwise be silently ignored by the solver.
    if (wet.newton_eliminate && !solver_capabilities(solver.name).eliminate)
        throw InputError(source + ": [wet].newton_eliminate = true needs a solver with nonlinear elimination (newton); "
                         "solver is '" + solver.name + "'");
    if (wet.schwarz_block > 0 && !solver_capabilities(solver.name).eliminate)
        throw InputError(source + ": [wet].schwarz_block = " + std::to_string(wet.schwarz_block) +
                         " needs a solver with nonlinear elimination (newton); solver is '" + solver.name + "'");
    check_beta(wet.beta, source, "[wet].beta");
    // The law file last: a --law flag replaces the scene's before any file is opened.
    if (!wet.law.empty()) {
        try {
            CapillaryLaw::read(wet.law);  // a malformed table names its file and row
        } catch (const InputError& e) {
            throw InputError(source + ": [wet].law: " + e.what());
        }
    }
}

void Scene::check_beta(double beta, const std::string& where, const std::string& name) const {
    const double stretch = 4 * discretization.aspect_ratio * discretization.aspect_ratio;
    check_value(beta >= 0, beta, where, name, "must be >= 0");
    check_value(beta <= kMaxBetaOverStretch * stretch, beta, where, name,
                "exceeds the stretching stiffness 4 a^2 = " + show(stretch) + " (a = " + show(discretization.aspect_ratio) +
                    "): capillary forces would crush the fibers axially, outside the model");
}

void Scene::check_values() const {
    if (network_file.empty()) mikado.check(source);
    discretization.check(source);
    check_value(true, gamma, source, "gamma", "");
    check_value(solver.tol > 0, solver.tol, source, "solver.tol", "must be > 0");
    check_value(solver.max_iter >= 1, solver.max_iter, source, "solver.max_iter", "must be >= 1");
    check_value(wet.beta >= 0, wet.beta, source, "[wet].beta", "must be >= 0");
    check_value(wet.fraction >= 0 && wet.fraction <= 1, wet.fraction, source, "[wet].fraction", "must lie in [0, 1]");
    if (wet.crossings != "all" && wet.crossings != "free" && wet.crossings != "fraction")
        throw InputError(source + ": [wet].crossings = '" + wet.crossings + "' is unknown (expected all, free or fraction)");
    check_value(wet.free_box_tol > 0, wet.free_box_tol, source, "[wet].free_box_tol", "must be > 0");
    check_value(wet.max_rounds >= 1, wet.max_rounds, source, "[wet].max_rounds", "must be >= 1");
    check_value(wet.round_iterations >= 0, wet.round_iterations, source, "[wet].round_iterations", "must be >= 0");
    check_value(wet.local_fraction >= 0 && wet.local_fraction <= 1, wet.local_fraction, source, "[wet].local_fraction",
                "must lie in [0, 1]");
    check_value(wet.local_threshold > 0 && wet.local_threshold < 1, wet.local_threshold, source, "[wet].local_threshold",
                "must lie in (0, 1)");
    check_value(wet.eliminate_hops >= 0, wet.eliminate_hops, source, "[wet].eliminate_hops", "must be >= 0");
    check_value(wet.schwarz_block >= 0, wet.schwarz_block, source, "[wet].schwarz_block", "must be >= 0 (0: off)");
    check_value(wet.schwarz_overlap >= 0, wet.schwarz_overlap, source, "[wet].schwarz_overlap", "must be >= 0");
    check_value(wet.local_hops >= 0, wet.local_hops, source, "[wet].local_hops", "must be >= 0");
    check_value(wet.bundle_partners >= 0, wet.bundle_partners, source, "[wet].bundle_partners", "must be >= 0 (0: no cap)");
    if (wet.model != "events" && wet.model != "smooth")
        throw InputError(source + ": [wet].model = '" + wet.model + "' is unknown (expected events or smooth)");
    check_value(std::isfinite(wet.crossing_width) && wet.crossing_width >= 0, wet.crossing_width, source,
                "[wet].crossing_width", "must be >= 0 (0: the fiber radius)");
    check_value(std::isfinite(wet.contact_distance) && wet.contact_distance >= 0, wet.contact_distance, source,
                "[wet].contact_distance", "must be >= 0 (0: the fiber diameter)");
    check_value(std::isfinite(wet.skin) && wet.skin > 0, wet.skin, source, "[wet].skin", "must be > 0");
    check_value(std::isfinite(wet.checkpoint_seconds) && wet.checkpoint_seconds >= 0, wet.checkpoint_seconds, source,
                "[wet].checkpoint_seconds", "must be >= 0 (0: no checkpoints)");
    if (wet.model != "smooth" && !wet.start_state.empty())
        throw InputError(source + ": [wet].start_state = '" + wet.start_state +
                         "' applies to [wet].model = 'smooth' only (the event model's state includes its bridge set)");
    if (wet.model != "smooth" && wet.newton_projected)
        throw InputError(source + ": [wet].newton_projected applies to [wet].model = 'smooth' only");
    if (wet.free_box_shape != "full" && wet.free_box_shape != "isotropic")
        throw InputError(source + ": [wet].free_box_shape = '" + wet.free_box_shape +
                         "' is unknown (expected isotropic or full)");
}

namespace {
std::string type_name(toml::node_type t) {
    switch (t) {
        case toml::node_type::string: return "a string";
        case toml::node_type::integer: return "an integer";
        case toml::node_type::floating_point: return "a float";
        case toml::node_type::boolean: return "a boolean";
        case toml::node_type::array: return "an array";
        case toml::node_type::table: return "a table";
        default: return "a date or time";
    }
}

struct TableReader {
    const toml::table& t;
    std::string where;  // "file: [table]"
    std::set<std::string> known;

    template <class T>
    bool get(const std::string& key, T& out) {
        known.insert(key);
        const toml::node* n = t.get(key);
        if (!n) return false;
        if constexpr (std::is_same_v<T, double>) {
            if (auto v = n->value<double>()) return out = *v, true;
        } else if constexpr (std::is_same_v<T, bool>) {
            if (auto v = n->value_exact<bool>()) return out = *v, true;
        } else if constexpr (std::is_same_v<T, std::string>) {
            if (auto v = n->value_exact<std::string>()) return out = *v, true;
        } else {
            if (auto v = n->value_exact<int64_t>()) {
                // A TOML integer outside T's range would wrap silently (max_iter = 2^32 + 2 ran 2 iterations).
                if (*v < static_cast<int64_t>(std::numeric_limits<T>::min()) ||
                    (std::numeric_limits<T>::max() < std::numeric_limits<int64_t>::max() &&
                     *v > static_cast<int64_t>(std::numeric_limits<T>::max())))
                    throw InputError(where + "." + key + " = " + std::to_string(*v) + " is out of range [" +
                                     std::to_string(std::numeric_limits<T>::min()) + ", " +
                                     std::to_string(std::numeric_limits<T>::max()) + "]");
                return out = static_cast<T>(*v), true;
            }
        }
        throw InputError(where + "." + key + " has the wrong type (" + type_name(n->type()) + ")");
    }
    // A random seed: a non-negative TOML integer.
    void get_seed(const std::string& key, std::uint64_t& out) {
        int64_t v = 0;
        if (!get(key, v)) return;
        if (v < 0) throw InputError(where + "." + key + " = " + std::to_string(v) + " must be >= 0");
        out = static_cast<std::uint64_t>(v);
    }
    void finish() const {
        for (const auto& [k, v] : t)
            if (!known.count(std::string(k.str())))
                throw InputError(where + ": unknown key '" + std::string(k.str()) + "'");
    }
};
// One declared option (scene_options.hpp) from its table, if given.
void read_option(TableReader& r, const SceneOption& o, Scene& s) {
    switch (o.kind) {
        case OptionKind::Real: {
            double v = 0;
            if (r.get(o.key, v)) o.real(s) = v;
            return;
        }
        case OptionKind::Integer: {
            int v = 0;
            if (r.get(o.key, v)) o.integer(s) = v;
            return;
        }
        case OptionKind::Seed: r.get_seed(o.key, o.seed(s)); return;
        case OptionKind::Boolean: {
            bool v = false;
            if (r.get(o.key, v)) o.boolean(s) = v;
            return;
        }
        case OptionKind::Text: {
            std::string v;
            if (r.get(o.key, v)) o.text(s) = v;
            return;
        }
        case OptionKind::Choice: {
            std::string v;
            if (!r.get(o.key, v)) return;
            try {
                o.set_choice(s, v);
            } catch (const InputError& e) {
                throw InputError(r.where + "." + o.key + ": " + e.what());
            }
            return;
        }
    }
}

// [model].prune, the one array of a scene.
void read_prune(TableReader& r, Scene& s, const std::string& source) {
    r.known.insert("prune");
    if (auto* arr = r.t.get_as<toml::array>("prune")) {
        for (const auto& el : *arr) {
            auto v = el.value_exact<std::string>();
            if (v && *v == "dangling") s.prune.dangling = true;
            else if (v && *v == "nonspanning") s.prune.nonspanning = true;
            else if (v && *v == "ends") s.discretization.trim_ends = true;
            else throw InputError(source + ": [model].prune has an unknown entry (expected \"dangling\", \"nonspanning\", \"ends\")");
        }
    } else if (r.t.get("prune")) {
        throw InputError(source + ": [model].prune must be an array of strings");
    }
}
}  // namespace

Scene parse_scene(const std::string& text, const std::string& source) {
    Scene s;
    s.source = source;
    toml::table root;
    try {
        root = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        std::ostringstream os;
        os << source << ":" << e.source().begin.line << ": " << e.description();
        throw InputError(os.str());
    }
    static const std::set<std::string> tables = {"network", "model", "load", "solver", "wet"};
    for (const auto& [k, v] : root) {
        if (!tables.count(std::string(k.str())) || !v.is_table())
            throw InputError(source + ": unknown table or key '" + std::string(k.str()) +
                             "' (expected [network], [model], [load], [solver], [wet])");
    }
    auto table = [&](const char* name) -> const toml::table& {
        static const toml::table empty;
        auto* t = root.get_as<toml::table>(name);
        return t ? *t : empty;
    };
    for (const char* name : {"network", "model", "load", "solver", "wet"}) {
        TableReader r{table(name), source + ": [" + name + "]", {}};
        for (const SceneOption& o : scene_options())
            if (o.table == name) read_option(r, o, s);
        if (std::string(name) == "network") {
            std::vector<std::string> generation;  // generation keys given (they have no effect with a file)
            for (const char* k : {"L", "q", "pl", "seed", "periodic"})
                if (r.t.get(k)) generation.push_back(k);
            if (r.t.get("file") && !generation.empty())
                throw InputError(source + ": [network].file = '" + s.network_file + "' is given with [network]." +
                                 generation.front() + ": a saved network brings its own box and fibers (remove one)");
        }
        if (std::string(name) == "model") read_prune(r, s, source);
        r.finish();
    }
    s.check_values();  // the combinations once overrides are in (Scene::check)
    return s;
}

Scene load_scene(const std::string& path) {
    std::ifstream is(path);
    if (!is) throw InputError("scene file '" + path + "' cannot be opened");
    std::stringstream ss;
    ss << is.rdbuf();
    // Another of fibernet's files given where a scene is expected: say what it is and where it goes.
    const std::string text = ss.str();
    const std::string body = text.rfind("\xEF\xBB\xBF", 0) == 0 ? text.substr(3) : text;  // a UTF-8 BOM
    for (const auto& [magic, what] : std::vector<std::array<std::string, 2>>{
             {"fibernet-network", "a network file, not a scene (TOML): give it as --network " + path},
             {"fibernet-model", "a model file (what export and relax write), not a scene (TOML): fibernet export --model " + path +
                                   " exports its state"},
             {"fibernet-sweep-checkpoint", "a sweep checkpoint, not a scene (TOML): continue its sweep with sweep --resume"}})
        if (body.rfind(magic, 0) == 0) throw InputError("'" + path + "' is " + what);
    Scene s = parse_scene(text, path);
    // A network file named in a scene is found next to the scene, wherever it is run from.
    if (!s.network_file.empty() && std::filesystem::path(s.network_file).is_relative())
        s.network_file = (std::filesystem::path(path).parent_path() / s.network_file).string();  // ".." as the OS resolves it
    // So is a law table.
    if (!s.wet.law.empty() && std::filesystem::path(s.wet.law).is_relative())
        s.wet.law = (std::filesystem::path(path).parent_path() / s.wet.law).string();
    if (!s.wet.start_state.empty() && std::filesystem::path(s.wet.start_state).is_relative())
        s.wet.start_state = (std::filesystem::path(path).parent_path() / s.wet.start_state).string();
    if (!s.network_file.empty() && !std::filesystem::is_regular_file(s.network_file))
        throw InputError(path + ": [network].file = '" + s.network_file + "' is not a readable file");
    return s;
}

Network scene_network(const Scene& s) {
    Network net = s.network_file.empty() ? generate_mikado(s.mikado) : load_network(s.network_file);
    if (s.prune.dangling || s.prune.nonspanning) net = prune(net, s.prune);
    return net;
}

}  // namespace fibernet
