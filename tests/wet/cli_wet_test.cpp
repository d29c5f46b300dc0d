// `fibernet wet` end to end on a tiny network, and bad input: exit 2, a message naming the value, no output files.
#include <catch2/catch.hpp>

#include "../support/cli_run.hpp"
#include <cstdlib>
#include <algorithm>
#include <fstream>
#include <sstream>
#include <vector>
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
    const std::string out = tmpdir() + "/ok/new/dir";  // -o makes missing directories
    REQUIRE(std::system(("rm -rf " + tmpdir() + "/ok").c_str()) == 0);
    // beta = 0: the wet state is the dry one, so the run is quick and stable.
    REQUIRE(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0 --no-moduli -o " + out) == 0);
    for (const char* f : {"summary.json", "sweep.csv", "pores.csv", "network.svg", "pores.svg"}) CHECK(exists(out + "/" + f));
    const std::string j = slurp(out + "/summary.json");
    CHECK(j.find("\"capillary\"") != std::string::npos);
    CHECK(j.find("\"parameters\"") != std::string::npos);  // what generated the network
    CHECK(j.find("\"pl\": 1.0") != std::string::npos);
    CHECK(j.find("\"strain\": \"shear\"") != std::string::npos);  // the load the run was under, with gamma
    CHECK(j.find("\"bundle_partners\": 0") != std::string::npos);    // no cap by default
    CHECK(j.find("\"capped\": 0") != std::string::npos);
    CHECK(j.find("\"stable\"") != std::string::npos);
    CHECK(j.find("\"local_rounds\": 0") != std::string::npos);  // beta = 0: one global solve
    CHECK(j.find("\"complete\": true") != std::string::npos);  // false in the copies written between betas
    CHECK(slurp(out + "/sweep.csv").rfind("beta,status,bridges", 0) == 0);
    CHECK(slurp(out + "/sweep.csv").find("G_dry,G_wet,G_dry_fd,G_wet_fd") != std::string::npos);
    // Progress on stderr by default: a line per beta and per active-set round; none with --quiet.
    const std::string err = slurp(tmpdir() + "/stderr");
    CHECK(err.find("wet: beta = 0 (1 of 1)") != std::string::npos);
    CHECK(err.find("wet round  1:") != std::string::npos);
    CHECK(err.find("wet: beta = 0: stable after 1 round(s)") != std::string::npos);
    REQUIRE(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0 --no-moduli -q") == 0);
    CHECK(slurp(tmpdir() + "/stderr").empty());
}

TEST_CASE("cli wet: the shear moduli, linear and second difference, in the JSON and the sweep", "[wet][cli]") {
    const std::string out = tmpdir() + "/moduli";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    // A rigid network (pl = 1) at beta = 0: the linear modulus and the second difference at 1e-5 agree.
    REQUIRE(run("--L 2.5 --q 10 --pl 1 --seed 4 --beta 0 --modulus-strain 1e-5 -q -o " + out) == 0);
    const std::string j = slurp(out + "/summary.json");
    for (const char* key : {"\"shear_modulus\"", "\"shear_modulus_error\"", "\"shear_modulus_second_difference\"",
                            "\"strain\": 1e-05"})
        CHECK(j.find(key) != std::string::npos);
    // The sweep's row: G_dry, G_wet (linear) and G_dry_fd, G_wet_fd (second difference), by the header's names.
    std::istringstream csv(slurp(out + "/sweep.csv"));
    std::string header, row;
    REQUIRE(std::getline(csv, header));
    REQUIRE(std::getline(csv, row));
    auto fields = [](const std::string& line) {
        std::vector<std::string> f;
        std::stringstream ss(line);
        for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
        return f;
    };
    const auto names = fields(header), values = fields(row);
    REQUIRE(names.size() == values.size());
    auto at = [&](const std::string& name) {
        const auto it = std::find(names.begin(), names.end(), name);
        REQUIRE(it != names.end());
        return std::stod(values[static_cast<size_t>(it - names.begin())]);
    };
    INFO(header << "\n" << row);
    CHECK(at("G_wet") > 1e-3);
    CHECK(at("G_wet") == Approx(at("G_dry")).epsilon(1e-12));  // beta = 0: the wet network is the dry one
    CHECK(at("G_wet_fd") == Approx(at("G_wet")).epsilon(1e-4));
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
                          Case{"--fraction 0.5", "fraction = 0.5 is used only with crossings = fraction"},
                          Case{"--bundle-partners -1", "bundle_partners = -1"},
                          Case{"--crossings some", "some"}, Case{"--law " + law, "100"},
                          Case{"--law " + unsorted, "30"}, Case{scene, "fraction = 1.5"},
                          Case{"--prune ends", "prune \"ends\" is not valid for `fibernet wet`"},
                          Case{"--free-box --open", "periodic"}, Case{"--free-box --free-box-shape round", "round"},
                          Case{"--free-box --free-box-tol 0", "free_box_tol = 0"},
                          Case{"--free-box --free-box-tol nan", "free_box_tol = nan"},
                          Case{"--free-box-tol 1e-3", "--free-box-tol given without --free-box"},
                          Case{"--free-box-shape full", "--free-box-shape given without --free-box"},
                          Case{"-q -v", "--verbose and --quiet"},
                          Case{"--modulus-strain -1e-4", "modulus strain = -0.0001"},
                          Case{"--modulus-strain nan", "modulus strain = nan"},
                          Case{"--modulus-strain 0", "modulus strain = 0"},
                          Case{"--modulus-strain 0.2", "modulus strain = 0.2"},
                          Case{"--modulus-strain 1e-4 --no-moduli", "--modulus-strain given with --no-moduli"}}) {
        INFO(c.args);
        CHECK(run("--L 2.5 --q 5 " + c.args + " -o " + out) == 2);
        CHECK(slurp(tmpdir() + "/stderr").find(c.needle) != std::string::npos);
        CHECK(!exists(out + "/summary.json"));
    }
    // A scene's fraction with --crossings fraction from the command line: the combination is checked with it in.
    const std::string frac = tmpdir() + "/frac.toml";
    write(frac, "[network]\nL = 2.5\nq = 5\n[wet]\nfraction = 0.5\nbeta = 0\n");
    CHECK(run(frac + " --crossings fraction --no-moduli -q") == 0);
    CHECK(run(frac + " --no-moduli -q") == 2);
    // An output directory that cannot be made (a file is in the way) is refused before any work.
    CHECK(run("--L 2.5 --q 5 --beta 0 -o " + law + "/sub") == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("cannot create the directory") != std::string::npos);
}

TEST_CASE("cli wet: --free-box reports the zero-stress box, and exit 1 when it is not found", "[wet][cli][free_box]") {
    const std::string out = tmpdir() + "/free";
    REQUIRE(std::system(("mkdir -p " + out).c_str()) == 0);
    // beta = 0 on a rigid network strained by 2 %: the free box goes back to the reference, s = 1 / 1.02.
    const std::string net = "--L 2.5 --q 10 --pl 1 --seed 4 --beta 0 --no-moduli --strain isotropic --gamma 0.02 --free-box";
    REQUIRE(run(net + " --free-box-tol 1e-6 -o " + out) == 0);
    const std::string j = slurp(out + "/summary.json");
    for (const char* key : {"\"free_box\"", "\"areal_shrinkage\"", "\"residual\"", "\"iterations\"", "\"converged\": true",
                            "\"stiffness_eigenvalues\"", "\"shape\": \"isotropic\""})
        CHECK(j.find(key) != std::string::npos);
    const std::string csv = slurp(out + "/sweep.csv");
    CHECK(csv.find(",free_box,s,areal_shrinkage,free_box_residual,free_box_iterations") != std::string::npos);
    CHECK(csv.find(",converged,0.98039") != std::string::npos);  // s = 1 / 1.02 = 0.980392...
    CHECK(slurp(tmpdir() + "/stderr").find("free box iter") != std::string::npos);  // progress per iteration
    CHECK(slurp(out + "/pores.csv").find("free_box,0,") != std::string::npos);
    // With the moduli: the linear shear modulus at the free box (the last column), here the reference's (pl = 1: rigid).
    const std::string net_moduli = "--L 2.5 --q 10 --pl 1 --seed 4 --beta 0 --strain isotropic --gamma 0.02 --free-box";
    REQUIRE(run(net_moduli + " --free-box-tol 1e-6 -q -o " + out + "/moduli") == 0);
    const std::string csv_m = slurp(out + "/moduli/sweep.csv");
    REQUIRE(csv_m.find(",free_box_iterations,G_free_box\n") != std::string::npos);
    const std::string last = csv_m.substr(csv_m.rfind(',', csv_m.size() - 2) + 1);
    CHECK(std::stod(last) > 1e-3);
    // A tolerance below round-off cannot be met: not converged, exit 1, and the JSON says so.
    CHECK(run(net + " --free-box-tol 1e-300") == 1);
    const std::string k = slurp(tmpdir() + "/stdout");
    CHECK(k.find("\"converged\": false") != std::string::npos);
    CHECK(k.find("\"status\": \"free_box_not_converged\"") != std::string::npos);
}
