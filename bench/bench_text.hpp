#pragma once
// Text helpers of the benchmarks' command lines and CSV files.
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace fibernet::bench {

// The non-empty items of a comma-separated list.
inline std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

// A free text (a solver's message) as one quoted CSV field: no comma, double quote or line break left in it.
inline std::string csv_text(std::string s) {
    std::replace(s.begin(), s.end(), ',', ';');
    std::replace(s.begin(), s.end(), '"', '\'');
    std::replace(s.begin(), s.end(), '\n', ' ');
    return "\"" + s + "\"";
}

}  // namespace fibernet::bench
