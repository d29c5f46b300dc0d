#include "fibernet/scene/scene_toml.hpp"

#include <charconv>
#include <cstdio>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <utility>

#include "fibernet/util/error.hpp"

namespace fibernet {

std::string toml_float(double v) {
    char b[64];
    const auto r = std::to_chars(b, b + sizeof b, v);  // shortest text that reads back exactly
    std::string t(b, r.ptr);
    if (t.find_first_of(".eEn") == std::string::npos) t += ".0";  // "10" would be a TOML integer
    return t;
}

namespace {
std::string quoted(const std::string& s) {
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

// One row per key: its table, name and the TOML literal of a scene's value; which keys a scene writes depends on
// it (a network file replaces the generation keys).
struct Key {
    const char* table;
    const char* name;
    std::function<std::string(const Scene&)> literal;
};

const std::vector<Key>& keys() {
    static const std::vector<Key> k = {
        {"network", "L", [](const Scene& s) { return toml_float(s.mikado.L); }},
        {"network", "q", [](const Scene& s) { return toml_float(s.mikado.q); }},
        {"network", "pl", [](const Scene& s) { return toml_float(s.mikado.pl); }},
        {"network", "seed", [](const Scene& s) { return std::to_string(s.mikado.seed); }},
        {"network", "periodic", [](const Scene& s) { return std::string(s.mikado.periodic ? "true" : "false"); }},
        {"network", "file", [](const Scene& s) { return quoted(s.network_file); }},
        {"model", "scheme", [](const Scene& s) { return quoted(to_string(s.discretization.scheme)); }},
        {"model", "n_seg", [](const Scene& s) { return std::to_string(s.discretization.n_seg); }},
        {"model", "h", [](const Scene& s) { return toml_float(s.discretization.h); }},
        {"model", "a", [](const Scene& s) { return toml_float(s.discretization.aspect_ratio); }},
        {"model", "fiber_length", [](const Scene& s) { return toml_float(s.discretization.fiber_length); }},
        {"load", "strain", [](const Scene& s) { return quoted(to_string(s.strain)); }},
        {"load", "gamma", [](const Scene& s) { return toml_float(s.gamma); }},
        {"solver", "name", [](const Scene& s) { return quoted(s.solver.name); }},
        {"solver", "tol", [](const Scene& s) { return toml_float(s.solver.tol); }},
        {"solver", "max_iter", [](const Scene& s) { return std::to_string(s.solver.max_iter); }},
        {"wet", "beta", [](const Scene& s) { return toml_float(s.wet.beta); }},
        {"wet", "law", [](const Scene& s) { return quoted(s.wet.law); }},
        {"wet", "crossings", [](const Scene& s) { return quoted(s.wet.crossings); }},
        {"wet", "fraction", [](const Scene& s) { return toml_float(s.wet.fraction); }},
        {"wet", "seed", [](const Scene& s) { return std::to_string(s.wet.seed); }},
        {"wet", "free_box", [](const Scene& s) { return std::string(s.wet.free_box ? "true" : "false"); }},
        {"wet", "free_box_shape", [](const Scene& s) { return quoted(s.wet.free_box_shape); }},
        {"wet", "free_box_tol", [](const Scene& s) { return toml_float(s.wet.free_box_tol); }},
        {"wet", "max_rounds", [](const Scene& s) { return std::to_string(s.wet.max_rounds); }},
        {"wet", "round_iterations", [](const Scene& s) { return std::to_string(s.wet.round_iterations); }},
        {"wet", "newton_ldl", [](const Scene& s) { return std::string(s.wet.newton_ldl ? "true" : "false"); }},
        {"wet", "local_fraction", [](const Scene& s) { return toml_float(s.wet.local_fraction); }},
        {"wet", "local_threshold", [](const Scene& s) { return toml_float(s.wet.local_threshold); }},
        {"wet", "local_hops", [](const Scene& s) { return std::to_string(s.wet.local_hops); }},
        {"wet", "bundle_partners", [](const Scene& s) { return std::to_string(s.wet.bundle_partners); }},
    };
    return k;
}

// Keys a scene leaves out: a saved network has no generation keys and a generated one no file; an empty law is
// the default law.
bool written(const Scene& s, const std::string& table, const std::string& name,
             const std::map<std::string, std::string>& replace) {
    const std::string full = table + "." + name;
    if (replace.count(full)) return true;
    const bool from_file = !s.network_file.empty() || replace.count("network.file");
    if (table == "network") return name == "file" ? from_file : !from_file;
    if (full == "wet.law") return !s.wet.law.empty();
    return true;
}
}  // namespace

const std::vector<std::string>& scene_keys() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> n;
        for (const auto& k : keys()) n.push_back(std::string(k.table) + "." + k.name);
        return n;
    }();
    return names;
}

std::string to_toml(const Scene& s, const std::map<std::string, std::string>& replace) {
    for (const auto& [name, seed] : {std::pair<const char*, std::uint64_t>{"network.seed", s.mikado.seed}, {"wet.seed", s.wet.seed}})
        if (seed > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) && !replace.count(name))
            throw InputError(std::string(name) + " = " + std::to_string(seed) + " cannot be written in a TOML scene "
                             "(TOML integers stop at 2^63 - 1 = 9223372036854775807): give a smaller seed");
    const std::set<std::string> known(scene_keys().begin(), scene_keys().end());
    for (const auto& [key, value] : replace)
        if (!known.count(key)) throw InputError("scene key '" + key + "' is unknown");
    std::ostringstream os;
    os << "# fibernet scene (every key; docs/formats.md)\n";
    std::string table;
    for (const auto& k : keys()) {
        if (!written(s, k.table, k.name, replace)) continue;
        if (table != k.table) {
            table = k.table;
            os << (os.tellp() > 0 ? "\n" : "") << "[" << table << "]\n";
        }
        const std::string full = table + "." + k.name;
        const auto it = replace.find(full);
        os << k.name << " = " << (it != replace.end() ? it->second : k.literal(s)) << "\n";
        if (full == "model.fiber_length") {  // [model].prune, an array, after the model's scalars
            std::string prune;
            if (s.prune.dangling) prune += "\"dangling\"";
            if (s.prune.nonspanning) prune += std::string(prune.empty() ? "" : ", ") + "\"nonspanning\"";
            if (s.discretization.trim_ends) prune += std::string(prune.empty() ? "" : ", ") + "\"ends\"";
            os << "prune = [" << prune << "]\n";
        }
    }
    return os.str();
}

}  // namespace fibernet
