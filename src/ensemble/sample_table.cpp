#include "fibernet/ensemble/sample_table.hpp"

#include <cmath>
#include <cstdio>
#include <map>
#include <set>

namespace fibernet {

namespace {
constexpr std::size_t kMaxListedObjects = 16;

void flatten_into(const nlohmann::json& j, const std::string& prefix, std::vector<std::pair<std::string, nlohmann::json>>& out) {
    for (const auto& [k, v] : j.items()) {
        if (k == "seconds") continue;  // wall times differ from run to run
        const std::string name = prefix.empty() ? k : prefix + "." + k;
        if (v.is_object()) {
            flatten_into(v, name, out);
        } else if (v.is_array()) {  // a short list of objects (fibernet wet's runs, one per beta): each by index
            if (v.size() > kMaxListedObjects || v.empty() || !v.front().is_object()) continue;
            for (std::size_t i = 0; i < v.size(); ++i)
                if (v[i].is_object()) flatten_into(v[i], name + "." + std::to_string(i), out);
        } else {
            out.emplace_back(name, v);
        }
    }
}

// The columns: the union over the records in index order, each where it first appears (a failed sample has fewer).
std::vector<std::string> result_columns(const std::vector<const nlohmann::json*>& records) {
    std::vector<std::string> cols;
    std::set<std::string> seen;
    for (const auto* r : records)
        if (r->contains("result"))
            for (const auto& [name, v] : flatten_result((*r)["result"]))
                if (seen.insert(name).second) cols.push_back(name);
    return cols;
}

std::map<std::string, nlohmann::json> by_name(const nlohmann::json& record) {
    std::map<std::string, nlohmann::json> m;
    if (record.contains("result"))
        for (auto& [name, v] : flatten_result(record["result"])) m.emplace(name, std::move(v));
    return m;
}

std::string header_field(const std::string& s) { return csv_field(nlohmann::json(s)); }

std::string number(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g", v);
    return b;
}
}  // namespace

std::vector<std::pair<std::string, nlohmann::json>> flatten_result(const nlohmann::json& result) {
    std::vector<std::pair<std::string, nlohmann::json>> out;
    if (result.is_object()) flatten_into(result, "", out);
    return out;
}

std::string csv_field(const nlohmann::json& v) {
    if (v.is_null()) return "";
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_number_integer()) return v.dump();
    if (v.is_number()) return std::isfinite(v.get<double>()) ? number(v.get<double>()) : "";
    std::string s = v.is_string() ? v.get<std::string>() : v.dump();
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

std::string samples_csv(const Grid& grid, const std::vector<const nlohmann::json*>& records) {
    const auto cols = result_columns(records);
    std::set<std::string> leading = {"index", "status", "exit_code"};
    std::string out = "index";
    for (const auto& a : grid.axes) out += "," + header_field(a.name), leading.insert(a.name);
    out += ",status,exit_code";
    // A result's own "status" (or a key named like an axis) under "result." so that no two columns share a name.
    for (const auto& c : cols) out += "," + header_field(leading.count(c) ? "result." + c : c);
    out += "\n";
    for (const auto* r : records) {
        const std::size_t index = (*r)["index"].get<std::size_t>();
        const auto coord = grid.coordinates(index);
        out += std::to_string(index);
        for (std::size_t k = 0; k < grid.axes.size(); ++k) out += "," + csv_field(nlohmann::json(grid.axes[k].labels[coord[k]]));
        out += "," + csv_field(r->value("status", nlohmann::json(""))) + "," + csv_field(r->value("exit_code", nlohmann::json()));
        const auto values = by_name(*r);
        for (const auto& c : cols) {
            const auto it = values.find(c);
            out += "," + (it == values.end() ? std::string() : csv_field(it->second));
        }
        out += "\n";
    }
    return out;
}

std::string summary_csv(const Grid& grid, const std::vector<const nlohmann::json*>& records) {
    const auto cols = result_columns(records);
    struct Point {
        std::size_t first_index = 0, samples = 0, ok = 0;
        std::map<std::string, std::vector<double>> values;
        std::set<std::string> not_numeric;
    };
    std::map<std::size_t, Point> points;
    for (const auto* r : records) {
        const std::size_t index = (*r)["index"].get<std::size_t>();
        auto [it, fresh] = points.try_emplace(grid.point(index));
        Point& p = it->second;
        if (fresh) p.first_index = index;
        ++p.samples;
        if (r->value("exit_code", -1) != 0) continue;
        ++p.ok;
        for (const auto& [name, v] : by_name(*r)) {
            if (v.is_number() && !v.is_null() && std::isfinite(v.get<double>())) p.values[name].push_back(v.get<double>());
            else if (!v.is_null()) p.not_numeric.insert(name);
        }
    }
    // Columns numeric wherever given.
    std::vector<std::string> numeric;
    for (const auto& c : cols) {
        bool any = false, bad = false;
        for (const auto& [k, p] : points) any = any || p.values.count(c), bad = bad || p.not_numeric.count(c);
        if (any && !bad) numeric.push_back(c);
    }
    std::string out;
    std::set<std::string> leading = {"samples", "ok"};
    for (std::size_t k = 0; k < grid.axes.size(); ++k)
        if (!grid.replica_axis(k)) out += header_field(grid.axes[k].name) + ",", leading.insert(grid.axes[k].name);
    out += "samples,ok";
    for (const auto& c : numeric) {
        const std::string name = leading.count(c) ? "result." + c : c;
        out += "," + header_field(name + ".mean") + "," + header_field(name + ".sem");
    }
    out += "\n";
    for (const auto& [pi, p] : points) {
        const auto coord = grid.coordinates(p.first_index);
        for (std::size_t k = 0; k < grid.axes.size(); ++k)
            if (!grid.replica_axis(k)) out += csv_field(nlohmann::json(grid.axes[k].labels[coord[k]])) + ",";
        out += std::to_string(p.samples) + "," + std::to_string(p.ok);
        for (const auto& c : numeric) {
            const auto it = p.values.find(c);
            if (it == p.values.end() || it->second.empty()) {
                out += ",,";
                continue;
            }
            const auto& v = it->second;
            double mean = 0;
            for (double x : v) mean += x;
            mean /= static_cast<double>(v.size());
            out += "," + number(mean) + ",";
            if (v.size() >= 2) {
                double ss = 0;
                for (double x : v) ss += (x - mean) * (x - mean);
                out += number(std::sqrt(ss / static_cast<double>(v.size() - 1) / static_cast<double>(v.size())));
            }
        }
        out += "\n";
    }
    return out;
}

}  // namespace fibernet
