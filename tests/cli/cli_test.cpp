// End-to-end checks of the `fibernet` executable: outputs, exit codes, and bad input (exit 2, no output file).
#include <catch2/catch.hpp>

#include "../support/cli_run.hpp"
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>
#include <sys/wait.h>
#include <unistd.h>

using clitest::exists;
using clitest::run;
using clitest::slurp;
using clitest::tmpdir;

TEST_CASE("cli: generate and export write documented files", "[cli]") {
    const std::string net = tmpdir() + "/net.txt", model = tmpdir() + "/model.txt";
    REQUIRE(run("generate --L 4 --q 5 --pl 1 --seed 1 -o " + net) == 0);
    CHECK(slurp(net).rfind("fibernet-network 1\n", 0) == 0);
    REQUIRE(run("export --network " + net + " --scheme even -o " + model) == 0);
    CHECK(slurp(model).rfind("fibernet-model 2\n", 0) == 0);
    REQUIRE(run("info --network " + net) == 0);
    CHECK(slurp(tmpdir() + "/stdout").find("\"supernodes\"") != std::string::npos);
}

TEST_CASE("cli: bad input exits 2, names the value and writes no output file", "[cli][input]") {
    const std::string out = tmpdir() + "/should_not_exist.txt";
    struct Case {
        std::string args, message;
    };
    const Case cases[] = {
        {"generate --q -3", "q (density) = -3"},
        {"generate --q 0", "q (density) = 0"},
        {"generate --pl 1.5", "pl (crosslink probability) = 1.5"},
        {"generate --pl nan", "pl (crosslink probability) = nan"},
        {"generate --L 1.5", "L (box side in fiber lengths) = 1.5"},
        {"generate --L inf", "is not a finite number"},
        {"export --nseg 0", "n_seg = 0"},
        {"export --a -1", "a (aspect ratio) = -1"},
        {"export --scheme odd", "'odd'"},
        {"generate --frobnicate", "frobnicate"},
        {"generate --q abc", "abc"},
        {"export --network /nonexistent.net", "nonexistent"},
        {"nosuchcmd", "unknown command 'nosuchcmd' (expected one of: generate,"},
        {"generate --seed -1", "seed -1 is not an integer in [0, 2^64)"},
        {"generate --seed 18446744073709551616", "seed 18446744073709551616 is not an integer"},
        {"relax --L 3 --q 5 --strain uniaxial --gamma -2", "gamma = -2 flips or collapses the box"},
        {"relax --L 3 --q 5 --strain isotropic --gamma -3", "gamma = -3 flips or collapses the box"},
        {"relax --L 3 --q 5 --gamma 0.01 --solver lbfgs --eliminate", "--eliminate needs a solver with nonlinear elimination"},
        // The dry solves' elimination flag would do nothing in a wet run: the message names the wet one.
        {"wet --L 2.5 --q 5 --betas 0 --no-eliminate", "the wet relaxation's is --wet-eliminate"},
        {"wet --L 2.5 --q 5 --betas 0 --solver lbfgs --wet-eliminate", "newton_eliminate = true needs a solver with nonlinear"},
    };
    for (const auto& c : cases) {
        std::remove(out.c_str());
        INFO(c.args);
        CHECK(run(c.args + " -o " + out) == 2);
        CHECK(slurp(tmpdir() + "/stderr").find(c.message) != std::string::npos);
        CHECK(!exists(out));
    }
    // A malformed network file.
    const std::string bad = tmpdir() + "/bad.net";
    std::ofstream(bad) << "fibernet-network 1\nbox 10 open\nfibers 1\n0 0 zero 1\ncrossings 0\n";
    CHECK(run("export --network " + bad + " -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find(bad + ":4: fiber theta = 'zero' is not a number") != std::string::npos);
    CHECK(!exists(out));
    // Generation flags beside a saved network would be ignored silently.
    REQUIRE(run("generate --L 3 --q 5 -o " + tmpdir() + "/saved.net") == 0);
    for (const char* flag : {"--pl 0.2", "--L 9", "--q 3", "--seed 5", "--open"}) {
        INFO(flag);
        CHECK(run("export --network " + tmpdir() + "/saved.net " + flag + " -o " + out) == 2);
        CHECK(slurp(tmpdir() + "/stderr").find("has no effect on a saved network") != std::string::npos);
        CHECK(!exists(out));
    }
    // A malformed scene.
    const std::string scene = tmpdir() + "/bad.toml";
    std::ofstream(scene) << "[network]\npl = -0.1\n";
    CHECK(run("generate " + scene + " -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("bad.toml: pl (crosslink probability) = -0.1") != std::string::npos);
    CHECK(!exists(out));
}

TEST_CASE("cli: an unknown flag is named as unknown, with the nearest flag, before its value is read as a scene",
          "[cli][input]") {
    const std::string out = tmpdir() + "/should_not_exist.txt";
    struct Case {
        std::string args;
        std::vector<std::string> messages;
    };
    const Case cases[] = {
        // Before, CLI11 took "8" for the scene file: "scene: File does not exist: 8".
        {"modulus --L 4 --density 8", {"unknown flag '--density' for 'fibernet modulus'", "did you mean --q?"}},
        {"modulus --L 4 --seeds 3", {"unknown flag '--seeds'", "did you mean --seed?"}},
        {"modulus --L 4 --gamma-max 0.2", {"unknown flag '--gamma-max' for 'fibernet modulus'", "is a flag of:", "sweep"}},
        {"modulus --L 4 --density=8", {"unknown flag '--density'"}},
        // A flag that takes no value, then a word: the word was the scene file.
        {"modulus --L 4 --open 8", {"'8' is not a scene file (no such file); --open takes no value"}},
        // A value that starts with '-' is a value, not a flag.
        {"relax --L 3 --q 5 --strain isotropic --gamma -3 --frob", {"unknown flag '--frob'"}},
    };
    for (const auto& c : cases) {
        INFO(c.args);
        CHECK(run(c.args + " -o " + out) == 2);
        const std::string err = slurp(tmpdir() + "/stderr");
        for (const std::string& m : c.messages) CHECK(err.find(m) != std::string::npos);
        CHECK(err.find("File does not exist") == std::string::npos);
        CHECK(!exists(out));
    }
    // Known flags with values that look like flags or come in lists still parse.
    CHECK(run("modulus --L 3 --q 5 --gamma -0.01 -q") == 0);
}

TEST_CASE("cli: a result that cannot be written exits 4 naming where it went", "[cli][output]") {
    // A full device: the JSON was lost and the exit code was 0.
    const std::string exe = FIBERNET_EXE, err = tmpdir() + "/full_stderr";
    auto rc_of = [&](const std::string& args) {
        const int rc = std::system((exe + " " + args + " 2>" + err).c_str());
        return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    };
    CHECK(rc_of("modulus --L 3 --q 8 --scheme even -q >/dev/full") == 4);
    CHECK(slurp(err).find("cannot write the results to standard output") != std::string::npos);
    CHECK(rc_of("generate --L 3 --q 4 >/dev/full") == 4);
    CHECK(rc_of("generate --L 3 --q 4 -o /dev/full") == 4);
    CHECK(slurp(err).find("cannot write output '/dev/full' (No space left on device)") != std::string::npos);
    CHECK(rc_of("modulus --L 3 --q 8 --scheme even -q >/dev/null") == 0);  // a device that takes the bytes is fine
}

TEST_CASE("cli: paths that are not UTF-8 are used as given and echoed with U+FFFD", "[cli][input]") {
    // A Latin-1 directory name ended in exit 3 ("invalid UTF-8 byte") where a path went into the JSON results.
    const std::string d = tmpdir() + "/r\xe9s";
    REQUIRE(std::system(("mkdir -p '" + d + "'").c_str()) == 0);
    REQUIRE(run("generate --L 3 --q 4 -o '" + d + "/n.net'") == 0);
    clitest::write(d + "/s.toml", "[network]\nL = 3\nq = 8\n[model]\nscheme = \"even\"\n");
    CHECK(run("modulus '" + d + "/s.toml' -q") == 0);
    CHECK(slurp(tmpdir() + "/stdout").find("r\xef\xbf\xbds/s.toml") != std::string::npos);  // U+FFFD for the 0xe9
    CHECK(run("wet --network '" + d + "/n.net' --betas 0.01 --no-moduli -q -o '" + d + "/out'") == 0);
    CHECK(exists(d + "/out/summary.json"));
    CHECK(run("sweep --network '" + d + "/n.net' --scheme even --gamma-max 0.02 -q -o '" + d + "/sw.csv'") == 0);
    CHECK(run("sweep --network '" + d + "/n.net' --scheme even --gamma-max 0.02 -q --resume -o '" + d + "/sw.csv'") == 0);
}

TEST_CASE("cli: bare fibernet prints the usage, and every command takes -q", "[cli]") {
    CHECK(run("") == 2);
    const std::string err = slurp(tmpdir() + "/stderr");
    CHECK(err.find("Usage: fibernet") != std::string::npos);
    CHECK(err.find("scan") != std::string::npos);
    CHECK(slurp(tmpdir() + "/stdout").empty());
    // generate and export print statistics on stderr; -q silences them. The others take it too.
    for (const std::string c : {"generate --L 3", "export --L 3", "info --L 3", "rigidity --L 3 --open",
                                "modulus --L 3", "relax --L 3"}) {
        INFO(c);
        CHECK(run(c + " -q") == 0);
        CHECK(slurp(tmpdir() + "/stderr").empty());
    }
}
