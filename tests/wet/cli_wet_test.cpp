// `fibernet wet` end to end on a tiny network, and bad input: exit 2, a message naming the value, no output files.
#include <catch2/catch.hpp>

#include "../support/cli_background.hpp"
#include "../support/cli_run.hpp"
#include <cstdlib>
#include <algorithm>
#include <fstream>
#include <sstream>
#include <vector>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <thread>
#include <nlohmann/json.hpp>

namespace {
using clitest::exists;
using clitest::slurp;
using clitest::tmpdir;
using clitest::write;
int run(const std::string& args) { return clitest::run("wet " + args); }

using clitest::wait_until;

// `fibernet wet ARGS` in the background (clitest::start_background).
pid_t start(std::vector<std::string> args) {
    args.insert(args.begin(), "wet");
    return clitest::start_background(args);
}

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(slurp(path), nullptr, false); }

int lines(const std::string& path) {
    const std::string t = slurp(path);
    return static_cast<int>(std::count(t.begin(), t.end(), '\n'));
}

bool any_tmp(const std::string& dir) {
    for (const auto& f : std::filesystem::directory_iterator(dir))
        if (f.path().extension() == ".tmp") return true;
    return false;
}
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
    // The pores block classifies every face (pores.hpp): on the torus the classes tile the box, pores.csv has the
    // pores only, and the wall width is the default contact distance 2/a.
    const nlohmann::json s = read_json(out + "/summary.json");
    REQUIRE(s.is_object());
    const nlohmann::json& p = s["runs"][0]["pores"]["wet"];
    CHECK(p["cover"].get<double>() == Approx(1).epsilon(1e-12));
    CHECK(p["wall_width"].get<double>() == Approx(0.2));
    double pores = 0;
    for (const char* k : {"wall_area", "island_area", "open_area"}) pores += p[k].get<double>();
    CHECK(p["remainder_area"].get<double>() == Approx(pores).margin(1e-9 * p["box_area"].get<double>()));
    CHECK(lines(out + "/pores.csv") == 1 + 2 * p["count"].get<int>());  // header, dry and wet rows (beta = 0)
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
    const std::string latin1 = tmpdir() + "/latin1.txt";  // its text goes into summary.json: exit 3 before
    write(latin1, "# r\xe9sultats Surface Evolver\n0 -1\n90 0\n");
    const std::string huge = tmpdir() + "/huge.txt";
    write(huge, "0 -1e6\n90 0\n");
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
                          Case{"--law " + latin1, "latin1.txt:1: byte 0xe9 at column 4 is not UTF-8"},
                          // Magnitudes outside the model (a run with --beta 1e9 grew to 98,625 bridges on 38 fibers).
                          Case{"--beta 1e9", "[wet].beta = 1000000000 exceeds the stretching stiffness 4 a^2 = 400"},
                          Case{"--betas 0,500", "--betas entry = 500 exceeds the stretching stiffness"},
                          Case{"--a 3 --beta 40", "4 a^2 = 36 (a = 3)"},
                          Case{"--law " + huge, "huge.txt: row 1: value = -1000000 is not E / (beta l) of order 1"},
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
                          Case{"--modulus-strain 1e-4 --no-moduli", "--modulus-strain given with --no-moduli"},
                          // The draw's seed is as unused as its fraction without crossings = fraction.
                          Case{"--wet-seed 5", "[wet].seed = 5 is used only with crossings = fraction"},
                          Case{"--crossings free --wet-seed 5", "[wet].seed = 5 is used only with crossings = fraction"},
                          // An empty entry was dropped: 0,,0.1 ran two betas.
                          Case{"--betas 0,,0.1", "--betas '0,,0.1': entry 2 is empty"},
                          Case{"--betas 0,0.1,", "--betas '0,0.1,': entry 3 is empty"},
                          Case{"--betas 0,abc", "--betas '0,abc': entry 2, 'abc', is not a number"}}) {
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

TEST_CASE("cli wet: --free-box on the smooth model", "[wet][cli][free_box][smooth]") {
    const std::string out = tmpdir() + "/free_smooth";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    // Capillary load on a rigid network: the mean normal stress at the fixed box is well above tolerance, and the
    // search ends below it, at a stable box (one stiffness eigenvalue, positive), with its modulus.
    REQUIRE(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --free-box --free-box-tol 1e-4 -o " +
                out) == 0);
    const nlohmann::json j = nlohmann::json::parse(slurp(out + "/summary.json"));
    const nlohmann::json& f = j["runs"][0]["free_box"];
    INFO(f.dump(1).substr(0, 2000));
    CHECK(f["converged"] == true);
    CHECK(f["residual_fixed_box"].get<double>() > 1e-2);
    CHECK(f["residual"].get<double>() <= 1e-4);
    REQUIRE(f["stiffness_eigenvalues"].size() == 1);
    CHECK(f["stiffness_eigenvalues"][0].get<double>() > 0);
    CHECK(f["shear_modulus"].get<double>() > 0);
    CHECK(f["bridges"].get<int>() > 0);
    CHECK(slurp(out + "/sweep.csv").find(",converged,") != std::string::npos);
    CHECK(slurp(tmpdir() + "/stderr").find("free box iter") != std::string::npos);
}

TEST_CASE("cli wet: a law file refused leaves a previous run's outputs as they were", "[wet][cli][input]") {
    // A law with a Latin-1 comment left header-only CSVs and deleted the SVGs of the previous run in the directory.
    const std::string out = tmpdir() + "/keep", law = tmpdir() + "/keep_law.txt";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    REQUIRE(run("--L 2.5 --q 5 --betas 0.01 --no-moduli -q -o " + out) == 0);
    std::vector<std::string> before;
    for (const char* f : {"summary.json", "sweep.csv", "pores.csv", "network.svg", "pores.svg"}) before.push_back(slurp(out + "/" + f));
    write(law, "# r\xe9sultats\n0 -1\n90 0\n");
    CHECK(run("--L 2.5 --q 5 --betas 0.01 --no-moduli -q --law " + law + " -o " + out) == 2);
    size_t k = 0;
    for (const char* f : {"summary.json", "sweep.csv", "pores.csv", "network.svg", "pores.svg"}) {
        INFO(f);
        CHECK(slurp(out + "/" + f) == before[k++]);
    }
}

TEST_CASE("cli wet: a scene's law file is found next to the scene, and --law replaces it unopened", "[wet][cli]") {
    // Before, a scene's law was opened relative to the current directory, and also when --law replaced it.
    const std::string dir = tmpdir() + "/lawdir", out = tmpdir() + "/lawrun";
    REQUIRE(std::system(("rm -rf " + dir + " " + out + " && mkdir -p " + dir).c_str()) == 0);
    write(dir + "/law.txt", "0 -1\n90 0\n");
    write(dir + "/near.toml", "[network]\nL = 2.5\nq = 5\n[wet]\nlaw = \"law.txt\"\nbeta = 0\n");
    write(dir + "/gone.toml", "[network]\nL = 2.5\nq = 5\n[wet]\nlaw = \"no_such_law.txt\"\nbeta = 0\n");
    CHECK(run(dir + "/near.toml --no-moduli -q -o " + out) == 0);  // run from another directory
    CHECK(read_json(out + "/summary.json")["wet"]["law"] == dir + "/law.txt");
    CHECK(run(dir + "/gone.toml --no-moduli -q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find(dir + "/no_such_law.txt") != std::string::npos);
    CHECK(run(dir + "/gone.toml --law " + dir + "/law.txt --no-moduli -q -o " + out) == 0);
}

TEST_CASE("cli wet: summary.json records what reproduces the run", "[wet][cli]") {
    const std::string out = tmpdir() + "/record", law = tmpdir() + "/record_law.txt", scene = tmpdir() + "/record.toml";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    const std::string law_text = "# E/(beta l)\n0 -1\n45 -0.5\n90 0\n";
    write(law, law_text);
    // Every [wet] setting away from its default, so that each recorded value is this run's.
    write(scene, "[network]\nL = 2.5\nq = 8\npl = 1\nseed = 3\n[wet]\ncrossings = \"fraction\"\nfraction = 0.5\n"
                 "max_rounds = 50\nround_iterations = 0\nnewton_ldl = false\nlocal_fraction = 0\n"
                 "local_threshold = 0.2\nlocal_hops = 1\nnewton_eliminate = true\n");
    REQUIRE(run(scene + " --wet-seed 5 --law " + law + " --betas 0,0 --no-moduli -q -o " + out) == 0);
    const nlohmann::json j = read_json(out + "/summary.json");
    REQUIRE(j.is_object());
    const nlohmann::json& w = j["wet"];
    INFO(w.dump(2));
    CHECK(w["seed"] == 5);
    CHECK(w["fraction"] == 0.5);
    CHECK(w["max_rounds"] == 50);
    CHECK(w["round_iterations"] == 0);
    CHECK(w["newton_ldl"] == false);
    CHECK(w["local_fraction"] == 0.0);
    CHECK(w["local_threshold"] == 0.2);
    CHECK(w["local_hops"] == 1);
    CHECK(w["betas"] == nlohmann::json::array({0.0, 0.0}));  // the list asked for, also before any run finished
    CHECK(w["law"] == law);
    CHECK(w["law_table"] == law_text);  // the table itself: the file may change or be gone
    CHECK(w["law_fnv1a"].is_number_unsigned());
    CHECK(w["moduli"] == false);
    CHECK(j["solver"] == nlohmann::json({{"name", "newton"}, {"tol", 1e-10}, {"max_iter", 500}, {"eliminate", true},
                                         {"eliminate_hops", nullptr},  // the event model keeps the solver's hops
                                         {"schwarz_block", nullptr}, {"schwarz_overlap", nullptr}}));
    CHECK(j["prune"] == nlohmann::json::array());
    CHECK(j["parameters"]["seed"] == 3);
    // The default law is named, with no table.
    REQUIRE(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0 --no-moduli -q -o " + out) == 0);
    const nlohmann::json d = read_json(out + "/summary.json");
    CHECK(d["wet"]["law"] == "cos2");
    CHECK(d["wet"]["law_table"].is_null());
    CHECK(d["wet"]["seed"].is_null());  // no draw: crossings = all
    CHECK(d["wet"]["betas"] == nlohmann::json::array({0.0}));
}

TEST_CASE("cli wet: a re-run invalidates the old results, and SIGINT keeps the finished betas", "[wet][cli][signal]") {
    const std::string out = tmpdir() + "/rerun";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    const std::string quick = "--L 2.5 --q 8 --pl 1 --seed 3 --beta 0 --no-moduli -q -o " + out;
    // A new network (L = 5) whose wet beta takes seconds: the signal comes while it runs.
    auto is_new = [&](const nlohmann::json& j) { return j.is_object() && j["parameters"]["L"] == 5.0; };

    SECTION("interrupted in the second beta: the first is kept, on disk and on stdout") {
        REQUIRE(run(quick) == 0);  // an old, complete result with its pictures
        REQUIRE(exists(out + "/network.svg"));
        const pid_t pid = start({"--L", "5", "--q", "10", "--seed", "3", "--betas", "0,0.05", "--no-moduli", "-o", out});
        REQUIRE(wait_until(pid, [&] {
            const nlohmann::json j = read_json(out + "/summary.json");
            return is_new(j) && j["runs"].size() == 1;
        }));
        kill(pid, SIGINT);
        int st = 0;
        REQUIRE(waitpid(pid, &st, 0) == pid);
        REQUIRE(WIFEXITED(st));  // not killed by the signal
        CHECK(WEXITSTATUS(st) == 130);
        CHECK(slurp(tmpdir() + "/bg_stderr").find("wet: interrupted during beta = 0.05 (2 of 2)") != std::string::npos);
        const nlohmann::json j = read_json(out + "/summary.json");
        CHECK(is_new(j));
        CHECK(j["complete"] == false);
        REQUIRE(j["runs"].size() == 1);
        CHECK(j["runs"][0]["beta"] == 0.0);
        const nlohmann::json o = read_json(tmpdir() + "/bg_stdout");  // the finished betas reported
        REQUIRE(o.is_object());
        CHECK(o["complete"] == false);
        CHECK(o["interrupted"] == true);
        CHECK(o["runs"].size() == 1);
        CHECK(lines(out + "/sweep.csv") == 2);  // header and beta 0
        CHECK(slurp(out + "/pores.csv").find("wet,0,") != std::string::npos);
        // The old run's pictures are gone rather than left beside tables they do not show.
        CHECK(!exists(out + "/network.svg"));
        CHECK(!exists(out + "/pores.svg"));
        CHECK(!any_tmp(out));
    }
    SECTION("interrupted in the first beta: the old results were invalidated at the start") {
        REQUIRE(run(quick) == 0);
        REQUIRE(exists(out + "/pores.svg"));
        const pid_t pid = start({"--L", "5", "--q", "10", "--seed", "3", "--betas", "0.05", "--no-moduli", "-q", "-o", out});
        REQUIRE(wait_until(pid, [&] { return is_new(read_json(out + "/summary.json")); }));
        const nlohmann::json j = read_json(out + "/summary.json");
        CHECK(j["complete"] == false);
        CHECK(j["runs"].empty());
        CHECK(j["wet"]["betas"] == nlohmann::json::array({0.05}));
        CHECK(!exists(out + "/network.svg"));
        CHECK(!exists(out + "/pores.svg"));
        CHECK(lines(out + "/sweep.csv") == 1);  // the old rows are gone: header only
        CHECK(lines(out + "/pores.csv") == 1);
        kill(pid, SIGINT);
        int st = 0;
        REQUIRE(waitpid(pid, &st, 0) == pid);
        REQUIRE(WIFEXITED(st));
        CHECK(WEXITSTATUS(st) == 130);
        // -q silences progress, not the interrupt's message.
        CHECK(slurp(tmpdir() + "/bg_stderr").find("wet: interrupted during beta = 0.05 (1 of 1)") != std::string::npos);
        CHECK(read_json(out + "/summary.json")["runs"].empty());
        CHECK(read_json(tmpdir() + "/bg_stdout")["runs"].empty());
        CHECK(!any_tmp(out));
    }
}

TEST_CASE("cli wet: the smooth model relaxes to an equilibrium of the whole energy and reports it", "[wet][cli][smooth]") {
    const std::string out = tmpdir() + "/smooth";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    REQUIRE(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --tol 1e-9 -q -o " + out) == 0);
    const nlohmann::json j = read_json(out + "/summary.json");
    REQUIRE(!j.is_discarded());
    CHECK(j["wet"]["model"] == "smooth");
    CHECK(j["wet"]["skin"] == 0.5);
    const nlohmann::json& r = j["runs"][0];
    CHECK(r["status"] == "stable");
    REQUIRE(r["smooth"].is_object());
    CHECK(r["smooth"]["grad_max"].get<double>() <= 1e-9);
    CHECK(r["smooth"]["list_builds"].get<int>() >= 1);
    // One Newton solve that followed the Hessian pattern; the time split names the list and pattern builds.
    CHECK(r["smooth"]["rounds"] == 1);
    CHECK(r["smooth"]["stale_patterns"] == 0);
    const double total = r["smooth"]["seconds_solver"]["total"].get<double>();
    CHECK(r["smooth"]["seconds_lists"].get<double>() >= 0);
    CHECK(r["smooth"]["seconds_lists"].get<double>() <= total);
    CHECK(r["smooth"]["seconds_patterns"].get<double>() >= 0);
    CHECK(r["smooth"]["seconds_patterns"].get<double>() <= total);
    CHECK(r["energy"]["wet"]["capillary"].get<double>() < 0);
    CHECK(r["bridges"]["final"].get<int>() > 0);
    // The exact linear modulus of the smooth energy and the second difference of relaxed energies agree.
    const double G = r["shear_modulus"]["wet"].get<double>(), Gfd = r["shear_modulus_second_difference"]["wet"].get<double>();
    CHECK(G > 0);
    CHECK(std::abs(G - Gfd) <= 1e-3 * G);
}

TEST_CASE("cli wet: the smooth model with nonlinear elimination reaches an equilibrium of the whole energy",
          "[wet][cli][smooth]") {
    const std::string out = tmpdir() + "/smooth_eliminate";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    REQUIRE(run("--L 2.5 --q 8 --pl 0.5 --seed 3 --beta 0.1 --wet-model smooth --bundle-partners 2 --wet-eliminate "
                "--no-moduli --tol 1e-9 -q -o " + out) == 0);
    const nlohmann::json j = read_json(out + "/summary.json");
    CHECK(j["solver"]["eliminate"] == true);
    CHECK(j["solver"]["eliminate_hops"] == 2);
    const nlohmann::json& r = j["runs"][0];
    CHECK(r["status"] == "stable");
    CHECK(r["smooth"]["grad_max"].get<double>() <= 1e-9);
    CHECK(r["smooth"]["local_solves"].get<int>() > 0);
    CHECK(r["smooth"]["eliminating_iterations"].get<int>() > 0);
    CHECK(r["smooth"]["eliminating_iterations"].get<int>() <= r["smooth"]["factorizations"].get<int>());
    CHECK(r["energy"]["wet"]["capillary"].get<double>() < 0);
}

TEST_CASE("cli wet: the smooth model with the Schwarz sweep reaches an equilibrium of the whole energy",
          "[wet][cli][smooth]") {
    // Blocks of 100 coordinates on a network of about 1000: every global iteration relaxes several blocks first.
    const std::string out = tmpdir() + "/smooth_schwarz";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    REQUIRE(run("--L 2.5 --q 8 --pl 0.5 --seed 3 --beta 0.1 --wet-model smooth --bundle-partners 2 --wet-schwarz 100 "
                "--no-moduli --tol 1e-9 -q -o " + out) == 0);
    const nlohmann::json j = read_json(out + "/summary.json");
    CHECK(j["solver"]["eliminate"] == true);
    CHECK(j["solver"]["schwarz_block"] == 100);
    CHECK(j["solver"]["schwarz_overlap"] == 4);
    const nlohmann::json& r = j["runs"][0];
    CHECK(r["status"] == "stable");
    CHECK(r["smooth"]["grad_max"].get<double>() <= 1e-9);
    // A sweep before every global step, each over several blocks.
    CHECK(r["smooth"]["eliminating_iterations"].get<int>() >= r["solver"]["iterations"].get<int>());
    CHECK(r["smooth"]["local_solves"].get<int>() >= 2 * r["smooth"]["eliminating_iterations"].get<int>());
    CHECK(r["energy"]["wet"]["capillary"].get<double>() < 0);
}

TEST_CASE("cli wet: the smooth model with projected Newton and a partner cap", "[wet][cli][smooth]") {
    // A cap of 1 binds at beta = 0.1 on this network (the capillary energy is above the uncapped one), and the exact
    // linear modulus, whose strain derivatives carry the cap's coupling, matches the second difference.
    const std::string out = tmpdir() + "/smooth_cap";
    const std::string net = "--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.1 --wet-model smooth --tol 1e-9 -q -o " + out;
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    REQUIRE(run(net) == 0);
    CHECK(slurp(tmpdir() + "/stderr").find("without a partner cap") != std::string::npos);  // said even with -q
    const double uncapped = read_json(out + "/summary.json")["runs"][0]["energy"]["wet"]["capillary"].get<double>();
    REQUIRE(run("--projected --bundle-partners 1 " + net) == 0);
    CHECK(slurp(tmpdir() + "/stderr").find("without a partner cap") == std::string::npos);
    const nlohmann::json j = read_json(out + "/summary.json");
    CHECK(j["wet"]["newton_projected"] == true);
    CHECK(j["wet"]["bundle_partners"] == 1);
    const nlohmann::json& r = j["runs"][0];
    CHECK(r["status"] == "stable");
    CHECK(r["smooth"]["grad_max"].get<double>() <= 1e-9);
    CHECK(r["energy"]["wet"]["capillary"].get<double>() < 0);
    CHECK(r["energy"]["wet"]["capillary"].get<double>() > uncapped + 0.1);
    const double G = r["shear_modulus"]["wet"].get<double>(), Gfd = r["shear_modulus_second_difference"]["wet"].get<double>();
    CHECK(G > 0);
    CHECK(std::abs(G - Gfd) <= 1e-3 * G);
    // Projected Newton belongs to the smooth model.
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.1 --projected -q -o " + out + "_events") == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].newton_projected") != std::string::npos);
}

TEST_CASE("cli wet: the smooth model's options are refused by name", "[wet][cli][smooth][input]") {
    const std::string out = tmpdir() + "/smooth_bad";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model drops -q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("'drops'") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --skin 0 -q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].skin") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --crossing-width -1 -q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].crossing_width") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --bundle-partners -2 -q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].bundle_partners = -2") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --wet-eliminate --wet-eliminate-hops -1 "
              "-q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].eliminate_hops = -1") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --wet-schwarz -5 -q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].schwarz_block = -5") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --wet-schwarz 100 --wet-schwarz-overlap -1 "
              "-q -o " + out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].schwarz_overlap = -1") != std::string::npos);
    CHECK(run("--L 2.5 --q 8 --pl 1 --seed 3 --beta 0.01 --wet-model smooth --wet-schwarz 100 --solver lbfgs -q -o " +
              out) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("[wet].schwarz_block = 100 needs a solver with nonlinear elimination") !=
          std::string::npos);
    CHECK(!exists(out));
}
