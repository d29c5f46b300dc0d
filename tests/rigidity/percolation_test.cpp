// Percolation fits on synthetic data with known answers, and the `percolation`, `rigidity`, `compare` commands:
// output, resume after an interruption, bad input (exit 2, message names the value).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "fibernet/rigidity/percolation.hpp"
#include "fibernet/rigidity/percolation_fit.hpp"

using namespace fibernet;

namespace {
int run(const std::string& args, std::string* out = nullptr) {
    const std::string file = "/tmp/fibernet_rigidity_test_out.txt";
    const int rc = std::system((std::string(FIBERNET_EXE) + " " + args + " > " + file + " 2>&1").c_str());
    if (out) {
        std::ifstream in(file);
        std::stringstream ss;
        ss << in.rdbuf();
        *out = ss.str();
    }
    return WEXITSTATUS(rc);
}
int count_lines(const std::string& path) {
    std::ifstream in(path);
    int n = 0;
    for (std::string l; std::getline(in, l);) ++n;
    return n;
}
}  // namespace

TEST_CASE("probit fit recovers the inflection point of exact data", "[rigidity][percolation]") {
    std::vector<double> q;
    std::vector<int> hits, n;
    for (double x = 5; x <= 9.01; x += 0.25) {
        q.push_back(x);
        n.push_back(1000);
        hits.push_back(static_cast<int>(std::lround(1000 * 0.5 * std::erfc(-(x - 6.9) / (0.4 * std::sqrt(2.0))))));
    }
    const ProbitFit f = fit_spanning_probability(q, hits, n);
    REQUIRE(f.ok);
    CHECK(f.q_half == Approx(6.9).margin(0.01));
    CHECK(f.width == Approx(0.4).margin(0.01));
    CHECK(f.q_half_err > 0);
    CHECK(f.q_half_err < 0.05);
    // No transition in the data: no fit.
    std::vector<int> none(q.size(), 0);
    CHECK_FALSE(fit_spanning_probability(q, none, n).ok);
}

TEST_CASE("finite-size scaling fit recovers q_c and nu", "[rigidity][percolation]") {
    std::vector<double> L{8, 12, 16, 24, 32, 48}, y, e;
    for (double l : L) y.push_back(5.6 + 3.0 * std::pow(l, -1 / 1.33)), e.push_back(0.01);
    const ScalingFit f = fit_finite_size_scaling(L, y, e);
    REQUIRE(f.ok);
    CHECK(f.q_c == Approx(5.6).margin(1e-3));
    CHECK(f.nu == Approx(1.33).margin(2e-3));
    CHECK(f.A == Approx(3.0).margin(1e-2));
    CHECK_FALSE(fit_finite_size_scaling({8, 16, 32}, {6, 5.8, 5.7}, {0.1, 0.1, 0.1}).ok);  // 3 sizes, 3 parameters
}

TEST_CASE("percolation samples are reproducible from their seed", "[rigidity][percolation]") {
    const PercolationSample a = percolation_sample(0.7, 6, 9, 3, 42), b = percolation_sample(0.7, 6, 9, 3, 42);
    CHECK(a.seed == b.seed);
    CHECK(a.d == b.d);
    CHECK(a.fibers == b.fibers);
    CHECK(percolation_seed(42, 6, 9, 3) != percolation_seed(42, 6, 9, 4));
    CHECK(percolation_seed(42, 6, 9, 3) != percolation_seed(42, 6, 9.25, 3));
}

TEST_CASE("percolation command appends per sample and resumes", "[rigidity][percolation][cli]") {
    const std::string csv = "/tmp/fibernet_percolation_test.csv";
    std::remove(csv.c_str());
    const std::string base = "percolation --pl 1 --L 4,6 --q-min 6 --q-max 7 --q-step 0.5 --threads 2 --out " + csv;
    std::string out;
    REQUIRE(run(base + " --samples 3", &out) == 0);
    CHECK(count_lines(csv) == 1 + 2 * 3 * 3);
    CHECK(out.find("\"per_L\"") != std::string::npos);
    // Without --resume an existing CSV is refused; with it only the missing samples run.
    CHECK(run(base + " --samples 5", &out) == 2);
    CHECK(out.find("--resume") != std::string::npos);
    // An interrupted write leaves a partial last line: it is skipped and its sample run again.
    { std::ofstream(csv, std::ios::app) << "1,4,6,4,123"; }
    REQUIRE(run(base + " --samples 5 --resume", &out) == 0);
    CHECK(count_lines(csv) == 1 + 2 * 3 * 5 + 1);
    REQUIRE(run(base + " --samples 5 --resume", &out) == 0);  // nothing left to do
    CHECK(count_lines(csv) == 1 + 2 * 3 * 5 + 1);
    CHECK(run(base + " --samples 0 --resume", &out) == 2);
    CHECK(out.find("--samples = 0") != std::string::npos);
    CHECK(run("percolation --pl 1.5 --L 4 --q-min 6 --q-max 7 --q-step 0.5 --samples 1 --out /tmp/x.csv", &out) == 2);
    CHECK(out.find("--pl = 1.5") != std::string::npos);
}

TEST_CASE("rigidity and compare commands", "[rigidity][cli]") {
    std::string out;
    REQUIRE(run("rigidity --open --L 4 --q 7 --seed 3 --svg /tmp/fibernet_rigidity_test.svg", &out) == 0);
    CHECK(out.find("\"d\"") != std::string::npos);
    CHECK(out.find("\"floppy_modes\"") != std::string::npos);
    CHECK(count_lines("/tmp/fibernet_rigidity_test.svg") > 10);
    CHECK(run("rigidity --L 4 --q 7", &out) == 2);  // periodic
    CHECK(out.find("--open") != std::string::npos);
    CHECK(run("rigidity --open --L 4 --q -1", &out) == 2);
    CHECK(out.find("q (density) = -1") != std::string::npos);
    // An open network without crosslinks is a valid input.
    REQUIRE(run("rigidity --open --L 3 --q 2 --pl 0", &out) == 0);
    CHECK(out.find("\"d\": 3") != std::string::npos);
    REQUIRE(run("compare --open --L 2.5 --q 6 --pl 0.8 --seed 5 --samples 3", &out) == 0);
    CHECK(out.find("\"agreement_rate\": 1.0") != std::string::npos);
    CHECK(run("compare --open --L 2.5 --q 6 --zero-cut -1", &out) == 2);
}
