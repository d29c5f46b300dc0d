#include "fibernet/scene/scene_options.hpp"

#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>

#include "fibernet/scene/scene_toml.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

namespace {

SceneOption opt(const char* table, const char* key, const char* flag, const char* doc, OptionKind kind) {
    SceneOption o;
    o.table = table, o.key = key, o.flag = flag, o.doc = doc, o.kind = kind;
    return o;
}
SceneOption real(const char* t, const char* k, const char* f, const char* d, std::function<double&(Scene&)> a) {
    SceneOption o = opt(t, k, f, d, OptionKind::Real);
    o.real = std::move(a);
    return o;
}
SceneOption integer(const char* t, const char* k, const char* f, const char* d, std::function<int&(Scene&)> a) {
    SceneOption o = opt(t, k, f, d, OptionKind::Integer);
    o.integer = std::move(a);
    return o;
}
SceneOption seed(const char* t, const char* k, const char* f, const char* d, std::function<std::uint64_t&(Scene&)> a) {
    SceneOption o = opt(t, k, f, d, OptionKind::Seed);
    o.seed = std::move(a);
    return o;
}
SceneOption boolean(const char* t, const char* k, const char* f, const char* d, std::function<bool&(Scene&)> a) {
    SceneOption o = opt(t, k, f, d, OptionKind::Boolean);
    o.boolean = std::move(a);
    return o;
}
SceneOption text(const char* t, const char* k, const char* f, const char* d, std::function<std::string&(Scene&)> a) {
    SceneOption o = opt(t, k, f, d, OptionKind::Text);
    o.text = std::move(a);
    return o;
}
SceneOption choice(const char* t, const char* k, const char* f, const char* d,
                   std::function<void(Scene&, const std::string&)> set, std::function<std::string(const Scene&)> get) {
    SceneOption o = opt(t, k, f, d, OptionKind::Choice);
    o.set_choice = std::move(set), o.get_choice = std::move(get);
    return o;
}

std::string toml_quoted(const std::string& s) {  // a TOML basic string
    std::string q = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') q += '\\', q += c;
        else if (static_cast<unsigned char>(c) < 0x20) {
            char b[8];
            std::snprintf(b, sizeof b, "\\u%04x", c);
            q += b;
        } else q += c;
    }
    return q + "\"";
}

std::vector<SceneOption> declare() {
    std::vector<SceneOption> v;
    auto add = [&](SceneOption o) { v.push_back(std::move(o)); };
    // [network]
    SceneOption file = text("network", "file", "--network", "read this network file instead of generating one",
                            [](Scene& s) -> std::string& { return s.network_file; });
    file.existing_file = true;
    add(real("network", "L", "--L", "box side in fiber lengths", [](Scene& s) -> double& { return s.mikado.L; }));
    add(real("network", "q", "--q", "density N lf^2 / A", [](Scene& s) -> double& { return s.mikado.q; }));
    add(real("network", "pl", "--pl", "crosslink probability in [0, 1]", [](Scene& s) -> double& { return s.mikado.pl; }));
    add(seed("network", "seed", "--seed", "random seed, an integer in [0, 2^64)",
             [](Scene& s) -> std::uint64_t& { return s.mikado.seed; }));
    SceneOption periodic = boolean("network", "periodic", "--open", "open box instead of periodic",
                                   [](Scene& s) -> bool& { return s.mikado.periodic; });
    periodic.flag_sets_false = true;
    add(periodic);
    add(file);
    // [model]
    add(choice("model", "scheme", "--scheme", "discretization: seed | even",
               [](Scene& s, const std::string& w) { s.discretization.scheme = parse_scheme(w); },
               [](const Scene& s) { return to_string(s.discretization.scheme); }));
    add(integer("model", "n_seg", "--nseg", "seed scheme: segments per fiber",
                [](Scene& s) -> int& { return s.discretization.n_seg; }));
    add(real("model", "h", "--h", "even scheme: segment length in seed units",
             [](Scene& s) -> double& { return s.discretization.h; }));
    add(real("model", "a", "--a", "fiber aspect ratio a = ls / r",
             [](Scene& s) -> double& { return s.discretization.aspect_ratio; }));
    add(real("model", "fiber_length", "", "lf in seed units", [](Scene& s) -> double& { return s.discretization.fiber_length; }));
    // [load]
    add(choice("load", "strain", "--strain", "strain path: shear | uniaxial | uniaxial-y | isotropic",
               [](Scene& s, const std::string& w) { s.strain = parse_strain_kind(w); },
               [](const Scene& s) { return to_string(s.strain); }));
    add(real("load", "gamma", "--gamma", "strain parameter", [](Scene& s) -> double& { return s.gamma; }));
    // [solver]
    add(text("solver", "name", "--solver", "solver", [](Scene& s) -> std::string& { return s.solver.name; }));
    add(real("solver", "tol", "--tol", "max |gradient| to stop at", [](Scene& s) -> double& { return s.solver.tol; }));
    add(integer("solver", "max_iter", "--max-iter", "iteration limit", [](Scene& s) -> int& { return s.solver.max_iter; }));
    SceneOption eliminate = boolean(
        "solver", "eliminate", "--eliminate",
        "Newton (relax, modulus, sweep): solve the hot places to local equilibrium before and inside each global step; "
        "on by default, --no-eliminate: plain Newton (docs/solvers.md)",
        [](Scene& s) -> bool& { return s.solver.eliminate; });
    eliminate.negation = "--no-eliminate";
    add(eliminate);
    // [wet] (docs/wet.md)
    add(real("wet", "beta", "--beta", "adhesion per unit bundle length, bending units",
             [](Scene& s) -> double& { return s.wet.beta; }));
    add(text("wet", "law", "--law", "tabulated capillary law file: lines 'alpha_deg value'",
             [](Scene& s) -> std::string& { return s.wet.law; }));
    add(text("wet", "crossings", "--crossings", "wet crossings: all | free | fraction",
             [](Scene& s) -> std::string& { return s.wet.crossings; }));
    add(real("wet", "fraction", "--fraction", "wet fraction of crossings, in [0, 1]",
             [](Scene& s) -> double& { return s.wet.fraction; }));
    add(seed("wet", "seed", "--wet-seed", "seed of the wet fraction draw (with --crossings fraction)",
             [](Scene& s) -> std::uint64_t& { return s.wet.seed; }));
    add(boolean("wet", "free_box", "--free-box",
                "then find the zero-stress box of the wet network (drying shrinkage, docs/wet.md)",
                [](Scene& s) -> bool& { return s.wet.free_box; }));
    add(text("wet", "free_box_shape", "--free-box-shape",
             "isotropic (F = s F0, mean normal stress -> 0) | full (symmetric box stretch, sigma_xx, sigma_yy, "
             "sigma_xy -> 0; less robust, docs/wet.md)",
             [](Scene& s) -> std::string& { return s.wet.free_box_shape; }));
    add(real("wet", "free_box_tol", "--free-box-tol", "free box converged at |sigma| <= tol * sigma_c",
             [](Scene& s) -> double& { return s.wet.free_box_tol; }));
    add(integer("wet", "max_rounds", "", "active-set rounds per relaxation", [](Scene& s) -> int& { return s.wet.max_rounds; }));
    add(integer("wet", "round_iterations", "", "Newton iterations per round while the set changes",
                [](Scene& s) -> int& { return s.wet.round_iterations; }));
    add(boolean("wet", "newton_ldl", "", "Newton's first rung by LDL^T", [](Scene& s) -> bool& { return s.wet.newton_ldl; }));
    add(boolean("wet", "newton_projected", "--projected",
                "smooth model: projected Newton (element-wise PSD Hessian until full steps, then exact) instead of "
                "newton_ldl (docs/wet.md)",
                [](Scene& s) -> bool& { return s.wet.newton_projected; }));
    add(boolean("wet", "newton_eliminate", "--wet-eliminate",
                "Newton's nonlinear elimination in the wet relaxation (off by default: docs/solvers.md)",
                [](Scene& s) -> bool& { return s.wet.newton_eliminate; }));
    add(integer("wet", "eliminate_hops", "--wet-eliminate-hops",
                "smooth model with --wet-eliminate: coordinate hops the hot set grows by before its local solves "
                "(the event model keeps the dry default, 16; docs/wet.md)",
                [](Scene& s) -> int& { return s.wet.eliminate_hops; }));
    add(integer("wet", "schwarz_block", "--wet-schwarz",
                "Newton's Schwarz sweep in the wet relaxation: before each global step, every coordinate to local "
                "equilibrium in connected blocks of about this many coordinates (0: off; implies --wet-eliminate; "
                "docs/wet.md)",
                [](Scene& s) -> int& { return s.wet.schwarz_block; }));
    add(integer("wet", "schwarz_overlap", "--wet-schwarz-overlap",
                "with --wet-schwarz: coordinate hops each block is grown by",
                [](Scene& s) -> int& { return s.wet.schwarz_overlap; }));
    add(real("wet", "local_fraction", "", "local rounds: largest part of the coordinates",
             [](Scene& s) -> double& { return s.wet.local_fraction; }));
    add(real("wet", "local_threshold", "", "local rounds: hot where |g| > threshold x max|g|",
             [](Scene& s) -> double& { return s.wet.local_threshold; }));
    add(integer("wet", "local_hops", "", "local rounds: element hops the hot part grows by",
                [](Scene& s) -> int& { return s.wet.local_hops; }));
    add(integer("wet", "bundle_partners", "--bundle-partners",
                "excluded volume: a segment adheres along at most N other fibers (0: no cap; 2: flat ribbon; "
                "6: close-packed; docs/wet.md)",
                [](Scene& s) -> int& { return s.wet.bundle_partners; }));
    add(text("wet", "model", "--wet-model",
             "capillary model: events (bridges moved, formed, ruptured between solves) | smooth (one smooth energy "
             "over all segment pairs, docs/wet.md)",
             [](Scene& s) -> std::string& { return s.wet.model; }));
    add(real("wet", "crossing_width", "--crossing-width",
             "smooth model: distance over which a crossing passes between segments, seed units (0: fiber radius 1/a)",
             [](Scene& s) -> double& { return s.wet.crossing_width; }));
    add(real("wet", "contact_distance", "--contact-distance",
             "smooth model: aligned fibers closer than this adhere, seed units (0: fiber diameter 2/a)",
             [](Scene& s) -> double& { return s.wet.contact_distance; }));
    add(real("wet", "skin", "--skin", "smooth model: neighbour-list skin, seed units (also Newton's largest step)",
             [](Scene& s) -> double& { return s.wet.skin; }));
    add(real("wet", "checkpoint_seconds", "--checkpoint-seconds",
             "smooth model with --out-dir: write the wet relaxation's current state as checkpoint_<k>.txt at most this "
             "often, for --start-state after an interrupt (0: never; docs/wet.md)",
             [](Scene& s) -> double& { return s.wet.checkpoint_seconds; }));
    add(text("wet", "start_state", "--start-state",
             "smooth model, one beta: start the wet relaxation from this state file of the same network (a "
             "checkpoint_<k>.txt or state_<k>.txt of an earlier run) instead of the dry equilibrium",
             [](Scene& s) -> std::string& { return s.wet.start_state; }));
    return v;
}

}  // namespace

const std::vector<SceneOption>& scene_options() {
    static const std::vector<SceneOption> v = declare();
    return v;
}

const SceneOption* find_scene_option(const std::string& table, const std::string& key) {
    for (const auto& o : scene_options())
        if (o.table == table && o.key == key) return &o;
    return nullptr;
}

std::string SceneOption::literal(const Scene& cs) const {
    Scene& s = const_cast<Scene&>(cs);  // the accessors are shared by reading and writing; nothing is written here
    switch (kind) {
        case OptionKind::Real: return toml_float(real(s));
        case OptionKind::Integer: return std::to_string(integer(s));
        case OptionKind::Seed: return std::to_string(seed(s));
        case OptionKind::Boolean: return boolean(s) ? "true" : "false";
        case OptionKind::Text: return toml_quoted(text(s));
        case OptionKind::Choice: return toml_quoted(get_choice(s));
    }
    return "";
}

void SceneOption::set_from_text(Scene& s, const std::string& t, const std::string& where) const {
    const std::string what = where + ": " + (flag.empty() ? name() : flag) + " = '" + t + "'";
    switch (kind) {
        case OptionKind::Real: {
            char* end = nullptr;
            errno = 0;
            const double v = std::strtod(t.c_str(), &end);
            // nan and inf parse, as a scene's do: the value's own check names them (Scene::check and the structs').
            if (t.empty() || *end) throw InputError(what + " is not a number");
            real(s) = v;
            return;
        }
        case OptionKind::Integer: {
            long v = 0;
            const size_t skip = t.size() > 1 && t[0] == '+' && t[1] != '-' ? 1 : 0;  // "+5", as before
            const auto r = std::from_chars(t.data() + skip, t.data() + t.size(), v);
            if (r.ec != std::errc() || r.ptr != t.data() + t.size() || v < INT_MIN || v > INT_MAX)
                throw InputError(what + " is not an integer in [" + std::to_string(INT_MIN) + ", " +
                                 std::to_string(INT_MAX) + "]");
            integer(s) = static_cast<int>(v);
            return;
        }
        case OptionKind::Seed: {
            std::uint64_t v = 0;
            const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
            if (r.ec != std::errc() || r.ptr != t.data() + t.size())
                throw InputError(what + " is not an integer in [0, 2^64)");
            seed(s) = v;
            return;
        }
        case OptionKind::Boolean:
            if (t == "true" || t == "1") boolean(s) = true;
            else if (t == "false" || t == "0") boolean(s) = false;
            else throw InputError(what + " is not true or false");
            return;
        case OptionKind::Text: text(s) = t; return;
        case OptionKind::Choice:
            try {
                set_choice(s, t);
            } catch (const InputError& e) {
                throw InputError(where + ": " + (flag.empty() ? name() : flag) + ": " + e.what());
            }
            return;
    }
}

}  // namespace fibernet
