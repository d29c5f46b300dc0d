#include "fibernet/ensemble/grid.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>

#include "fibernet/scene/scene_toml.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/utf8.hpp"

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
// A value is printable UTF-8: a control byte (a NUL ends messages and file names) or a broken sequence is refused.
void check_text(const std::string& t, const std::string& where) {
    for (unsigned char c : t)
        if (c < 0x20 || c == 0x7f) throw InputError(where + ": a value holds the control byte " + std::to_string(c));
    const std::size_t bad = invalid_utf8_at(t);
    if (bad != std::string::npos) throw InputError(where + ": a value is not UTF-8 (byte " + std::to_string(bad + 1) + ")");
}

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
    ax.source = "--vary " + spec;
    ax.name = spec.substr(0, eq);
    ax.key = grid_key(ax.name, where + ": --vary " + ax.name);
    const std::string rhs = spec.substr(eq + 1);
    std::vector<std::string> texts;
    if (rhs.find(':') != std::string::npos && rhs.find(',') == std::string::npos) texts = range_values(ax.name, rhs, where);
    else texts = split(rhs, ',');
    std::set<std::string> seen;
    std::set<double> seen_numbers;  // 8 and 8.0 are one value
    for (const auto& t : texts) {
        if (t.empty()) throw InputError(where + ": --vary " + ax.name + ": an empty value");
        check_text(t, where + ": --vary " + ax.name);
        const auto [lit, label] = literal(t);
        double d = 0;
        const bool repeated_number = number(lit, d) && !seen_numbers.insert(d).second;
        if (!seen.insert(lit).second || repeated_number)
            throw InputError(where + ": --vary " + spec + ": the value " + t + " is given twice (a sample counts once)");
        ax.values.push_back(lit), ax.labels.push_back(label);
    }
    return ax;
}

std::vector<GridAxis> parse_points(const std::string& text, const std::string& where, int group) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream is(text);
    int lineno = 0;
    for (std::string line; std::getline(is, line);) {
        ++lineno;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        rows.push_back(split(line, ','));
        for (auto& f : rows.back()) {
            f.erase(0, f.find_first_not_of(" \t"));
            f.erase(f.find_last_not_of(" \t") + 1);
            if (f.empty()) throw InputError(where + ":" + std::to_string(lineno) + ": an empty field");
            check_text(f, where + ":" + std::to_string(lineno));
        }
        if (rows.size() > 1 && rows.back().size() != rows.front().size())
            throw InputError(where + ":" + std::to_string(lineno) + ": " + std::to_string(rows.back().size()) +
                             " fields, the header has " + std::to_string(rows.front().size()));
    }
    if (rows.size() < 2) throw InputError(where + ": no points (a header of scene keys, then one row per point)");
    std::vector<GridAxis> axes(rows.front().size());
    for (std::size_t c = 0; c < axes.size(); ++c) {
        axes[c].name = rows.front()[c];
        axes[c].key = grid_key(axes[c].name, where + ": column " + std::to_string(c + 1));
        axes[c].group = group;
        axes[c].source = where;
    }
    std::set<std::vector<std::string>> seen;
    for (std::size_t r = 1; r < rows.size(); ++r) {
        std::vector<std::string> point;
        for (std::size_t c = 0; c < axes.size(); ++c) {
            const auto [lit, label] = literal(rows[r][c]);
            axes[c].values.push_back(lit), axes[c].labels.push_back(label), point.push_back(lit);
        }
        if (!seen.insert(point).second) throw InputError(where + ": point " + std::to_string(r) + " is given twice");
    }
    return axes;
}

namespace {
// The axes that share a coordinate: each group's axis indices, in the order of their first axis.
std::vector<std::vector<std::size_t>> coordinate_groups(const std::vector<GridAxis>& axes) {
    std::vector<std::vector<std::size_t>> groups;
    std::map<int, std::size_t> of_group;
    for (std::size_t k = 0; k < axes.size(); ++k) {
        if (axes[k].group >= 0) {
            const auto [it, fresh] = of_group.emplace(axes[k].group, groups.size());
            if (fresh) groups.emplace_back();
            groups[it->second].push_back(k);
        } else {
            groups.push_back({k});
        }
    }
    return groups;
}
}  // namespace

std::size_t Grid::size() const {
    std::size_t n = 1;
    for (const auto& g : coordinate_groups(axes)) n *= axes[g.front()].values.size();
    return n;
}

std::vector<std::size_t> Grid::coordinates(std::size_t index) const {
    std::vector<std::size_t> c(axes.size());
    const auto groups = coordinate_groups(axes);
    for (std::size_t k = groups.size(); k-- > 0;) {
        const std::size_t len = axes[groups[k].front()].values.size();
        for (std::size_t a : groups[k]) c[a] = index % len;
        index /= len;
    }
    return c;
}

std::map<std::string, std::string> Grid::replacements(std::size_t index) const {
    std::map<std::string, std::string> r;
    const auto c = coordinates(index);
    for (std::size_t k = 0; k < axes.size(); ++k) r[axes[k].key] = axes[k].values[c[k]];
    return r;
}

bool Grid::replica_axis(std::size_t k) const {
    return axes[k].group < 0 && (axes[k].key == "network.seed" || axes[k].key == "wet.seed");  // a point's seed: no
}

std::size_t Grid::point(std::size_t index) const {
    const auto c = coordinates(index);
    std::size_t p = 0;
    for (const auto& g : coordinate_groups(axes)) {
        bool replicas = true;  // a group of seeds only (a list of points with a seed column is a point)
        for (std::size_t a : g) replicas = replicas && replica_axis(a);
        if (!replicas) p = p * axes[g.front()].values.size() + c[g.front()];
    }
    return p;
}

void check_grid(const Grid& g, std::size_t max_samples, const std::string& where) {
    std::set<std::string> keys;
    for (const auto& a : g.axes)
        if (!keys.insert(a.key).second) throw InputError(where + ": --vary " + a.name + ": " + a.key + " is varied twice");
    double n = 1;
    for (const auto& grp : coordinate_groups(g.axes)) {
        for (std::size_t a : grp)
            if (g.axes[a].values.size() != g.axes[grp.front()].values.size() || g.axes[a].values.empty())
                throw InputError(where + ": the axes of a list of points differ in length");
        n *= static_cast<double>(g.axes[grp.front()].values.size());
    }
    if (n > static_cast<double>(max_samples))
        throw InputError(where + ": the grid has " + show(n) + " samples, more than " + std::to_string(max_samples));
}

}  // namespace fibernet
