// Percolation fits on synthetic data with known answers, and the `percolation`, `rigidity`, `compare` commands:
// output, resume after an interruption, bad input (exit 2, message names the value).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>
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

TEST_CASE("width fit recovers nu from exact widths", "[rigidity][percolation]") {
    std::vector<double> L{8, 12, 16, 24, 32, 48}, w, e;
    for (double l : L) w.push_back(4.2 * std::pow(l, -1 / 1.21)), e.push_back(0.1 * w.back());
    const WidthScalingFit f = fit_width_scaling(L, w, e);
    REQUIRE(f.ok);
    CHECK(f.reason.empty());
    CHECK(f.points == 6);
    CHECK(f.dof == 4);
    CHECK(f.nu == Approx(1.21).epsilon(1e-10));
    CHECK(f.inv_nu == Approx(1 / 1.21).epsilon(1e-10));
    CHECK(f.c == Approx(4.2).epsilon(1e-10));
    CHECK(f.chi2 < 1e-20);
    // Exact data: the errors are the unscaled ones, sigma(1/nu) = 0.1 / sqrt(sum w (log L - mean)^2), equal weights.
    double mean = 0, sxx = 0;
    for (double l : L) mean += std::log(l) / L.size();
    for (double l : L) sxx += std::pow(std::log(l) - mean, 2);
    CHECK(f.inv_nu_err == Approx(0.1 / std::sqrt(sxx)).epsilon(1e-9));
    CHECK(f.nu_err == Approx(f.inv_nu_err * 1.21 * 1.21).epsilon(1e-9));  // delta method
    // Sizes whose probit fit failed (width 0, NaN error) are skipped; two sizes are enough for a line (dof 0).
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double w8 = 4.2 * std::pow(8.0, -1 / 1.21), w32 = 4.2 * std::pow(32.0, -1 / 1.21);
    const WidthScalingFit two =
        fit_width_scaling({8, 16, 24, 32}, {w8, 0, 0.3, w32}, {0.1 * w8, 0.01, nan, 0.1 * w32});
    REQUIRE(two.ok);
    CHECK(two.points == 2);
    CHECK(two.dof == 0);
    CHECK(two.nu == Approx(1.21).epsilon(1e-10));
}

TEST_CASE("width fit: stated errors cover the true nu on noisy synthetic widths", "[rigidity][percolation]") {
    // widths c L^(-1/nu) with 10% log-normal noise of known size (the error bars): over many data sets the
    // recovered 1/nu must scatter around the truth as its stated error says (pull mean ~ 0, pull rms ~ 1; the
    // chi2/dof > 1 inflation makes the errors slightly conservative, rms a bit below 1).
    const std::vector<double> L{8, 12, 16, 24, 32, 48};
    const double nu = 4.0 / 3.0, c = 3.0;
    std::mt19937_64 rng(12345);
    std::normal_distribution<double> gauss(0, 1);
    const int sets = 2000;
    double pull_sum = 0, pull_sq = 0;
    int within_1 = 0, within_2 = 0;
    for (int k = 0; k < sets; ++k) {
        std::vector<double> w, e;
        for (double l : L) {
            const double rel = 0.05 + 0.1 * l / 48;  // relative errors 6% .. 15%, larger for the larger sizes
            w.push_back(c * std::pow(l, -1 / nu) * std::exp(rel * gauss(rng)));
            e.push_back(rel * w.back());
        }
        const WidthScalingFit f = fit_width_scaling(L, w, e);
        REQUIRE(f.ok);
        const double pull = (f.inv_nu - 1 / nu) / f.inv_nu_err;
        pull_sum += pull, pull_sq += pull * pull;
        within_1 += std::abs(f.nu - nu) < f.nu_err;
        within_2 += std::abs(f.nu - nu) < 2 * f.nu_err;
    }
    const double mean = pull_sum / sets, rms = std::sqrt(pull_sq / sets);
    CHECK(std::abs(mean) < 0.07);
    CHECK(rms > 0.8);
    CHECK(rms < 1.05);
    CHECK(within_1 > 0.66 * sets);
    CHECK(within_1 < 0.85 * sets);
    CHECK(within_2 > 0.94 * sets);
}

TEST_CASE("width fit: bad inputs give no fit with a reason", "[rigidity][percolation]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto no_fit = [](const WidthScalingFit& f, const std::string& why) {
        CHECK_FALSE(f.ok);
        CHECK(f.reason.find(why) != std::string::npos);
        CHECK(std::isnan(f.nu));
        CHECK(std::isnan(f.nu_err));
    };
    no_fit(fit_width_scaling({}, {}, {}), "fewer than 2 sizes");
    no_fit(fit_width_scaling({16}, {0.3}, {0.03}), "fewer than 2 sizes");
    // Three sizes, but only one with a valid width (the others failed: width 0, error NaN or 0, L <= 0).
    no_fit(fit_width_scaling({8, 16, 32, -4}, {0.5, 0, 0.2, 0.9}, {0.05, 0.02, nan, 0.1}), "fewer than 2 sizes");
    no_fit(fit_width_scaling({8, 16, 32}, {0.5, 0.3, 0.2}, {0.05, 0, -0.01}), "fewer than 2 sizes");
    no_fit(fit_width_scaling({16, 16}, {0.3, 0.35}, {0.03, 0.03}), "all sizes equal");
    no_fit(fit_width_scaling({8, 16}, {0.3}, {0.03}), "differ in length");
    // Widths that grow with L: 1/nu < 0 is reported, nu is not.
    const WidthScalingFit up = fit_width_scaling({8, 16, 32}, {0.2, 0.3, 0.45}, {0.02, 0.03, 0.04});
    no_fit(up, "do not fall");
    CHECK(up.inv_nu < 0);
    // And no q_c from such a width fit.
    CHECK_FALSE(fit_finite_size_scaling_width_nu({8, 16, 32}, {7, 6.9, 6.85}, {0.02, 0.02, 0.02}, up).ok);
}

TEST_CASE("q_c with nu from the widths carries the nu uncertainty", "[rigidity][percolation]") {
    std::vector<double> L{8, 12, 16, 24, 32, 48}, q, qe, w, we;
    const double nu = 1.21;
    for (double l : L) {
        q.push_back(7.0 + 2.0 * std::pow(l, -1 / nu)), qe.push_back(0.03);
        w.push_back(4 * std::pow(l, -1 / nu)), we.push_back(0.1 * w.back());
    }
    const WidthScalingFit wf = fit_width_scaling(L, w, we);
    REQUIRE(wf.ok);
    const ScalingFit f = fit_finite_size_scaling_width_nu(L, q, qe, wf);
    REQUIRE(f.ok);
    CHECK(f.q_c == Approx(7.0).margin(1e-9));
    CHECK(f.A == Approx(2.0).margin(1e-8));
    CHECK(f.nu == Approx(nu).epsilon(1e-10));
    CHECK(f.nu_err == Approx(wf.nu_err));
    // The nu part: half the q_c spread between the fits at 1/nu +- sigma(1/nu), added in quadrature.
    const ScalingFit a = fit_finite_size_scaling_fixed_nu(L, q, qe, 1 / (wf.inv_nu + wf.inv_nu_err)),
                     b = fit_finite_size_scaling_fixed_nu(L, q, qe, 1 / (wf.inv_nu - wf.inv_nu_err));
    CHECK(f.q_c_err_nu == Approx(0.5 * std::abs(a.q_c - b.q_c)));
    CHECK(f.q_c_err_nu > 0.01);  // a real shift (A = 2) makes q_c depend on nu
    CHECK(f.q_c_err_stat == Approx(fit_finite_size_scaling_fixed_nu(L, q, qe, nu).q_c_err));
    CHECK(f.q_c_err == Approx(std::hypot(f.q_c_err_stat, f.q_c_err_nu)));
    // Without a shift (A = 0) q_c does not depend on nu.
    const std::vector<double> flat(L.size(), 7.0);
    const ScalingFit g = fit_finite_size_scaling_width_nu(L, flat, qe, wf);
    REQUIRE(g.ok);
    CHECK(g.q_c_err_nu < 1e-9);
    // A width fit whose 1/nu is within one error of 0 gives no q_c.
    WidthScalingFit vague = wf;
    vague.inv_nu_err = 1.5 * vague.inv_nu;
    CHECK_FALSE(fit_finite_size_scaling_width_nu(L, q, qe, vague).ok);
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
    CHECK(out.find("\"rigid_width\"") != std::string::npos);
    CHECK(out.find("\"connected_nu_from_width\"") != std::string::npos);
    // Without --resume an existing CSV is refused; with it only the missing samples run.
    CHECK(run(base + " --samples 5", &out) == 2);
    CHECK(out.find("--resume") != std::string::npos);
    // An interrupted write leaves a partial last line: it is cut off and its sample run again.
    { std::ofstream(csv, std::ios::app) << "1,4,6,4,123"; }
    REQUIRE(run(base + " --samples 5 --resume", &out) == 0);
    CHECK(count_lines(csv) == 1 + 2 * 3 * 5);
    REQUIRE(run(base + " --samples 5 --resume", &out) == 0);  // nothing left to do
    CHECK(count_lines(csv) == 1 + 2 * 3 * 5);
    {
        std::ifstream in(csv);
        const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        CHECK(all.find("1,4,6,4,123\n") == std::string::npos);
    }
    // A damaged row elsewhere is refused, naming its line: skipped, its sample would be counted twice.
    {
        std::ifstream in(csv);
        std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::size_t second = all.find('\n', all.find('\n') + 1);  // the end of the first data row
        all.insert(second + 1, "1,4,6,0,1,2,3\n");
        std::ofstream(csv) << all;
    }
    CHECK(run(base + " --samples 5 --resume", &out) == 2);
    CHECK(out.find(":3: not a percolation row") != std::string::npos);
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
