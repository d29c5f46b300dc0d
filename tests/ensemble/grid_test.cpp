// The samples of an ensemble (ensemble/grid.hpp): axes parsed from --vary, the index order (last axis fastest), grid
// points without the seed axes, and bad specifications refused with the value named.
#include <catch2/catch.hpp>

#include "fibernet/ensemble/grid.hpp"
#include "fibernet/util/error.hpp"

using namespace fibernet;

namespace {
std::string message_of(const std::string& spec) {
    try {
        parse_axis(spec, "here");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
}  // namespace

TEST_CASE("grid: lists, integer ranges and stepped ranges", "[ensemble]") {
    const GridAxis q = parse_axis("q=4,8.5,16", "here");
    CHECK(q.key == "network.q");
    CHECK(q.values == std::vector<std::string>{"4", "8.5", "16"});
    const GridAxis seed = parse_axis("seed=3:6", "here");
    CHECK(seed.key == "network.seed");
    CHECK(seed.values == std::vector<std::string>{"3", "4", "5", "6"});
    const GridAxis g = parse_axis("gamma=0:0.3:0.1", "here");  // 0.1 * 3 is 0.30000000000000004: written as 0.3
    CHECK(g.values == std::vector<std::string>{"0.0", "0.1", "0.2", "0.3"});
    const GridAxis s = parse_axis("scheme=even,seed", "here");
    CHECK(s.values == std::vector<std::string>{"\"even\"", "\"seed\""});
    CHECK(s.labels == std::vector<std::string>{"even", "seed"});
    CHECK(parse_axis("wet.seed=1,2", "here").key == "wet.seed");
    CHECK(parse_axis("a=10,100", "here").key == "model.a");
}

TEST_CASE("grid: index order, replacements and points", "[ensemble]") {
    Grid g;
    g.axes = {parse_axis("a=10,100", "t"), parse_axis("q=4,8,16", "t"), parse_axis("seed=1:2", "t")};
    REQUIRE(g.size() == 12);
    CHECK(g.coordinates(0) == std::vector<std::size_t>{0, 0, 0});
    CHECK(g.coordinates(1) == std::vector<std::size_t>{0, 0, 1});  // the last axis fastest
    CHECK(g.coordinates(11) == std::vector<std::size_t>{1, 2, 1});
    const auto r = g.replacements(7);  // 7 = 1 * 6 + 0 * 2 + 1: a = 100, q = 4, seed = 2
    CHECK(r.at("model.a") == "100");
    CHECK(r.at("network.q") == "4");
    CHECK(r.at("network.seed") == "2");
    CHECK(g.point(6) == g.point(7));  // differ only in the seed
    CHECK(g.point(5) != g.point(6));
    CHECK(g.point(11) == 5);
    CHECK(Grid{}.size() == 1);
}

TEST_CASE("grid: bad specifications name the value", "[ensemble]") {
    CHECK(message_of("q") .find("is not name=values") != std::string::npos);
    CHECK(message_of("density=1,2").find("'density' is not a scene key") != std::string::npos);
    CHECK(message_of("q=4,,8").find("an empty value") != std::string::npos);
    CHECK(message_of("q=4,8,4").find("the value 4 is given twice") != std::string::npos);
    CHECK(message_of("q=8,8.0").find("the value 8.0 is given twice") != std::string::npos);
    CHECK(message_of("seed=5:1").find("last 1 is below first 5") != std::string::npos);
    CHECK(message_of("q=1:2.5").find("takes integers") != std::string::npos);
    CHECK(message_of("q=1:2:0").find("step '0'") != std::string::npos);
    CHECK(message_of("q=1:2:nan").find("step 'nan'") != std::string::npos);
    CHECK(message_of("seed=0:100000000").find("more than 1e7 values") != std::string::npos);
    Grid g;
    g.axes = {parse_axis("q=1,2", "t"), parse_axis("network.q=3", "t")};
    CHECK_THROWS_WITH(check_grid(g, 100, "here"), Catch::Contains("network.q is varied twice"));
    g.axes = {parse_axis("q=1,2,3", "t"), parse_axis("seed=1:40", "t")};
    CHECK_THROWS_WITH(check_grid(g, 100, "here"), Catch::Contains("120 samples, more than 100"));
}

TEST_CASE("grid: a list of points varies its columns together", "[ensemble]") {
    Grid g;
    g.axes = parse_points("# L and q together\nL,q,seed\n10, 8,1\n20,16,1\n", "pts.csv", 0);
    g.axes.push_back(parse_axis("a=10,100", "t"));
    REQUIRE(g.size() == 4);  // 2 points x 2 values of a
    CHECK(g.replacements(2).at("network.L") == "20");
    CHECK(g.replacements(2).at("network.q") == "16");
    CHECK(g.replacements(2).at("model.a") == "10");
    CHECK(!g.replica_axis(2));  // a seed column of the points is part of the point
    CHECK(g.point(3) == 3);
    check_grid(g, 100, "t");
    CHECK_THROWS_WITH(parse_points("L,q\n10,8\n10,8\n", "p.csv", 0), Catch::Contains("p.csv: point 2 is given twice"));
    CHECK_THROWS_WITH(parse_points("L,q\n10\n", "p.csv", 0), Catch::Contains("p.csv:2: 1 fields, the header has 2"));
    CHECK_THROWS_WITH(parse_points("L,density\n10,8\n", "p.csv", 0), Catch::Contains("'density' is not a scene key"));
    CHECK_THROWS_WITH(parse_points("L,q\n", "p.csv", 0), Catch::Contains("no points"));
    CHECK_THROWS_WITH(parse_points("L,q\n10,\n", "p.csv", 0), Catch::Contains("p.csv:2: an empty field"));
}
