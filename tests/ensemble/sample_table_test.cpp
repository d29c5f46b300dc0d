// Tables of an ensemble (ensemble/sample_table.hpp): flattened columns, CSV fields that read back exactly, and the
// mean and standard error per grid point over the seeds.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <sstream>

#include "fibernet/ensemble/sample_table.hpp"

using namespace fibernet;

namespace {
std::vector<std::vector<std::string>> rows(const std::string& csv) {
    std::vector<std::vector<std::string>> out;
    std::istringstream is(csv);
    for (std::string line; std::getline(is, line);) {
        out.emplace_back();
        std::istringstream ls(line);
        for (std::string f; std::getline(ls, f, ',');) out.back().push_back(f);
    }
    return out;
}
}  // namespace

TEST_CASE("sample_table: flattening leaves out arrays and timings", "[ensemble]") {
    const nlohmann::json r = {{"moduli", {{"G", 1.5}, {"seconds", 2}}}, {"list", {1, 2}}, {"seconds", {{"total", 3}}},
                              {"runs", {{{"beta", 0.5}}, {{"beta", 1}}}}, {"status", "converged"}};
    const auto f = flatten_result(r);
    REQUIRE(f.size() == 4);
    CHECK(f[0].first == "moduli.G");
    CHECK(f[1].first == "runs.0.beta");  // a short list of objects, by index
    CHECK(f[2].first == "runs.1.beta");
    CHECK(f[3].first == "status");
    CHECK(csv_field(0.1) == "0.10000000000000001");
    CHECK(std::strtod(csv_field(1.0 / 3).c_str(), nullptr) == 1.0 / 3);
    CHECK(csv_field(42) == "42");
    CHECK(csv_field(nullptr) == "");
    CHECK(csv_field("a,b \"c\"") == "\"a,b \"\"c\"\"\"");
}

TEST_CASE("sample_table: rows in index order, mean and standard error per point", "[ensemble]") {
    Grid g;
    g.axes = {parse_axis("q=4,8", "t"), parse_axis("seed=1:3", "t")};
    std::vector<nlohmann::json> recs;
    const double G[] = {1, 2, 3, 10, 20, 99};
    for (std::size_t i = 0; i < 6; ++i)
        recs.push_back({{"index", i}, {"status", i == 5 ? "failed" : "converged"}, {"exit_code", i == 5 ? 1 : 0},
                        {"result", {{"moduli", {{"G", G[i]}}}}}});
    std::vector<const nlohmann::json*> p;
    for (const auto& r : recs) p.push_back(&r);
    const auto s = rows(samples_csv(g, p));
    REQUIRE(s.size() == 7);
    CHECK(s[0] == std::vector<std::string>{"index", "q", "seed", "status", "exit_code", "moduli.G"});
    CHECK(s[5] == std::vector<std::string>{"4", "8", "2", "converged", "0", "20"});
    std::vector<nlohmann::json> named = {{{"index", 0}, {"status", "completed"}, {"exit_code", 0},
                                          {"result", {{"status", "completed"}, {"q", 1}}}}};
    CHECK(rows(samples_csv(g, {&named[0]}))[0] ==
          std::vector<std::string>{"index", "q", "seed", "status", "exit_code", "result.q", "result.status"});
    const auto m = rows(summary_csv(g, p));
    REQUIRE(m.size() == 3);
    CHECK(m[0] == std::vector<std::string>{"q", "samples", "ok", "moduli.G.mean", "moduli.G.sem"});
    CHECK(m[1][0] == "4");
    CHECK(m[1][2] == "3");
    CHECK(std::strtod(m[1][3].c_str(), nullptr) == Approx(2).epsilon(1e-15));
    CHECK(std::strtod(m[1][4].c_str(), nullptr) == Approx(1 / std::sqrt(3.0)).epsilon(1e-15));  // sd 1, n 3
    CHECK(m[2][1] == "3");
    CHECK(m[2][2] == "2");  // the failed sample is not averaged
    CHECK(std::strtod(m[2][3].c_str(), nullptr) == Approx(15).epsilon(1e-15));
}
