// The stability map of the smooth wet model (issues 22 and 23; docs/solvers.md, "Wet scenes on the smooth model").
// The scenes of the event model's wet map (bench_solvers --mode stability-wet: Mikado networks with pl = 0.5, L = 3,
// q = 6 and 10, both schemes, a = 10 and 100, beta = 0.01, 0.1 and 1), relaxed as `fibernet wet --wet-model smooth
// --bundle-partners N` relaxes them: relax_smooth_wet from the rest state (the dry equilibrium at gamma = 0), the
// pair widths from the fiber's radius, tol 1e-10 on the whole energy. Every solver gets the same wall budget for the
// whole relaxation (all its rounds). Each accepted iterate is timed (SmoothRelaxOptions::observe), so a row says when
// max|g| of the whole energy first fell to 1e-6 and to 1e-10. The energy is not convex: each run is compared with the
// lowest energy any solver returned on its scene, through the gap (E - E_best) / (E_start - E_best).
// Solvers: registry names, and newton+eliminate (`--wet-eliminate`, hops 2 as the wet command) and newton+schwarz
// (`--wet-schwarz 500`, overlap 4).
//   bench_smooth_map [--out DIR] [--L 3] [--q 6,10] [--a 10,100] [--schemes seed,even] [--betas 0.01,0.1,1]
//                    [--solvers newton,newton+eliminate,...] [--budget 4] [--partners 2] [--seed 1] [--best-tol 1e-6]
// Writes DIR/stability_smooth.csv (one row per scene and solver); progress on stderr.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_text.hpp"
#include "deadline_solver.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/util/stopwatch.hpp"
#include "fibernet/wet/smooth_wet_relax.hpp"
#include "fibernet/wet/wet_run.hpp"

using namespace fibernet;
using bench::csv_text;
using bench::DeadlineSolver;
using bench::split;

namespace {

struct MapOptions {
    std::vector<double> Ls{3}, qs{6, 10}, as{10, 100}, betas{0.01, 0.1, 1};
    std::vector<std::string> schemes{"seed", "even"};
    std::vector<std::string> solvers{"newton", "newton+eliminate", "newton+schwarz", "lbfgs-hessian", "lbfgs", "fire",
                                     "ipopt"};
    double budget = 4, best_tol = 1e-6;
    int partners = 2;
    std::uint64_t seed = 1;
    std::string out = "docs/solvers";
};

std::vector<double> numbers(const std::string& key, const std::string& s) {
    std::vector<double> out;
    for (const auto& x : split(s)) {
        size_t used = 0;
        double v = std::nan("");
        try {
            v = std::stod(x, &used);
        } catch (const std::exception&) {
        }
        if (used != x.size() || !std::isfinite(v))
            throw std::runtime_error("--" + key + " '" + s + "' is not a list of numbers");
        out.push_back(v);
    }
    if (out.empty()) throw std::runtime_error("--" + key + " needs at least one value");
    return out;
}

double one_number(const std::string& key, const std::string& s) {
    const auto v = numbers(key, s);
    if (v.size() != 1) throw std::runtime_error("--" + key + " takes one number, not '" + s + "'");
    return v[0];
}

long whole_number(const std::string& key, const std::string& s) {
    const double v = one_number(key, s);
    if (!(v >= 0 && v <= 1e15 && v == std::floor(v)))
        throw std::runtime_error("--" + key + " '" + s + "' must be a whole number >= 0");
    return static_cast<long>(v);
}

// The solver of a map name: a registry name, or newton with elimination or the Schwarz sweep as the wet command sets
// them (src/cli/cmd_wet.cpp, run_options). tol 1e-10; the budget is the wrapper's.
DeadlineSolver map_solver(const std::string& spec, double budget) {
    SolverOptions opt;
    opt.tol = 1e-10, opt.max_iter = 100000000;
    std::string name = spec;
    if (spec == "newton+eliminate" || spec == "newton+schwarz") {
        name = "newton", opt.eliminate = true, opt.elimination.hops = 2;
        if (spec == "newton+schwarz") opt.elimination.block = 500, opt.elimination.overlap = 4;
    }
    make_solver(name, opt);  // an unknown name fails here
    return DeadlineSolver(name, opt, budget);
}

struct Run {
    SmoothRelaxResult r;
    double t_1e6 = NAN, t_1e10 = NAN, seconds = 0;
    std::string error;
};

Run relax(const NetworkEnergy& dry, const FiberPairs& dry_pairs, const SmoothWetParams& sp, const std::string& spec,
          double budget) {
    Run run;
    DeadlineSolver solver = map_solver(spec, budget);
    Eigen::VectorXd q = dry.dofs(dry.model().x);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    SmoothWetEnergy W(dry, I, sp, dry_pairs, q);
    SmoothRelaxOptions ro;  // the wet command's rounds: 1000 of at most 10 Newton iterations
    ro.max_rounds = 1000, ro.round_iterations = 10;
    const auto t0 = std::chrono::steady_clock::now();
    ro.observe = [&](const Eigen::VectorXd&, double, double gmax) {
        const double t = seconds_since(t0);
        if (gmax <= 1e-6 && std::isnan(run.t_1e6)) run.t_1e6 = t;
        if (gmax <= 1e-10 && std::isnan(run.t_1e10)) run.t_1e10 = t;
    };
    try {
        run.r = relax_smooth_wet(W, solver, q, ro);
    } catch (const std::exception& e) {
        run.error = e.what();
        run.r.energy = NAN, run.r.grad_max = NAN;
    }
    run.seconds = seconds_since(t0);
    if (run.r.grad_max <= 1e-6 && std::isnan(run.t_1e6)) run.t_1e6 = run.seconds;  // the start, or the last round
    if (run.r.grad_max <= 1e-10 && std::isnan(run.t_1e10)) run.t_1e10 = run.seconds;
    return run;
}

// One scene: the network, its discretization and the smooth energy's parameters as run_wet_smooth sets them.
void map_scene(const MapOptions& o, double L, double qd, double a, const std::string& scheme, std::ofstream& csv) {
    MikadoParams mp;
    mp.L = L, mp.q = qd, mp.pl = 0.5, mp.seed = o.seed, mp.periodic = true;
    const Network net = generate_mikado(mp);
    DiscretizationParams dp;
    dp.scheme = parse_scheme(scheme), dp.aspect_ratio = a;
    const Model model = discretize(net, dp);
    const NetworkEnergy dry(model);
    const FiberPairs dry_pairs = smooth_dry_pairs(net, WettingRule{});
    for (double beta : o.betas) {
        SmoothWetParams sp;
        sp.pair.beta = beta, sp.bundle_partners = o.partners;
        sp.pair.crossing_width = 1 / a, sp.pair.contact = 2 / a, sp.pair.overlap_width = 1 / a;
        std::ostringstream id;
        id << scheme << "_L" << L << "_q" << qd << "_a" << a << "_b" << beta;
        std::vector<Run> runs;
        for (const auto& spec : o.solvers) {
            runs.push_back(relax(dry, dry_pairs, sp, spec, o.budget));
            const Run& r = runs.back();
            std::fprintf(stderr, "%-28s %-18s %-10s it %6d  t %6.2fs  t(1e-6) %7.2f  E %.10g  max|g| %.1e  %s\n",
                         id.str().c_str(), spec.c_str(), r.r.converged ? "converged" : "no", r.r.iterations, r.seconds,
                         r.t_1e6, r.r.energy, r.r.grad_max, r.error.empty() ? r.r.message.c_str() : r.error.c_str());
        }
        Eigen::VectorXd q0 = dry.dofs(model.x);
        const double E0 = SmoothWetEnergy(dry, Eigen::Matrix2d::Identity(), sp, dry_pairs, q0).value(q0);
        double best = std::numeric_limits<double>::infinity();
        for (const Run& r : runs)
            if (std::isfinite(r.r.energy)) best = std::min(best, r.r.energy);
        const double drop = std::max(E0 - best, 1e-300);
        for (size_t k = 0; k < runs.size(); ++k) {
            const Run& r = runs[k];
            const double gap = (r.r.energy - best) / drop;
            csv << id.str() << "," << scheme << "," << L << "," << qd << "," << a << "," << beta << "," << o.seed << ","
                << net.fibers.size() << "," << dry.num_dofs() << "," << o.partners << "," << o.solvers[k] << ","
                << r.r.converged << "," << r.r.iterations << "," << r.r.factorizations << "," << r.r.rounds << ","
                << r.seconds << "," << o.budget << "," << r.t_1e6 << "," << r.t_1e10 << "," << r.r.grad_max << ","
                << std::setprecision(17) << E0 << "," << r.r.energy << "," << best << "," << std::setprecision(6)
                << gap << "," << (std::isfinite(gap) && gap <= o.best_tol) << ","
                << csv_text(r.error.empty() ? r.r.message : "exception: " + r.error) << "\n";
        }
        csv.flush();
    }
}

MapOptions parse(int argc, char** argv) {
    std::map<std::string, std::string> arg;
    for (int i = 1; i < argc; i += 2) {
        const std::string k = argv[i];
        if (k.rfind("--", 0) != 0 || i + 1 >= argc)
            throw std::runtime_error("'" + k + "': options are --key value pairs");
        arg[k.substr(2)] = argv[i + 1];
    }
    MapOptions o;
    for (const auto& [k, v] : arg) {
        if (k == "out") o.out = v;
        else if (k == "L") o.Ls = numbers(k, v);
        else if (k == "q") o.qs = numbers(k, v);
        else if (k == "a") o.as = numbers(k, v);
        else if (k == "betas") o.betas = numbers(k, v);
        else if (k == "schemes") o.schemes = split(v);
        else if (k == "solvers") o.solvers = split(v);
        else if (k == "budget") o.budget = one_number(k, v);
        else if (k == "best-tol") o.best_tol = one_number(k, v);
        else if (k == "partners") o.partners = static_cast<int>(std::min(whole_number(k, v), 1000000L));
        else if (k == "seed") o.seed = static_cast<std::uint64_t>(whole_number(k, v));
        else throw std::runtime_error("unknown option --" + k);
    }
    if (!(o.budget > 0)) throw std::runtime_error("--budget must be > 0 seconds");
    for (double b : o.betas)
        if (!(b > 0)) throw std::runtime_error("--betas must be > 0");
    for (const auto& s : o.schemes) parse_scheme(s);
    for (const auto& s : o.solvers) map_solver(s, 1);
    return o;
}

}  // namespace

int main(int argc, char** argv) {
    MapOptions o;
    try {
        o = parse(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "bench_smooth_map: " << e.what() << "\n";
        return 2;
    }
    std::ofstream csv(o.out + "/stability_smooth.csv");
    if (!csv) {
        std::cerr << "bench_smooth_map: cannot write " << o.out << "/stability_smooth.csv\n";
        return 1;
    }
    csv << "case,scheme,L,q,a,beta,seed,fibers,dof,partners,solver,converged,iterations,factorizations,rounds,"
           "seconds,budget_s,t_grad_1e-6,t_grad_1e-10,grad_max,energy_start,energy,energy_best,rel_energy_gap,at_best,"
           "message\n";
    for (double L : o.Ls)
        for (double qd : o.qs)
            for (double a : o.as)
                for (const auto& sc : o.schemes) map_scene(o, L, qd, a, sc, csv);
    return 0;
}
