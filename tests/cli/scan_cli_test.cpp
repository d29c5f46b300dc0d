// `fibernet scan` end to end (serial; the MPI runs are tests/cli/scan_mpi_test.sh): rows and summary, shards and
// their merge, resume after SIGINT and SIGKILL, a failed sample as a row, a sample's scene rerun by hand, bad input.
#include <catch2/catch.hpp>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "../support/cli_run.hpp"

using namespace clitest;

namespace {
// 18 samples of about 0.1 s each: moduli of L = 4 networks over q and three seeds.
const std::string kGrid = "--L 4 --scheme even --prune dangling --vary q=6,8,12 --vary a=10,100 --vary seed=1:3 "
                          "--job modulus -q";

std::string dir(const std::string& name) {
    const std::string d = tmpdir() + "/" + name;
    std::filesystem::remove_all(d);
    return d;
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> v;
    std::istringstream is(text);
    for (std::string l; std::getline(is, l);) v.push_back(l);
    return v;
}

// The reference: the whole grid in one serial run.
const std::string& reference() {
    static const std::string d = [] {
        const std::string r = dir("reference");
        REQUIRE(run("scan " + kGrid + " -o " + r) == 0);
        return r;
    }();
    return d;
}

// Each case (arguments, what the message must say) exits 2 with that message and leaves no directory d.
void check_refused(const std::vector<std::pair<std::string, std::string>>& cases, const std::string& d) {
    for (const auto& [args, says] : cases) {
        INFO(args);
        CHECK(run("scan --L 3 " + args + " -o " + d) == 2);
        CHECK(slurp(tmpdir() + "/stderr").find(says) != std::string::npos);
        CHECK(!std::filesystem::exists(d));
    }
}

int journal_records(const std::string& d) {
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(d + "/journal")) n += static_cast<int>(lines(slurp(e.path())).size());
    return n;
}
}  // namespace

TEST_CASE("cli scan: one row per sample in index order, a summary row per grid point", "[cli][scan]") {
    const std::string r = reference();
    const auto rows = lines(slurp(r + "/samples.csv"));
    REQUIRE(rows.size() == 19);
    CHECK(rows[0].rfind("index,q,a,seed,status,exit_code,", 0) == 0);
    CHECK(rows[0].find(",moduli.G,") != std::string::npos);
    CHECK(rows[0].find("seconds") == std::string::npos);  // timings stay in samples.jsonl
    for (int i = 0; i < 18; ++i) CHECK(rows[i + 1].rfind(std::to_string(i) + ",", 0) == 0);
    CHECK(rows[5].rfind("4,6,100,2,converged,0,", 0) == 0);  // index 4: q = 6, a = 100, seed = 2
    const auto summary = lines(slurp(r + "/summary.csv"));
    REQUIRE(summary.size() == 7);  // 3 q x 2 a
    CHECK(summary[0].rfind("q,a,samples,ok,", 0) == 0);
    CHECK(summary[0].find("moduli.G_ratio.mean,moduli.G_ratio.sem") != std::string::npos);
    CHECK(summary[6].rfind("12,100,3,3,", 0) == 0);
    const auto out = nlohmann::json::parse(slurp(tmpdir() + "/stdout"));
    (void)out;
    const auto m = nlohmann::json::parse(slurp(r + "/scan.json"));
    CHECK(m["samples"] == 18);
    CHECK(m["job"] == "modulus");
    CHECK(m["command"].get<std::string>().find("--vary q=6,8,12") != std::string::npos);
    CHECK(lines(slurp(r + "/samples.jsonl")).size() == 18);
}

TEST_CASE("cli scan: shards run apart and merged give the rows of one run, bit for bit", "[cli][scan]") {
    const std::string ref = slurp(reference() + "/samples.csv");
    const std::string a = dir("shard_a"), b = dir("shard_b"), merged = dir("merged"), same = dir("shared");
    REQUIRE(run("scan " + kGrid + " --shard 0/2 -o " + a) == 0);
    REQUIRE(run("scan " + kGrid + " --shard 1/2 -o " + b) == 0);
    CHECK(lines(slurp(a + "/samples.csv")).size() == 10);  // its 9 samples
    REQUIRE(run("scan --merge " + a + " " + b + " -o " + merged) == 0);
    CHECK(slurp(merged + "/samples.csv") == ref);
    CHECK(slurp(merged + "/summary.csv") == slurp(reference() + "/summary.csv"));
    CHECK(nlohmann::json::parse(slurp(tmpdir() + "/stdout"))["complete"] == true);
    // Merging again adds nothing; shards of one directory need no merge.
    REQUIRE(run("scan --merge " + a + " " + b + " -o " + merged) == 0);
    CHECK(slurp(merged + "/samples.csv") == ref);
    REQUIRE(run("scan " + kGrid + " --shard 1/2 -o " + same) == 0);
    REQUIRE(run("scan " + kGrid + " --shard 0/2 -o " + same) == 0);
    CHECK(slurp(same + "/samples.csv") == ref);
    // Another scan's directory is refused.
    CHECK(run("scan " + kGrid + " --vary gamma=0.01 --shard 0/2 -o " + a) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("holds another scan") != std::string::npos);
}

TEST_CASE("cli scan: interrupted (SIGINT) or killed (SIGKILL), it resumes without losing a finished sample", "[cli][scan][signal]") {
    const std::string ref = slurp(reference() + "/samples.csv");
    for (const std::string sig : {"INT", "KILL"}) {
        INFO(sig);
        const std::string d = dir("resume_" + sig);
        // Stop it once two samples are journaled (set -m: a background job of a script would ignore SIGINT).
        const std::string script = "set -m; " + std::string(FIBERNET_EXE) + " scan " + kGrid + " -o " + d + " >/dev/null 2>" + d +
                                   ".err & pid=$!; for i in $(seq 1 600); do n=$(cat " + d + "/journal/*.jsonl 2>/dev/null | wc -l); " +
                                   "[ \"$n\" -ge 2 ] && break; sleep 0.01; done; kill -" + sig + " $pid; wait $pid; echo $? > " + d + ".rc";
        REQUIRE(std::system(("bash -c '" + script + "'").c_str()) >= 0);
        const int rc = std::stoi(slurp(d + ".rc"));
        CHECK(rc == (sig == "INT" ? 130 : 137));
        const int kept = journal_records(d);
        CHECK(kept >= 2);
        CHECK(kept < 18);
        if (sig == "INT") CHECK(slurp(d + ".err").find("--resume") != std::string::npos);
        CHECK(run("scan " + kGrid + " -o " + d) == 2);  // a rerun without --resume is refused, naming it
        CHECK(slurp(tmpdir() + "/stderr").find("add --resume") != std::string::npos);
        REQUIRE(run("scan " + kGrid + " --resume -o " + d) == 0);
        CHECK(slurp(d + "/samples.csv") == ref);
        const auto out = nlohmann::json::parse(slurp(tmpdir() + "/stdout"));
        CHECK(out["run"]["samples_run"].get<int>() == 18 - kept);
    }
}

TEST_CASE("cli scan: a sample whose solver fails is a row with its status, and the exit code says so", "[cli][scan]") {
    const std::string d = dir("failing");
    // A strained solve with a budget of one Newton iteration fails at the larger strain only.
    CHECK(run("scan --L 4 --scheme even --max-iter 1 --vary gamma=0,0.05 --job relax -q -o " + d) == 1);
    const auto rows = lines(slurp(d + "/samples.csv"));
    REQUIRE(rows.size() == 3);
    CHECK(rows[1].rfind("0,0,converged,0,", 0) == 0);
    CHECK(rows[2].find(",converged,") == std::string::npos);
    CHECK(rows[2].find(",1,") != std::string::npos);
    const auto out = nlohmann::json::parse(slurp(tmpdir() + "/stdout"));
    CHECK(out["failed"] == 1);
    CHECK(out["complete"] == true);
}

TEST_CASE("cli scan: a sample's scene, printed, reruns to the same result", "[cli][scan]") {
    const std::string r = reference();
    REQUIRE(run("scan -o " + r + " --print-scene 13") == 0);  // q = 12, a = 10, seed = 2
    const std::string scene = tmpdir() + "/sample13.toml";
    write(scene, slurp(tmpdir() + "/stdout"));
    CHECK(slurp(scene).find("q = 12") != std::string::npos);
    // The scan runs a sample on one thread; so does this run.
    const std::string cmd = "FIBERNET_THREADS=1 OPENBLAS_NUM_THREADS=1 " + std::string(FIBERNET_EXE) + " modulus " +
                            scene + " -q > " + tmpdir() + "/direct.json";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const auto direct = nlohmann::json::parse(slurp(tmpdir() + "/direct.json"));
    std::string record;
    for (const auto& l : lines(slurp(r + "/samples.jsonl")))
        if (l.rfind("{\"exit_code\":0,\"host\"", 0) == 0 && l.find("\"index\":13,") != std::string::npos) record = l;
    REQUIRE(!record.empty());
    const auto rec = nlohmann::json::parse(record);
    CHECK(rec["params"]["q"] == "12");
    CHECK(rec["result"]["moduli"]["G"] == direct["moduli"]["G"]);
    CHECK(rec["result"]["energy"] == direct["energy"]);
    CHECK(run("scan -o " + r + " --print-scene 18") == 2);
}

TEST_CASE("cli scan: bad grids, jobs and arguments exit 2 before any work and leave no directory", "[cli][scan][input]") {
    const std::string d = dir("bad");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"--vary q=4,-1 --job modulus", "q = -1)"},
        {"--vary density=1,2 --job modulus", "'density' is not a scene key"},
        {"--vary q=4,,8 --job modulus", "an empty value"},
        {"--vary seed=3:1 --job modulus", "last 1 is below first 3"},
        {"--vary scheme=even,odd --job modulus", "odd"},
        {"--vary q=4 --job generate", "--job generate is not a job"},
        {"--vary q=4", "--job is required"},
        {"--vary q=4 --job modulus --job-args \"--q 3\"", "a scan sets --q itself"},
        {"--vary q=4 --job modulus --job-args --bogus", "--job-args for modulus"},
        {"--vary q=4 --job modulus --shard 2/2", "need 0 <= i < N"},
        {"--vary q=4 --job modulus --shard x", "is not i/N"},
        {"--vary q=4 --vary network.q=5 --job modulus", "varied twice"},
    };
    check_refused(cases, d);
}

TEST_CASE("cli scan: every job, two samples each in one process", "[cli][scan]") {
    // The second sample of a job runs after the first in the same process: a command's leftover state must not
    // change or stop it (wet's interrupt state once made the second sample wait for ever; hence the timeout).
    const std::vector<std::pair<std::string, std::string>> jobs = {
        {"relax", "--L 3 --scheme even --vary gamma=0.01,0.02 --job relax"},
        {"rigidity", "--L 3 --open --vary seed=1:2 --job rigidity --sample-files"},
        {"sweep", "--L 3 --q 7 --scheme even --h 2.5 --vary seed=1:2 --job sweep --job-args \"--gamma-max 0.02 --step 0.01\""},
        {"wet", "--L 2.2 --q 6 --pl 0.5 --vary beta=0.1,0.2 --job wet --job-args --no-moduli"},
    };
    for (const auto& [job, args] : jobs) {
        INFO(job);
        const std::string d = dir("job_" + job);
        const std::string cmd = "timeout 300 " + std::string(FIBERNET_EXE) + " scan " + args + " -q -o " + d + " > " +
                                tmpdir() + "/stdout 2> " + tmpdir() + "/stderr";
        CHECK(WEXITSTATUS(std::system(cmd.c_str())) == 0);
        const auto rows = lines(slurp(d + "/samples.csv"));
        REQUIRE(rows.size() == 3);
        CHECK(rows[2].find(",0,") != std::string::npos);
        if (job == "sweep") CHECK(lines(slurp(d + "/samples/sample-1.csv")).size() == 4);  // header and 3 steps
        if (job == "rigidity") CHECK(std::filesystem::exists(d + "/samples/sample-1.svg"));
        if (job == "wet") CHECK(rows[0].find(",runs.0.pores.wet.count,") != std::string::npos);
    }
}

TEST_CASE("cli scan: a list of points with seeds", "[cli][scan]") {
    const std::string d = dir("points"), pts = tmpdir() + "/points.csv";
    write(pts, "L,q\n3,6\n4,8\n");
    REQUIRE(run("scan --scheme even --points " + pts + " --vary seed=1:2 --job modulus -q -o " + d) == 0);
    const auto rows = lines(slurp(d + "/samples.csv"));
    REQUIRE(rows.size() == 5);
    CHECK(rows[0].rfind("index,L,q,seed,", 0) == 0);
    CHECK(rows[3].rfind("2,4,8,1,", 0) == 0);
    const auto summary = lines(slurp(d + "/summary.csv"));
    REQUIRE(summary.size() == 3);
    CHECK(summary[0].rfind("L,q,samples,ok,", 0) == 0);
    CHECK(summary[2].rfind("4,8,2,2,", 0) == 0);
    write(pts, "L,q\n3,6\n3,6\n");
    CHECK(run("scan --points " + pts + " --job modulus -q -o " + dir("points_bad")) == 2);
    CHECK(slurp(tmpdir() + "/stderr").find("point 2 is given twice") != std::string::npos);
}

TEST_CASE("cli scan: interrupting a wet or sweep sample ends the scan cleanly, and it resumes", "[cli][scan][signal]") {
    // wet and sweep have interrupt handlers of their own; inside a scan, wet's must not end the process mid-sample,
    // and a sweep sample cut short must run again from the start on --resume (its unfinished checkpoint removed).
    const std::vector<std::pair<std::string, std::string>> jobs = {
        {"wet", "--L 2.2 --q 6 --pl 0.5 --vary seed=1:6 --job wet --job-args --no-moduli"},
        // Steps of 0.001: a sample lasts 0.3 s here, so the signal lands inside the scan, not after it.
        {"sweep", "--L 3 --q 7 --scheme even --h 2.5 --vary seed=1:6 --job sweep --job-args \"--gamma-max 0.05 --step "
                  "0.001 --max-step 0.001\""},
    };
    for (const auto& [job, args] : jobs) {
        INFO(job);
        const std::string d = dir("interrupt_" + job);
        const std::string script = "set -m; " + std::string(FIBERNET_EXE) + " scan " + args + " -q -o " + d + " > " + d +
                                   ".out 2>/dev/null & pid=$!; for i in $(seq 1 1000); do n=$(cat " + d +
                                   "/journal/*.jsonl 2>/dev/null | wc -l); [ \"$n\" -ge 1 ] && break; sleep 0.01; done; " +
                                   "kill -TERM $pid; wait $pid; echo $? > " + d + ".rc";
        REQUIRE(std::system(("bash -c '" + script + "'").c_str()) >= 0);
        CHECK(std::stoi(slurp(d + ".rc")) == 130);
        const auto out = nlohmann::json::parse(slurp(d + ".out"));  // the scan's JSON, not the job's
        CHECK(out["run"]["interrupted"] == true);
        CHECK(std::filesystem::exists(d + "/samples.csv"));
        const int rc = run("scan " + args + " -q --resume -o " + d);
        CHECK((rc == 0 || rc == 1));  // 1: a sample's own solve failed (its row says so)
        CHECK(nlohmann::json::parse(slurp(tmpdir() + "/stdout"))["complete"] == true);
        CHECK(lines(slurp(d + "/samples.csv")).size() == 7);
    }
}

TEST_CASE("cli scan: shards in one directory at once, and shards of sweeps merged, give one run's rows", "[cli][scan]") {
    const std::string ref = slurp(reference() + "/samples.csv");
    for (int trial = 0; trial < 3; ++trial) {
        const std::string d = dir("together" + std::to_string(trial));
        std::string script;
        for (int i = 0; i < 4; ++i)
            script += std::string(FIBERNET_EXE) + " scan " + kGrid + " --shard " + std::to_string(i) + "/4 -o " + d +
                      " > /dev/null 2>&1 & p" + std::to_string(i) + "=$!; ";
        script += "r=0; for p in $p0 $p1 $p2 $p3; do wait $p || r=1; done; exit $r";
        CHECK(WEXITSTATUS(std::system(("bash -c '" + script + "'").c_str())) == 0);
        CHECK(slurp(d + "/samples.csv") == ref);
    }
    const std::string sweep = "--L 3 --q 7 --scheme even --h 2.5 --vary seed=1:3 --job sweep --job-args "
                              "\"--gamma-max 0.02 --step 0.01\" -q";
    const std::string one = dir("sweep_one"), a = dir("sweep_a"), b = dir("sweep_b"), m = dir("sweep_merged");
    REQUIRE(run("scan " + sweep + " -o " + one) == 0);
    REQUIRE(run("scan " + sweep + " --shard 0/2 -o " + a) == 0);
    REQUIRE(run("scan " + sweep + " --shard 1/2 -o " + b) == 0);
    REQUIRE(run("scan --merge " + a + " " + b + " -o " + m) == 0);
    CHECK(slurp(m + "/samples.csv") == slurp(one + "/samples.csv"));
    CHECK(slurp(one + "/samples.csv").find(",samples/sample-1.csv,") != std::string::npos);
    const auto merged_table = lines(slurp(m + "/samples/sample-1.csv")), own = lines(slurp(one + "/samples/sample-1.csv"));
    REQUIRE(merged_table.size() == own.size());  // the sweep's table came along (its last column is wall time)
    for (std::size_t k = 1; k < own.size(); ++k)
        CHECK(merged_table[k].substr(0, merged_table[k].rfind(',')) == own[k].substr(0, own[k].rfind(',')));
}

TEST_CASE("cli scan: more bad input, refused before anything is written", "[cli][scan][input]") {
    const std::string d = dir("bad2");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"--vary network.file=/nonexistent.net --job modulus", "'/nonexistent.net' is not a readable file"},
        {"--vary q=8,8.0 --job modulus", "8.0 is given twice"},
        {"--vary seed=1:2 --job relax --job-args -o/tmp/x.model", "a scan sets -o itself"},
        {"--vary beta=0,1 --job wet --job-args --betas=0.5", "would override --vary beta"},
    };
    check_refused(cases, d);
    CHECK(run("scan --merge " + reference() + " " + tmpdir() + "/nonexistent -o " + d) == 2);
    CHECK(!std::filesystem::exists(d));
    // A shard count past the grid: shard 1 has sample 1 only.
    REQUIRE(run("scan " + kGrid + " --shard 1/18446744073709551615 -o " + d) == 0);
    CHECK(lines(slurp(d + "/samples.csv")).size() == 2);
}
