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

#include "fibernet/scene/scene_options.hpp"
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
        for (const auto& o : scene_options()) n.push_back(o.name());
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
    for (const auto& o : scene_options()) {
        if (!written(s, o.table, o.key, replace)) continue;
        if (table != o.table) {
            table = o.table;
            os << (os.tellp() > 0 ? "\n" : "") << "[" << table << "]\n";
        }
        const std::string full = o.name();
        const auto it = replace.find(full);
        os << o.key << " = " << (it != replace.end() ? it->second : o.literal(s)) << "\n";
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
