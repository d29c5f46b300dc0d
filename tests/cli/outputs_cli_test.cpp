// Output paths of rigidity, percolation and compare are checked before any work (exit 2, nothing written);
// percolation --resume refuses another --seed; compare reports progress per network.
#include <catch2/catch.hpp>

#include <sstream>
#include <vector>

#include "../support/cli_run.hpp"

using namespace clitest;

TEST_CASE("cli rigidity: a bad --out leaves no --svg behind", "[cli][rigidity][input]") {
    const std::string svg = tmpdir() + "/rig.svg", json = tmpdir() + "/nodir/rig.json";
    CHECK(run("rigidity --L 4 --q 6 --open --svg " + svg + " --out " + json) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("--out '" + json + "'") != std::string::npos);
    CHECK(!exists(svg));
    // One file for both: the JSON would replace the picture.
    CHECK(run("rigidity --L 4 --q 6 --open --svg " + svg + " --out " + svg) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("also given as --svg") != std::string::npos);
    CHECK(!exists(svg));
}

TEST_CASE("cli percolation: a bad --table is refused before any sample", "[cli][percolation][input]") {
    const std::string csv = tmpdir() + "/perc_table.csv", table = tmpdir() + "/nodir/t.csv";
    const std::string base = "percolation --pl 1 --L 3 --q-min 4 --q-max 5 --q-step 1 --samples 2 --out " + csv;
    CHECK(run(base + " --table " + table) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("--table '" + table + "'") != std::string::npos);
    CHECK(slurp(tmpdir() + "/stderr").find("samples") == std::string::npos);  // no progress: nothing ran
    CHECK(!exists(csv));
    CHECK(run(base + " --summary " + tmpdir() + "/nodir/s.json") == 2);
    CHECK(!exists(csv));
    CHECK(run(base + " --table " + csv) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("also given as --out") != std::string::npos);
    CHECK(!exists(csv));
}

TEST_CASE("cli percolation: --resume refuses samples of another --seed", "[cli][percolation][input]") {
    const std::string csv = tmpdir() + "/perc_seed.csv";
    const std::string base = "percolation --pl 1 --L 3 --q-min 4 --q-max 5 --q-step 1 --out " + csv;
    REQUIRE(run(base + " --samples 2 --seed 3") == 0);
    const std::string rows = slurp(csv);
    CHECK(run(base + " --samples 3 --seed 7 --resume") == 2);
    CHECK(slurp(tmpdir() + "/stderr").find(csv + ":2: seed = ") != std::string::npos);
    CHECK(slurp(tmpdir() + "/stderr").find("is not the seed --seed 7 gives") != std::string::npos);
    CHECK(slurp(csv) == rows);
    CHECK(run(base + " --samples 3 --resume") == 2);  // the default --seed 1 is another seed too
    REQUIRE(run(base + " --samples 3 --seed 3 --resume") == 0);
    CHECK(slurp(csv).size() > rows.size());
    // Rows of an L that this run leaves out are still checked (their L and q are exact in the CSV).
    const std::string other = "percolation --pl 1 --L 4 --q-min 4 --q-max 5 --q-step 1 --samples 2 --out " + csv;
    CHECK(run(other + " --seed 8 --resume") == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("is not the seed --seed 8 gives") != std::string::npos);
}

TEST_CASE("cli percolation: --resume refuses rows no run writes, and a sample twice", "[cli][percolation][input]") {
    // A duplicated row was counted twice, and rigid_spanning = 7 was taken as rigid.
    const std::string csv = tmpdir() + "/perc_rows.csv";
    const std::string base = "percolation --pl 1 --L 3 --q-min 4 --q-max 5 --q-step 1 --seed 3 --out " + csv;
    REQUIRE(run(base + " --samples 2") == 0);
    const std::string rows = slurp(csv);
    const auto second = rows.find('\n') + 1, third = rows.find('\n', second) + 1;
    const std::string row = rows.substr(second, third - second);  // L,q,sample,seed,fibers,d,rigid,connected
    auto field = [&](int k, const std::string& value) {  // the first data row with field k replaced
        std::vector<std::string> f;
        std::istringstream is(row.substr(0, row.size() - 1));
        for (std::string x; std::getline(is, x, ',');) f.push_back(x);
        f[k] = value;
        std::string line;
        for (size_t i = 0; i < f.size(); ++i) line += (i ? "," : "") + f[i];
        return rows.substr(0, second) + line + "\n" + rows.substr(third);
    };
    struct Case {
        std::string csv, message;
    };
    const Case cases[] = {
        {rows + row, "is already on line 2 (a sample counts once)"},
        {field(7, "7"), "rigid_spanning = 7 contradicts d = "},
        {field(8, "2"), "connected_spanning = 2 is not 0 or 1"},
        {field(6, "5"), "d = 5 is not a clamp's degrees of freedom"},
        {field(3, "-1"), "sample = -1 is negative"},
        {field(9, "-3"), "seconds = -3 is not a duration"},
    };
    for (const auto& c : cases) {
        INFO(c.message);
        write(csv, c.csv);
        CHECK(run(base + " --samples 3 --resume") == 2);
        CHECK(slurp(tmpdir() + "/stderr").find(csv + ":") != std::string::npos);
        CHECK(slurp(tmpdir() + "/stderr").find(c.message) != std::string::npos);
        CHECK(slurp(csv) == c.csv);
    }
    // A sample number past int (sscanf read 4294967296 as 0, so sample 0 counted twice): not a row this run writes,
    // and not a torn last line either, so it is refused with its line (skipped, its sample would be run again and
    // the CSV would hold a damaged row between whole ones).
    const std::string wrapped = field(3, "4294967296");
    write(csv, wrapped);
    CHECK(run(base + " --samples 2 --resume") == 2);
    CHECK(slurp(tmpdir() + "/stderr").find(csv + ":2: not a percolation row") != std::string::npos);
    CHECK(slurp(csv) == wrapped);
    write(csv, rows);
    CHECK(run(base + " --samples 3 --resume") == 0);
}

TEST_CASE("cli compare: --out is checked first; progress per network on stderr, -q silences it", "[cli][compare]") {
    const std::string json = tmpdir() + "/nodir/cmp.json";
    // --max-dofs 10 would refuse the first network: the --out message shows that nothing was generated first.
    CHECK(run("compare --open --L 2.5 --q 6 --samples 2 --max-dofs 10 --out " + json) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("--out '" + json + "'") != std::string::npos);
    REQUIRE(run("compare --open --L 2.5 --q 6 --pl 0.8 --seed 5 --samples 2") == 0);
    const std::string err = slurp(tmpdir() + "/stderr");
    CHECK(err.find("compare: network 1 of 2 (seed 5)") != std::string::npos);
    CHECK(err.find("compare: network 2 of 2 (seed 6)") != std::string::npos);
    CHECK(err.find("floppy modes") != std::string::npos);
    REQUIRE(run("compare --open --L 2.5 --q 6 --pl 0.8 --seed 5 --samples 2 -q") == 0);
    CHECK(slurp(tmpdir() + "/stderr").empty());
}
