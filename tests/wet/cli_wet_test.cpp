// `fibernet wet` end to end on a tiny network, and bad input: exit 2, a message naming the value, no output files.
#include <catch2/catch.hpp>

#include "../support/cli_run.hpp"
#include <cstdlib>
#include <fstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace {
using clitest::exists;
using clitest::slurp;
using clitest::tmpdir;
using clitest::write;
int run(const std::string& args) { return clitest::run("wet " + args); }
}  // namespace

TEST_CASE("cli wet: a small run writes its documented outputs", "[wet][cli]") {
    const std::string out = tmpdir() + "/ok";
    REQUIRE(std::system(("mkdir -p " + out).c_str()) == 0);
    // beta = 0: the wet state is the dry one, so the run is quick and stable.
    REQUIRE(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0 --no-moduli -o " + out) == 0);
    for (const char* f : {"summary.json", "sweep.csv", "pores.csv", "network.svg", "pores.svg"}) CHECK(exists(out + "/" + f));
    const std::string j = slurp(out + "/summary.json");
    CHECK(j.find("\"capillary\"") != std::string::npos);
    CHECK(j.find("\"stable\"") != std::string::npos);
    CHECK(slurp(out + "/sweep.csv").rfind("beta,status,bridges", 0) == 0);
}

TEST_CASE("cli wet: bad input exits 2 and names the value", "[wet][cli]") {
    const std::string out = tmpdir() + "/bad";
    REQUIRE(std::system(("mkdir -p " + out).c_str()) == 0);
    const std::string law = tmpdir() + "/law.txt", unsorted = tmpdir() + "/unsorted.txt", scene = tmpdir() + "/wet.toml";
    write(law, "0 -1\n45 -0.5\n100 0\n");
    write(unsorted, "0 -1\n60 -0.2\n30 -0.7\n90 0\n");
    write(scene, "[network]\nL = 2.5\nq = 5\n[wet]\nfraction = 1.5\n");
    struct Case {
        std::string args, needle;
    };
    for (const Case& c : {Case{"--beta -1", "beta = -1"}, Case{"--beta nan", "beta"}, Case{"--betas 0,-0.5", "-0.5"},
                          Case{"--crossings fraction --fraction 2", "fraction = 2"},
                          Case{"--crossings some", "some"}, Case{"--law " + law, "100"},
                          Case{"--law " + unsorted, "30"}, Case{scene, "fraction = 1.5"},
                          Case{"--prune ends", "prune \"ends\" is not valid for `fibernet wet`"}}) {
        INFO(c.args);
        CHECK(run("--L 2.5 --q 5 " + c.args + " -o " + out) == 2);
        CHECK(slurp(tmpdir() + "/stderr").find(c.needle) != std::string::npos);
        CHECK(!exists(out + "/summary.json"));
    }
}
