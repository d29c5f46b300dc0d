#include "fibernet/ensemble/grid.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "fibernet/scene/scene_toml.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

std::string grid_key(const std::string& name, const std::string& where) {
    const auto& keys = scene_keys();
    for (const auto& k : keys)
        if (k == name) return k;
    if (name == "seed") return "network.seed";
    std::string found, all;
    int hits = 0;
    for (const auto& k : keys) {
        all += (all.empty() ? "" : ", ") + k;
        if (k.substr(k.find('.') + 1) == name) found = k, ++hits;
    }
    if (hits == 1) return found;
    if (hits > 1) throw InputError(where + ": '" + name + "' names a key of more than one table: write table.key");
    throw InputError(where + ": '" + name + "' is not a scene key (expected one of: " + all + ")");
}

namespace {
bool whole_integer(const std::string& t, long long& v) {
    const char* b = t.data() + (t.size() > 1 && t[0] == '+' ? 1 : 0);
    const auto r = std::from_chars(b, t.data() + t.size(), v);
    return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}
bool number(const std::string& t, double& v) {
    if (t.empty() || t.find_first_of("xXpP") != std::string::npos) return false;  // no hex floats
    char* end = nullptr;
    v = std::strtod(t.c_str(), &end);
    return end == t.c_str() + t.size() && std::isfinite(v);
}
std::string twelve_digits(double v) {  // first + k step, without the round-off of the sum (0.1 * 3)
    char b[64];
    std::snprintf(b, sizeof b, "%.12g", v);
    return toml_float(std::strtod(b, nullptr));
}

// A value as written on the command line -> its TOML literal and its CSV label.
std::pair<std::string, std::string> literal(const std::string& text) {
    long long i = 0;
    double d = 0;
    if (whole_integer(text, i)) return {std::to_string(i), std::to_string(i)};
    if (number(text, d)) return {toml_float(d), toml_float(d)};
    if (text == "true" || text == "false") return {text, text};
    std::string q = "\"";
    for (char c : text) q += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    return {q + "\"", text};
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::size_t start = 0;
    for (;;) {
        const std::size_t k = s.find(sep, start);
        out.push_back(s.substr(start, k == std::string::npos ? std::string::npos : k - start));
        if (k == std::string::npos) return out;
        start = k + 1;
    }
}

// "first:last[:step]" -> the values' texts.
std::vector<std::string> range_values(const std::string& name, const std::string& spec, const std::string& where) {
    const auto parts = split(spec, ':');
    const std::string at = where + ": --vary " + name + "=" + spec;
    if (parts.size() > 3) throw InputError(at + ": a range is first:last or first:last:step");
    long long a = 0, b = 0;
    std::vector<std::string> out;
    if (parts.size() == 2) {
        if (!whole_integer(parts[0], a) || !whole_integer(parts[1], b))
            throw InputError(at + ": first:last takes integers (give first:last:step for other numbers)");
        if (b < a) throw InputError(at + ": last " + parts[1] + " is below first " + parts[0]);
        if (b - a >= 10000000) throw InputError(at + ": more than 1e7 values");
        for (long long v = a; v <= b; ++v) out.push_back(std::to_string(v));
        return out;
    }
    double first = 0, last = 0, step = 0;
    if (!number(parts[0], first)) throw InputError(at + ": first '" + parts[0] + "' is not a number");
    if (!number(parts[1], last)) throw InputError(at + ": last '" + parts[1] + "' is not a number");
    if (!number(parts[2], step) || !(step > 0)) throw InputError(at + ": step '" + parts[2] + "' is not a number > 0");
    if (last < first) throw InputError(at + ": last " + parts[1] + " is below first " + parts[0]);
    const double n = std::floor((last - first) / step * (1 + 1e-12) + 1e-9) + 1;
    if (n > 1e7) throw InputError(at + ": more than 1e7 values");
    for (long long k = 0; k < static_cast<long long>(n); ++k) out.push_back(twelve_digits(first + k * step));
    return out;
}
}  // namespace

GridAxis parse_axis(const std::string& spec, const std::string& where) {
    const std::size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0)
        throw InputError(where + ": --vary '" + spec + "' is not name=values (e.g. q=4,8,16 or seed=1:8)");
    GridAxis ax;
    ax.name = spec.substr(0, eq);
    ax.key = grid_key(ax.name, where + ": --vary " + ax.name);
    const std::string rhs = spec.substr(eq + 1);
    std::vector<std::string> texts;
    if (rhs.find(':') != std::string::npos && rhs.find(',') == std::string::npos) texts = range_values(ax.name, rhs, where);
    else texts = split(rhs, ',');
    std::set<std::string> seen;
    for (const auto& t : texts) {
        if (t.empty()) throw InputError(where + ": --vary " + spec + ": an empty value");
        const auto [lit, label] = literal(t);
        if (!seen.insert(lit).second)
            throw InputError(where + ": --vary " + spec + ": the value " + t + " is given twice (a sample counts once)");
        ax.values.push_back(lit), ax.labels.push_back(label);
    }
    return ax;
}

std::size_t Grid::size() const {
    std::size_t n = 1;
    for (const auto& a : axes) n *= a.values.size();
    return n;
}

std::vector<std::size_t> Grid::coordinates(std::size_t index) const {
    std::vector<std::size_t> c(axes.size());
    for (std::size_t k = axes.size(); k-- > 0;) {
        c[k] = index % axes[k].values.size();
        index /= axes[k].values.size();
    }
    return c;
}

std::map<std::string, std::string> Grid::replacements(std::size_t index) const {
    std::map<std::string, std::string> r;
    const auto c = coordinates(index);
    for (std::size_t k = 0; k < axes.size(); ++k) r[axes[k].key] = axes[k].values[c[k]];
    return r;
}

bool Grid::replica_axis(std::size_t k) const { return axes[k].key == "network.seed" || axes[k].key == "wet.seed"; }

std::size_t Grid::point(std::size_t index) const {
    const auto c = coordinates(index);
    std::size_t p = 0;
    for (std::size_t k = 0; k < axes.size(); ++k)
        if (!replica_axis(k)) p = p * axes[k].values.size() + c[k];
    return p;
}

void check_grid(const Grid& g, std::size_t max_samples, const std::string& where) {
    std::set<std::string> keys;
    double n = 1;
    for (const auto& a : g.axes) {
        if (!keys.insert(a.key).second) throw InputError(where + ": --vary " + a.name + ": " + a.key + " is varied twice");
        n *= static_cast<double>(a.values.size());
    }
    if (n > static_cast<double>(max_samples))
        throw InputError(where + ": the grid has " + show(n) + " samples, more than " + std::to_string(max_samples));
}

}  // namespace fibernet
