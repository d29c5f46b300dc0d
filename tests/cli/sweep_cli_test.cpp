// `fibernet sweep` end to end: CSV and checkpoint, resume, bad input.
#include <catch2/catch.hpp>

#include "../support/cli_run.hpp"

using namespace clitest;

TEST_CASE("cli sweep: CSV rows, checkpoint, and --resume of a finished sweep adds nothing", "[cli][sweep]") {
    const std::string csv = tmpdir() + "/sweep.csv";
    const std::string net = "--L 3 --q 7 --seed 4 --scheme even --h 2.5";
    REQUIRE(run("sweep " + net + " --gamma-max 0.02 --step 0.01 -q -o " + csv) == 0);
    const std::string first = slurp(csv);
    CHECK(first.rfind("step,gamma,sigma_xx,sigma_xy", 0) == 0);
    CHECK(exists(csv + ".ckpt"));
    CHECK(slurp(tmpdir() + "/stdout").find("\"completed\"") != std::string::npos);
    REQUIRE(run("sweep " + net + " --gamma-max 0.02 --step 0.01 -q --resume -o " + csv) == 0);
    CHECK(slurp(csv) == first);
    // A checkpoint from another sweep is refused.
    CHECK(run("sweep " + net + " --gamma-max 0.03 --step 0.01 -q --resume -o " + csv) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("gamma_max = 0.02 differs") != std::string::npos);
}

TEST_CASE("cli sweep: bad input exits 2 and writes nothing", "[cli][sweep][input]") {
    const std::string csv = tmpdir() + "/bad_sweep.csv";
    for (const std::string args : {"--gamma-max 0", "--gamma-max 0.1 --step -1", "--gamma-max 0.1 --gamma 0.2",
                                   "--gamma-max nan", "--gamma-max 0.1 --q -1"}) {
        INFO(args);
        CHECK(run("sweep " + args + " -o " + csv) == 2);
        CHECK(!exists(csv));
    }
}
