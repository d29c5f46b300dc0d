// Checkpoints of `fibernet wet`'s smooth relaxation and --start-state (src/cli/wet_checkpoint.cpp), end to end: an
// unconverged relaxation leaves its last state, a running one writes checkpoints that survive SIGINT, a continued
// relaxation reaches an equilibrium without raising the energy, and bad start states exit 2 naming the file.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "../support/cli_background.hpp"
#include "../support/cli_run.hpp"

using clitest::exists;
using clitest::run;
using clitest::slurp;
using clitest::tmpdir;

namespace {
// The parsed file, or a discarded value when it is missing or not JSON. The results are indexed without const: a
// missing key or run then reads as null and fails its CHECK, where const operator[] would be undefined behaviour.
nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(slurp(path), nullptr, false); }

// A 64-fiber network whose smooth relaxation at beta = 0.1 takes a few hundred Newton iterations.
const std::string kNetwork = "--L 2.5 --q 8 --pl 0.5 --seed 3 --wet-model smooth --bundle-partners 2 --no-moduli";

// A scene that cuts the relaxation after 10 iterations and checkpoints at every iteration.
std::string short_scene() {
    const std::string path = tmpdir() + "/short.toml";
    clitest::write(path, "[wet]\nmax_rounds = 1\nround_iterations = 10\ncheckpoint_seconds = 1e-9\n");
    return path;
}
}  // namespace

TEST_CASE("wet checkpoint: an unconverged relaxation leaves its last state, and --start-state continues it",
          "[cli][wet][checkpoint]") {
    const std::string a = tmpdir() + "/ck_a", b = tmpdir() + "/ck_b";
    REQUIRE(std::system(("rm -rf " + a + " " + b).c_str()) == 0);
    REQUIRE(run("wet " + short_scene() + " " + kNetwork + " -q --betas 0.1 -o " + a) == 1);
    CHECK(slurp(tmpdir() + "/stderr").find("did not converge; its last state is " + a + "/checkpoint_0.txt") !=
          std::string::npos);
    nlohmann::json s = read_json(a + "/summary.json");
    REQUIRE(s.is_object());
    REQUIRE(s["runs"].size() == 1);
    CHECK(s["runs"][0]["status"] == "not_stable");
    CHECK(s["runs"][0]["checkpoint"] == "checkpoint_0.txt");
    CHECK(!exists(a + "/state_0.txt"));  // an unconverged state is no result
    REQUIRE(slurp(a + "/checkpoint_0.txt").rfind("fibernet-model 2\n", 0) == 0);
    nlohmann::json c = read_json(a + "/checkpoint_0.json");
    REQUIRE(c.is_object());
    CHECK(c["fibernet_checkpoint"] == "wet");
    CHECK(c["last"] == true);
    // The budget (10 iterations) cut it: the checkpoint is its last iterate.
    CHECK(c["iterations"] == s["runs"][0]["solver_iterations"]);
    CHECK(c["iterations"].get<int>() >= 1);
    CHECK(c["iterations"].get<int>() <= 10);
    CHECK(c["beta"] == 0.1);
    CHECK(c["grad_max"] == s["runs"][0]["smooth"]["grad_max"]);
    CHECK(c["continue_with"].get<std::string>().find("--betas 0.1 --start-state " + a + "/checkpoint_0.txt") !=
          std::string::npos);
    const double e_checkpoint = c["energy"].get<double>();

    // Continued with the default budget: an equilibrium of the whole energy, reached from the checkpoint without raising
    // the energy (every accepted Newton step lowers it).
    REQUIRE(run("wet " + kNetwork + " -v --betas 0.1 --tol 1e-8 --checkpoint-seconds 1e-9 --start-state " + a + "/checkpoint_0.txt -o " + b) == 0);
    // Its first Newton iterate is the checkpoint's state: the model file holds the displacements exactly. (The trace
    // opens with the dry relaxation, which ends with its summary line "newton: <status> after ...".)
    const std::string trace = slurp(tmpdir() + "/stderr");
    CHECK(trace.find("wet: checkpoint at iteration 1 ") != std::string::npos);  // progress names each checkpoint
    const size_t dry_end = trace.find("newton: ");
    REQUIRE(dry_end != std::string::npos);
    const size_t first = trace.find("newton    0  E = ", dry_end);
    REQUIRE(first != std::string::npos);
    const double e_start = std::strtod(trace.c_str() + first + 17, nullptr);
    CHECK(std::abs(e_start - e_checkpoint) <= 1e-12 * std::abs(e_checkpoint));
    nlohmann::json t = read_json(b + "/summary.json");
    REQUIRE(t.is_object());
    REQUIRE(t["runs"].size() == 1);
    nlohmann::json& r = t["runs"][0];
    CHECK(r["status"] == "stable");
    CHECK(r["smooth"]["grad_max"].get<double>() <= 1e-8);
    CHECK(r["energy"]["wet"]["total"].get<double>() <= e_checkpoint + 1e-9 * std::abs(e_checkpoint));
    CHECK(t["wet"]["start_state"]["iterations_before"] == c["iterations"]);
    CHECK(t["wet"]["start_state"]["file"] == a + "/checkpoint_0.txt");
    CHECK(exists(b + "/state_0.txt"));
    CHECK(!exists(b + "/checkpoint_0.txt"));  // converged: state_0.txt supersedes its checkpoints
    CHECK(exists(a + "/checkpoint_0.txt"));   // the start state is the user's file: kept
}

TEST_CASE("wet checkpoint: the Schwarz sweep is checkpointed between its local solves", "[cli][wet][checkpoint]") {
    const std::string a = tmpdir() + "/ck_sweep";
    REQUIRE(std::system(("rm -rf " + a).c_str()) == 0);
    // One global iteration (the sweep over blocks of 100 coordinates and one global step), checkpoints at every chance.
    const std::string scene = tmpdir() + "/one.toml";
    clitest::write(scene, "[wet]\nmax_rounds = 1\nround_iterations = 1\ncheckpoint_seconds = 1e-9\n");
    REQUIRE(run("wet " + scene + " " + kNetwork + " -v --betas 0.1 --wet-schwarz 100 -o " + a) == 1);
    const std::string trace = slurp(tmpdir() + "/stderr");
    const std::string line = "wet: checkpoint after iteration 0, within the next one's local solves (E = ";
    const size_t iterate = trace.find("newton    0  E = ", trace.find("newton: "));
    REQUIRE(iterate != std::string::npos);
    const size_t within = trace.rfind(line, iterate);  // the last written during the first sweep, before the first iterate
    REQUIRE(within != std::string::npos);
    // Its energy lies between the dry start (energy 0 at the unstrained dry equilibrium) and the first iterate's:
    // every local solve lowers the energy, and so does the global step.
    const double e_within = std::strtod(trace.c_str() + within + line.size(), nullptr);
    const double e_first = std::strtod(trace.c_str() + iterate + 17, nullptr);
    CHECK(e_within < 0);
    CHECK(e_first <= e_within + 1e-9 * std::abs(e_within));
    // The last state is a whole iterate's: the JSON says so and carries its max|g|.
    nlohmann::json c = read_json(a + "/checkpoint_0.json");
    REQUIRE(c.is_object());
    CHECK(c["last"] == true);
    CHECK(c["within_iteration"] == false);
    CHECK(c["grad_max"].is_number());
}

TEST_CASE("wet checkpoint: a running relaxation's checkpoints survive SIGINT", "[cli][wet][checkpoint][signal]") {
    const std::string out = tmpdir() + "/ck_sigint";
    REQUIRE(std::system(("rm -rf " + out).c_str()) == 0);
    // 250 fibers at beta = 0.05: a relaxation of many seconds, checkpointed every 0.2 s.
    const pid_t pid = clitest::start_background({"wet", "--L", "5", "--q", "10", "--pl", "0.5", "--seed", "3",
                                                 "--wet-model", "smooth", "--bundle-partners", "2", "--no-moduli",
                                                 "--betas", "0.05", "--checkpoint-seconds", "0.2", "-q", "-o", out});
    REQUIRE(clitest::wait_until(pid, [&] { return read_json(out + "/checkpoint_0.json").is_object(); }));
    kill(pid, SIGINT);
    int st = 0;
    REQUIRE(waitpid(pid, &st, 0) == pid);
    REQUIRE(WIFEXITED(st));
    CHECK(WEXITSTATUS(st) == 130);
    CHECK(slurp(tmpdir() + "/bg_stderr").find("--start-state " + out + "/checkpoint_0.txt") != std::string::npos);
    nlohmann::json c = read_json(out + "/checkpoint_0.json");
    REQUIRE(c.is_object());
    CHECK(c["last"] == false);
    CHECK(c["iterations"].get<int>() >= 1);
    CHECK(slurp(out + "/checkpoint_0.txt").rfind("fibernet-model 2\n", 0) == 0);
    // The state is whole: it is accepted as a start state by a run of the same network (cut at once by the budget).
    const std::string next = tmpdir() + "/ck_sigint_next";
    REQUIRE(std::system(("rm -rf " + next).c_str()) == 0);
    const int rc = run("wet " + short_scene() + " --L 5 --q 10 --pl 0.5 --seed 3 --wet-model smooth --bundle-partners 2 "
                       "--no-moduli -q --betas 0.05 --start-state " + out + "/checkpoint_0.txt -o " + next);
    CHECK((rc == 0 || rc == 1));
    CHECK(read_json(next + "/summary.json")["wet"]["start_state"]["iterations_before"] == c["iterations"]);
}

TEST_CASE("wet checkpoint: bad start states exit 2, name the file and write nothing", "[cli][wet][checkpoint][input]") {
    const std::string a = tmpdir() + "/ck_bad_src", out = tmpdir() + "/ck_bad_out";
    REQUIRE(std::system(("rm -rf " + a + " " + out).c_str()) == 0);
    REQUIRE(run("wet " + short_scene() + " " + kNetwork + " -q --betas 0.1 -o " + a) == 1);
    const std::string state = a + "/checkpoint_0.txt";
    REQUIRE(exists(state));
    struct Case {
        std::string args, message;
    };
    const Case cases[] = {
        {kNetwork + " -q --betas 0.1 --start-state " + tmpdir() + "/missing.txt", "missing.txt' cannot be read"},
        {kNetwork + " -q --betas 0.1 --start-state " + a + "/summary.json", "not a fibernet model file"},
        {kNetwork + " -q --betas 0.1,0.2 --start-state " + state, "give one beta (2 given)"},
        {"--L 2.5 --q 8 --pl 0.5 --seed 3 --no-moduli -q --betas 0.1 --start-state " + state,
         "applies to [wet].model = 'smooth' only"},
        {kNetwork + " -q --betas 0.1 --gamma 0.01 --start-state " + state, "written at box deformation F"},
        {"--L 2.5 --q 8 --pl 0.5 --seed 4 --wet-model smooth --no-moduli -q --betas 0.1 --start-state " + state,
         "is not this run's"},
        {kNetwork + " -q --betas 0.1 --checkpoint-seconds -1", "[wet].checkpoint_seconds"},
    };
    for (const Case& k : cases) {
        INFO(k.args);
        CHECK(run("wet " + k.args + " -o " + out) == 2);
        CHECK(slurp(tmpdir() + "/stderr").find(k.message) != std::string::npos);
        CHECK(!exists(out + "/summary.json"));
    }
}
