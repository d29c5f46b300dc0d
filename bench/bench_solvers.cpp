// Work-precision benchmark of the solver suite (issue 5, part 2), and the stability map (part 3).
//
// Mode "wp" (default): every solver minimizes the same sheared Mikado networks (sizes L, aspect ratios a, both
// discretizations) from the affine start q = F x. A wrapper around the objective records every evaluation
// (wall time, energy, max|g|), so all solvers are measured the same way whatever their internals. Writes
//   <out>/runs.csv   one row per (network, solver): status, counts, time, final energy error and max|g|
//   <out>/trace.csv  per (network, solver): time against the running minimum of max|g| and of the relative
//                    energy error (E - E_best) / |E_best|, E_best the lowest energy any solver found on that network
// Mode "stability": every solver on a grid of (a, gamma, q, scheme) with a fixed budget; writes <out>/stability.csv.
// Mode "discretization": the linear shear modulus G of the rest state (stress-free, so no relaxation: one
// factorization, mechanics/moduli.hpp) for the seed scheme at n_seg in --nseg and the even scheme at h in --h,
// against the finest even discretization; writes <out>/discretization.csv (G, relative error, nodes per fiber,
// DOF, seconds for discretize + modulus).
// Mode "ratio" (issue 5, part 1): in one process, the first of --solvers (newton) runs to --tol (or its round-off
// floor) with budget --ref-budget, then every other solver runs from the same start with budget --budget; from each
// recorded trace, the time at which max|g| first fell to --ratio-tol. Writes <out>/ratio.csv (one row per solver,
// with t_other / t_ref, a lower bound where the other solver never got there) and <out>/ratio_trace.csv.
// Mode "stability-wet" (issue 6): the stability map on wet scenes. Per (L, q, a, gamma, scheme): a Mikado network
// with crosslink probability --pl (0.5), relaxed dry with Newton, wetted at all crossings exactly as run_wet does
// (wet_crossings at the dry equilibrium, then update_bridges without new bridges); per beta in --betas, every solver
// minimizes the WetEnergy of that fixed bridge set from the dry equilibrium with budget --budget (one value) and
// tol = --rel-tol x max|g| at the start. Writes <out>/stability_wet.csv (one row per scene and solver: status, time,
// max|g| relative to the start, energy, and whether it is within --best-tol of the lowest energy any solver returned,
// measured as a fraction of the energy drop E_start - E_best) and <out>/stability_wet_relax.csv (per scene, the full
// active-set relaxation, relax_wet with Newton as in `fibernet wet`, under one wall budget --relax-budget; 0 skips it).
// Its own defaults: --L 3 --q 6,10 --gamma 0 --budget 1 --rel-tol 1e-8; --prune is refused (bridges sit on the arms).
// --tol is the dry Newton relaxation's (500 iterations at most, as `fibernet wet`), and the wet one's if --rel-tol 0.
//
//   bench_solvers [--mode wp|stability|stability-wet|discretization|ratio] [--out DIR] [--L 4,8,12] [--q 8]
//                 [--a 10,100] [--schemes seed,even] [--solvers newton,lbfgs,...] [--gamma 0.05] [--tol 1e-10]
//                 [--budget 2,4,8] [--seed 1] [--max-iter N] [--rel-tol R] [--prune dangling,nonspanning,ends]
//                 [--ref-budget 1800] [--ratio-tol 1e-6] [--verbose]
//                 [--betas 0.01,0.1,1] [--pl 0.5] [--relax-budget 8] [--best-tol 1e-6]   (stability-wet only)
// --rel-tol R > 0 sets each network's tolerance to R * max|g| at its start (the force scale grows like a^2 and
// gamma, so one absolute tol means different things across the stability grid); otherwise --tol applies.
// --prune: dangling/nonspanning prune the network (model/prune.hpp), ends trims the load-free end arms
// (DiscretizationParams::trim_ends); all exact for dry equilibria, so every solver sees a smaller, same problem.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_text.hpp"
#include "deadline_solver.hpp"
#include "fibernet/box/box.hpp"
#include "fibernet/energy/network_energy.hpp"
#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/model/prune.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/solve/solver_registry.hpp"
#include "fibernet/wet/active_set.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/wet/wetting.hpp"

using namespace fibernet;

namespace {

// A solver by registry name with optional suffixes: "+eliminate", nonlinear elimination (`--eliminate`);
// "+median", the shift floor at the median diagonal (SolverOptions::median_floor). "newton+eliminate+median" is what
// the dry commands run by default since 2026-12-04 (src/cli/common.cpp, dry_solver_options), charted beside plain
// Newton.
std::unique_ptr<Solver> bench_solver(const std::string& spec, SolverOptions opt) {
    static const std::pair<std::string, bool SolverOptions::*> suffixes[] = {{"+eliminate", &SolverOptions::eliminate},
                                                                             {"+median", &SolverOptions::median_floor}};
    std::string name = spec;
    for (bool more = true; more;) {
        more = false;
        for (const auto& [suffix, flag] : suffixes)
            if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
                if (opt.*flag) throw std::invalid_argument("bench_solvers: '" + spec + "' repeats " + suffix);
                opt.*flag = true, name.resize(name.size() - suffix.size()), more = true;
            }
    }
    if (name != spec && name != "newton")
        throw std::invalid_argument("bench_solvers: '" + spec + "': only newton takes +eliminate and +median");
    return make_solver(name, opt);
}
// Every registered solver, with newton+eliminate and the dry commands' default after newton.
std::vector<std::string> bench_solver_names() {
    std::vector<std::string> names = solver_names();
    names.insert(names.begin() + 1, {"newton+eliminate", "newton+eliminate+median"});
    return names;
}

using bench::split;
std::vector<double> split_d(const std::string& s) {
    std::vector<double> out;
    for (const auto& x : split(s)) out.push_back(std::stod(x));
    return out;
}

struct Sample {
    double t, energy, gmax;
    int evals;
};

// Records every evaluation of the wrapped objective.
class Recorder : public Objective {
public:
    Recorder(Objective& f) : f_(f), t0_(std::chrono::steady_clock::now()) {}
    int size() const override { return f_.size(); }
    double value(const Eigen::VectorXd& q) override {
        ++evals_;
        return f_.value(q);
    }
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override {
        const double e = f_.gradient(q, g);
        record(e, g);
        return e;
    }
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) override {
        const double e = f_.hessian(q, g, H, psd);
        record(e, g);
        return e;
    }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return f_.hessian_pattern(); }
    // Nonlinear elimination's parts: their evaluations are of a part's energy, not recorded.
    std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) override {
        return f_.restriction(q, coords);
    }
    std::vector<Sample> samples;

private:
    void record(double e, const Eigen::VectorXd& g) {
        ++evals_;
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
        const double gm = g.size() ? g.lpNorm<Eigen::Infinity>() : 0.0;
        if (std::isfinite(e) && std::isfinite(gm)) samples.push_back({t, e, gm, evals_});
    }
    Objective& f_;
    std::chrono::steady_clock::time_point t0_;
    int evals_ = 0;
};

struct Run {
    std::string solver;
    SolveResult res;
    std::vector<Sample> samples;
};

struct Case {
    double L, q, a, gamma;
    std::string scheme;
    int dof = 0;
    double shortest = 0;
};

std::string case_id(const Case& c) {
    std::ostringstream os;
    os << c.scheme << "_L" << c.L << "_q" << c.q << "_a" << c.a << "_g" << c.gamma;
    return os.str();
}

struct Pruning {
    PruneOptions net;
    bool ends = false;
};

Pruning parse_prune(const std::string& s) {
    Pruning p;
    for (const auto& x : split(s)) {
        if (x == "dangling") p.net.dangling = true;
        else if (x == "nonspanning") p.net.nonspanning = true;
        else if (x == "ends") p.ends = true;
        else throw std::runtime_error("--prune " + x + " is unknown (expected dangling, nonspanning or ends)");
    }
    return p;
}

// The network of one case, pruned as asked (the same pipeline as scene_network + discretize in the CLI).
Network make_network(double L, double q, std::uint64_t seed, const Pruning& pr) {
    MikadoParams mp;
    mp.L = L, mp.q = q, mp.pl = 1, mp.seed = seed, mp.periodic = true;
    Network net = generate_mikado(mp);
    if (pr.net.dangling || pr.net.nonspanning) net = prune(net, pr.net);
    return net;
}

// First recorded time at which max|g| <= thr; negative if never.
double time_to(const std::vector<Sample>& s, double thr) {
    for (const auto& x : s)
        if (x.gmax <= thr) return x.t;
    return -1;
}

// ---- Mode "stability-wet" (issue 6: wet scenes in the stability map) ----

using bench::DeadlineSolver;

using bench::csv_text;

struct WetGrid {
    std::vector<double> Ls, qs, as, gammas, betas;
    std::vector<std::string> schemes, solvers;
    double pl = 0.5, budget = 1, relax_budget = 8, rel_tol = 1e-8, tol_abs = 1e-10, best_tol = 1e-6;
    int max_iter = 100000000;
    std::uint64_t seed = 1;
    bool verbose = false;
    std::string out;
};

// Every solver on the same wet problem: the WetEnergy of a fixed bridge set (the wet crossings of the dry
// equilibrium, made consistent with the geometry exactly as run_wet does before its first solve), from the dry
// equilibrium, with the same wall budget and tolerance. Then, per scene, the full active-set relaxation (relax_wet
// with Newton, as `fibernet wet` does) under one overall wall budget. Writes <out>/stability_wet.csv (one row per
// scene and solver) and <out>/stability_wet_relax.csv (one row per scene; not with relax_budget = 0).
int stability_wet(const WetGrid& G) {
    std::ofstream runs(G.out + "/stability_wet.csv"), relax;
    if (G.relax_budget > 0) relax.open(G.out + "/stability_wet_relax.csv");
    if (!runs || (G.relax_budget > 0 && !relax)) {
        std::cerr << "cannot write to " << G.out << "\n";
        return 1;
    }
    runs << "case,scheme,L,q,pl,a,gamma,beta,seed,fibers,crossings,dof,bridges,solver,status,iterations,evaluations,"
            "factorizations,seconds,budget_s,tol,grad_start,grad_max,grad_rel,energy_start,energy,energy_best,"
            "rel_energy_gap,at_best,message\n";
    relax << "case,scheme,L,q,pl,a,gamma,beta,seed,fibers,crossings,dof,dry_status,dry_iterations,dry_seconds,"
             "bridges_initial,bridges_final,outcome,rounds,stable,cycling,iterations,seconds,seconds_solve,"
             "seconds_events,budget_s,tol,last_status,grad_max,energy,moves,ruptures,formed,merged,locked,message\n";
    for (double L : G.Ls)
        for (double qd : G.qs)
            for (double a : G.as)
                for (double gamma : G.gammas)
                    for (const auto& sc : G.schemes) {
                        MikadoParams mp;
                        mp.L = L, mp.q = qd, mp.pl = G.pl, mp.seed = G.seed, mp.periodic = true;
                        const Network net = generate_mikado(mp);
                        DiscretizationParams dp;
                        dp.scheme = parse_scheme(sc), dp.aspect_ratio = a;  // no trimmed ends: bridges sit on the arms
                        const Model model = discretize(net, dp);
                        const NetworkEnergy dry(model);
                        const Eigen::Matrix2d F = deformation(StrainKind::Shear, gamma);
                        const Eigen::Matrix2d B = F * model.box.B0();
                        // Dry equilibrium with Newton, as run_wet does (at gamma = 0 the rest state already is one).
                        Eigen::VectorXd q_dry = dry.affine_map(dry.dofs(model.x), Eigen::Matrix2d::Identity(), F);
                        SolverOptions dopt;
                        dopt.tol = G.tol_abs, dopt.max_iter = 500, dopt.verbose = G.verbose;
                        auto t0 = std::chrono::steady_clock::now();
                        WetEnergy D(dry, F, {}, WetParams{});
                        const SolveResult dres = make_solver("newton", dopt)->minimize(D, q_dry);
                        const double t_dry = seconds_since(t0);
                        // Bridges at the dry equilibrium's crossings, consistent with the geometry (run_wet).
                        std::vector<Bridge> bridges =
                            wet_crossings(net, model, dry.positions(q_dry, F), B, WettingRule{});
                        const size_t n_wet = bridges.size();
                        ActiveSetOptions first;
                        first.form_new = false;
                        update_bridges(dry, q_dry, F, bridges, first);
                        std::ostringstream sid;
                        sid << sc << "_L" << L << "_q" << qd << "_a" << a << "_g" << gamma;
                        std::fprintf(stderr, "wet %s: %zu fibers, %zu crossings, %d DOF, %zu bridges (%zu wet crossings); "
                                     "dry newton %s, %d it, %.3fs\n", sid.str().c_str(), net.fibers.size(),
                                     net.crossings.size(), dry.num_dofs(), bridges.size(), n_wet,
                                     to_string(dres.status).c_str(), dres.iterations, t_dry);
                        std::ostringstream scene;
                        scene << sc << "," << L << "," << qd << "," << G.pl << "," << a << "," << gamma;
                        for (double beta : G.betas) {
                            std::ostringstream cid;
                            cid << "wet_" << sid.str() << "_b" << beta;
                            WetParams wp;
                            wp.beta = beta;
                            WetEnergy W0(dry, F, bridges, wp);
                            Eigen::VectorXd g0;
                            const double E0 = W0.gradient(q_dry, g0);
                            const double g0max = g0.size() ? g0.lpNorm<Eigen::Infinity>() : 0.0;
                            const double tol = G.rel_tol > 0 ? G.rel_tol * g0max : G.tol_abs;
                            std::ostringstream head;
                            head << cid.str() << "," << scene.str() << "," << beta << "," << G.seed << ","
                                 << net.fibers.size() << "," << net.crossings.size() << "," << dry.num_dofs();
                            std::vector<SolveResult> rs;
                            for (const auto& name : G.solvers) {
                                SolverOptions opt;
                                opt.tol = tol, opt.max_iter = G.max_iter, opt.max_seconds = G.budget;
                                opt.verbose = G.verbose;
                                WetEnergy W(dry, F, bridges, wp);
                                Eigen::VectorXd q = q_dry;
                                SolveResult r;
                                try {
                                    r = make_solver(name, opt)->minimize(W, q);
                                } catch (const std::exception& e) {
                                    r.status = SolveStatus::Failed, r.solver = name;
                                    r.message = std::string("exception: ") + e.what();
                                    r.energy = std::numeric_limits<double>::quiet_NaN();
                                }
                                std::fprintf(stderr, "  %-32s %-14s %-18s it %7d  t %6.3fs  E %.12g  max|g|/g0 %.1e  %s\n",
                                             cid.str().c_str(), name.c_str(), to_string(r.status).c_str(), r.iterations,
                                             r.timings.total, r.energy, r.grad_max / g0max, r.message.c_str());
                                rs.push_back(r);
                            }
                            // The best energy any solver returned; gaps relative to the energy drop E0 - E_best.
                            double best = std::numeric_limits<double>::infinity();
                            for (const auto& r : rs)
                                if (std::isfinite(r.energy)) best = std::min(best, r.energy);
                            const double drop = std::max(E0 - best, 1e-300);
                            for (size_t k = 0; k < rs.size(); ++k) {
                                const SolveResult& r = rs[k];
                                const double gap = (r.energy - best) / drop;
                                runs << head.str() << "," << bridges.size() << "," << G.solvers[k] << ","
                                     << to_string(r.status) << "," << r.iterations << "," << r.evaluations << ","
                                     << r.factorizations << "," << r.timings.total << "," << G.budget << "," << tol
                                     << "," << g0max << "," << r.grad_max << "," << r.grad_max / g0max << ","
                                     << std::setprecision(17) << E0 << "," << r.energy << "," << best << ","
                                     << std::setprecision(6) << gap << "," << (std::isfinite(gap) && gap <= G.best_tol)
                                     << "," << csv_text(r.message) << "\n";
                            }
                            runs.flush();
                            if (G.relax_budget <= 0) continue;
                            // The full active-set relaxation with Newton (moves, ruptures, new bridges), one budget.
                            SolverOptions nopt;
                            nopt.tol = tol, nopt.max_iter = 500, nopt.verbose = G.verbose;
                            DeadlineSolver newton("newton", nopt, G.relax_budget);
                            Eigen::VectorXd q = q_dry;
                            t0 = std::chrono::steady_clock::now();
                            ActiveSetResult ar;
                            std::string outcome;
                            try {
                                ar = relax_wet(dry, F, wp, bridges, newton, q, ActiveSetOptions{});
                                outcome = ar.stable    ? "stable"
                                          : ar.cycling ? "cycling"
                                          : newton.spent ? "budget"
                                          : ar.last.converged() || ar.last.status == SolveStatus::IterationLimit
                                              ? "max_rounds"
                                              : "failed";
                            } catch (const std::exception& e) {
                                outcome = "failed", ar.message = std::string("exception: ") + e.what();
                            }
                            const double t_relax = seconds_since(t0);
                            const double E = WetEnergy(dry, F, ar.bridges, wp).value(q);
                            std::fprintf(stderr, "  %-32s %-14s %-18s it %7d  t %6.3fs  E %.12g  %d rounds  %zu -> %zu "
                                         "bridges  %s\n", cid.str().c_str(), "active-set", outcome.c_str(),
                                         ar.solver_iterations, t_relax, E, ar.rounds, bridges.size(),
                                         ar.bridges.size(), ar.message.c_str());
                            const WetEvents& ev = ar.events;
                            relax << cid.str() << "," << scene.str() << "," << beta << "," << G.seed << ","
                                  << net.fibers.size() << "," << net.crossings.size() << "," << dry.num_dofs() << ","
                                  << to_string(dres.status) << "," << dres.iterations << "," << t_dry << ","
                                  << bridges.size() << "," << ar.bridges.size() << "," << outcome << "," << ar.rounds
                                  << "," << ar.stable << "," << ar.cycling << "," << ar.solver_iterations << ","
                                  << t_relax << "," << ar.seconds_solve << "," << ar.seconds_events << ","
                                  << G.relax_budget << "," << tol << "," << to_string(ar.last.status) << ","
                                  << ar.last.grad_max << "," << std::setprecision(17) << E << std::setprecision(6)
                                  << "," << ev.moves << "," << ev.ruptures << "," << ev.formed << "," << ev.merged
                                  << "," << ev.locked << "," << csv_text(ar.message) << "\n";
                            relax.flush();
                        }
                    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    std::map<std::string, std::string> arg = {
        {"mode", "wp"},       {"out", "docs/solvers"}, {"L", "4,8,12"},   {"q", "8"},
        {"a", "10,100"},      {"schemes", "seed,even"}, {"gamma", "0.05"}, {"tol", "1e-10"},
        {"budget", "2,4,8"},  {"seed", "1"},           {"max-iter", "100000000"}, {"verbose", "0"},
        {"solvers", ""},      {"rel-tol", "0"},      {"nseg", "2,3,5,10,20,40"}, {"h", "4,2,1,0.5,0.25,0.125,0.0625"},
        {"prune", ""},        {"ref-budget", "1800"}, {"ratio-tol", "1e-6"},
        {"betas", "0.01,0.1,1"}, {"pl", "0.5"},     {"relax-budget", "8"}, {"best-tol", "1e-6"},
    };
    std::set<std::string> given;
    for (int i = 1; i < argc; ++i) {
        std::string k = argv[i];
        if (k.rfind("--", 0) != 0) {
            std::cerr << "unexpected argument " << k << "\n";
            return 2;
        }
        k = k.substr(2);
        if (!arg.count(k)) {
            std::cerr << "unknown option --" << k << "\n";
            return 2;
        }
        given.insert(k);
        if (k == "verbose") {
            arg[k] = "1";
            continue;
        }
        if (i + 1 >= argc) {
            std::cerr << "--" << k << " needs a value\n";
            return 2;
        }
        arg[k] = argv[++i];
    }
    const std::set<std::string> modes = {"wp", "stability", "stability-wet", "discretization", "ratio"};
    if (!modes.count(arg["mode"])) {
        std::cerr << "unknown mode " << arg["mode"] << " (expected wp, stability, stability-wet, discretization or ratio)\n";
        return 2;
    }
    const bool wet = arg["mode"] == "stability-wet";
    for (const char* k : {"betas", "pl", "relax-budget", "best-tol"})
        if (!wet && given.count(k)) {
            std::cerr << "--" << k << " applies to --mode stability-wet only\n";
            return 2;
        }
    if (wet) {
        if (given.count("prune")) {
            std::cerr << "--prune does not apply to --mode stability-wet (bridges sit on the end arms)\n";
            return 2;
        }
        // The wet grid's own defaults: the small pl = 0.5 networks of docs/wet.md, unstrained as `fibernet wet`.
        const std::map<std::string, std::string> wet_defaults = {
            {"L", "3"}, {"q", "6,10"}, {"gamma", "0"}, {"budget", "1"}, {"rel-tol", "1e-8"}};
        for (const auto& [k, v] : wet_defaults)
            if (!given.count(k)) arg[k] = v;
        WetGrid G;
        // Numbers of option k, or an error naming it.
        auto nums = [&](const std::string& k) {
            try {
                return split_d(arg[k]);
            } catch (const std::exception&) {
                throw std::runtime_error("--" + k + " " + arg[k] + " is not a list of numbers");
            }
        };
        auto num = [&](const std::string& k) {
            const auto v = nums(k);
            if (v.size() != 1) throw std::runtime_error("--" + k + " takes one number in --mode stability-wet");
            return v[0];
        };
        try {
            G.Ls = nums("L"), G.qs = nums("q"), G.as = nums("a"), G.gammas = nums("gamma"), G.betas = nums("betas");
            G.schemes = split(arg["schemes"]);
            G.budget = num("budget"), G.pl = num("pl"), G.relax_budget = num("relax-budget");
            G.rel_tol = num("rel-tol"), G.tol_abs = num("tol"), G.best_tol = num("best-tol");
            const double mi = num("max-iter"), sd = num("seed");
            if (!(mi >= 1 && mi <= 2e9 && mi == std::floor(mi))) throw std::runtime_error("--max-iter must be a positive integer");
            if (!(sd >= 0 && sd == std::floor(sd))) throw std::runtime_error("--seed must be an integer >= 0");
            G.max_iter = static_cast<int>(mi), G.seed = std::stoull(arg["seed"]);
            G.verbose = arg["verbose"] == "1", G.out = arg["out"];
            G.solvers = split(arg["solvers"]);
            if (G.solvers.empty()) G.solvers = solver_names();
            for (const auto& n : G.solvers) bench_solver(n, SolverOptions{});  // an unknown name fails here
            for (const auto& sc : G.schemes) parse_scheme(sc);
            if (G.Ls.empty() || G.qs.empty() || G.as.empty() || G.gammas.empty() || G.betas.empty() ||
                G.schemes.empty())
                throw std::runtime_error("--L, --q, --a, --gamma, --betas and --schemes need at least one value");
            for (double b : G.betas)
                if (!(b > 0)) throw std::runtime_error("--betas must be > 0 (beta = 0 is the dry map)");
            if (!(G.pl >= 0 && G.pl <= 1)) throw std::runtime_error("--pl must lie in [0, 1]");
            if (!(G.budget > 0)) throw std::runtime_error("--budget must be > 0 seconds");
            if (!(G.relax_budget >= 0)) throw std::runtime_error("--relax-budget must be >= 0 seconds (0: skip)");
            if (!(G.best_tol >= 0)) throw std::runtime_error("--best-tol must be >= 0");
            for (double L : G.Ls)
                for (double q : G.qs) {
                    MikadoParams mp;
                    mp.L = L, mp.q = q, mp.pl = G.pl, mp.seed = G.seed;
                    mp.check("bench_solvers");
                }
            for (double a : G.as) {
                DiscretizationParams dp;
                dp.aspect_ratio = a;
                dp.check("bench_solvers");
            }
        } catch (const std::exception& e) {
            std::cerr << "bad option: " << e.what() << "\n";
            return 2;
        }
        return stability_wet(G);
    }
    std::vector<std::string> solvers = split(arg["solvers"]);
    if (solvers.empty()) solvers = bench_solver_names();
    for (const auto& n : solvers) bench_solver(n, SolverOptions{});  // an unknown name fails here
    const std::string mode = arg["mode"], out = arg["out"];
    const double tol_abs = std::stod(arg["tol"]), rel_tol = std::stod(arg["rel-tol"]);
    const int max_iter = std::stoi(arg["max-iter"]);
    const bool verbose = arg["verbose"] == "1";
    const auto Ls = split_d(arg["L"]), qs = split_d(arg["q"]), as = split_d(arg["a"]), gammas = split_d(arg["gamma"]);
    const auto budgets = split_d(arg["budget"]);
    const auto schemes = split(arg["schemes"]);
    const std::uint64_t seed = std::stoull(arg["seed"]);
    Pruning pruning;
    try {
        pruning = parse_prune(arg["prune"]);
    } catch (const std::exception& e) {
        std::cerr << e.what() << "\n";
        return 2;
    }

    if (mode == "discretization") {
        std::ofstream os(out + "/discretization.csv");
        os << "L,q,a,seed,scheme,n_seg,h,fibers,nodes,dof,nodes_per_fiber,shortest_segment,G,G_affine,G_ref,rel_err,"
              "moduli_ok,seconds_discretize,seconds_modulus\n";
        for (double L : Ls)
            for (double q : qs)
                for (double a : as) {
                    const Network net = make_network(L, q, seed, pruning);
                    struct Row { std::string scheme; int n_seg; double h; int nodes, dof; double shortest, G, Ga, td, tm; bool ok; };
                    std::vector<Row> rows;
                    auto run = [&](Scheme sc, int n_seg, double h) {
                        DiscretizationParams dp;
                        dp.scheme = sc, dp.n_seg = n_seg, dp.h = h, dp.aspect_ratio = a, dp.trim_ends = pruning.ends;
                        const auto t0 = std::chrono::steady_clock::now();
                        const Model model = discretize(net, dp);
                        const NetworkEnergy e(model);
                        const auto t1 = std::chrono::steady_clock::now();
                        const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
                        ModuliInfo info;
                        const auto m = linear_moduli(e, e.dofs(model.x), I, {shear_mode(I, model.box.area())}, {}, &info);
                        const auto t2 = std::chrono::steady_clock::now();
                        Row r{to_string(sc), n_seg, h, model.num_nodes(), e.num_dofs(), summarize(model).shortest_segment,
                              m[0].value, m[0].affine, std::chrono::duration<double>(t1 - t0).count(),
                              std::chrono::duration<double>(t2 - t1).count(), m[0].ok};
                        std::fprintf(stderr, "L %g q %g a %g %s n_seg %d h %g: %d DOF  G %.10g  (%.3fs)\n", L, q, a,
                                     r.scheme.c_str(), n_seg, h, r.dof, r.G, r.tm);
                        rows.push_back(r);
                    };
                    for (double ns : split_d(arg["nseg"])) run(Scheme::Seed, static_cast<int>(ns), 1.0);
                    const auto hs = split_d(arg["h"]);
                    for (double h : hs) run(Scheme::Even, 10, h);
                    // Reference: the finest even discretization (the smallest h).
                    double Gref = 0, hmin = 1e300;
                    for (const auto& r : rows)
                        if (r.scheme == "even" && r.h < hmin) hmin = r.h, Gref = r.G;
                    for (const auto& r : rows)
                        os << L << "," << q << "," << a << "," << seed << "," << r.scheme << "," << r.n_seg << "," << r.h
                           << "," << net.fibers.size() << "," << r.nodes << "," << r.dof << ","
                           << double(r.nodes) / net.fibers.size() << "," << r.shortest << "," << std::setprecision(12)
                           << r.G << "," << r.Ga << "," << Gref << "," << std::setprecision(6)
                           << std::abs(r.G - Gref) / std::abs(Gref) << "," << r.ok << "," << r.td << "," << r.tm << "\n";
                    os.flush();
                }
        return 0;
    }

    if (mode == "ratio") {
        std::vector<std::string> names = split(arg["solvers"]);
        if (names.empty()) names = {"newton", "fire", "lbfgs"};
        const double ref_budget = std::stod(arg["ref-budget"]), target = std::stod(arg["ratio-tol"]);
        std::ofstream os(out + "/ratio.csv"), tr(out + "/ratio_trace.csv");
        os << "case,scheme,L,q,a,gamma,seed,prune,fibers,dof_unpruned,dof,solver,role,status,iterations,evaluations,"
              "factorizations,seconds,budget_s,tol,energy,rel_energy_err,grad_max,grad_min,target,t_target,t_ref,"
              "ratio,ratio_is_lower_bound,ratio_same_target,message\n";
        tr << "case,solver,t,evals,grad_min,energy\n";
        for (size_t li = 0; li < Ls.size(); ++li)
            for (double q : qs)
                for (double a : as)
                    for (double gamma : gammas)
                        for (const auto& sc : schemes) {
                            Case c{Ls[li], q, a, gamma, sc};
                            const double budget = budgets[std::min(li, budgets.size() - 1)];
                            DiscretizationParams dp;
                            dp.scheme = parse_scheme(sc), dp.aspect_ratio = a;
                            // DOF without pruning, for the record only.
                            const Model full = discretize(make_network(c.L, q, seed, {}), dp);
                            const int dof_full = NetworkEnergy(full).num_dofs();
                            dp.trim_ends = pruning.ends;
                            const Network net = make_network(c.L, q, seed, pruning);
                            const Model model = discretize(net, dp);
                            const NetworkEnergy energy(model);
                            const Eigen::Matrix2d F = deformation(StrainKind::Shear, gamma);
                            const Eigen::VectorXd q0 =
                                energy.affine_map(energy.dofs(model.x), Eigen::Matrix2d::Identity(), F);
                            c.dof = energy.num_dofs();
                            std::fprintf(stderr, "%s: %zu fibers, %d DOF (%d unpruned), prune '%s'\n", case_id(c).c_str(),
                                         net.fibers.size(), c.dof, dof_full, arg["prune"].c_str());
                            std::vector<Run> rs;
                            for (size_t k = 0; k < names.size(); ++k) {
                                // The reference runs to --tol; the others only need to reach the target, so they
                                // stop there (their time to it is the measurement).
                                SolverOptions opt;
                                opt.tol = k == 0 ? tol_abs : target, opt.max_iter = max_iter, opt.verbose = verbose;
                                opt.max_seconds = k == 0 ? ref_budget : budget;
                                auto solver = bench_solver(names[k], opt);
                                StrainedEnergy obj(energy, F);
                                Recorder rec(obj);
                                Eigen::VectorXd x = q0;
                                Run r;
                                r.solver = names[k];
                                try {
                                    r.res = solver->minimize(rec, x);
                                } catch (const std::exception& e) {
                                    r.res.status = SolveStatus::Failed, r.res.solver = names[k];
                                    r.res.message = std::string("exception: ") + e.what();
                                    r.res.energy = std::numeric_limits<double>::quiet_NaN();
                                }
                                r.samples = std::move(rec.samples);
                                std::fprintf(stderr, "  %-10s %-16s it %8d  t %8.2fs  E %.15g  max|g| %.2e  %s\n",
                                             names[k].c_str(), to_string(r.res.status).c_str(), r.res.iterations,
                                             r.res.timings.total, r.res.energy, r.res.grad_max, r.res.message.c_str());
                                rs.push_back(std::move(r));
                            }
                            double best = std::numeric_limits<double>::infinity();
                            for (const auto& r : rs) {
                                for (const auto& x : r.samples) best = std::min(best, x.energy);
                                if (std::isfinite(r.res.energy)) best = std::min(best, r.res.energy);
                            }
                            const double scale = std::max(std::abs(best), 1e-300);
                            // Newton's time is that of its converged return (to tol, or at its round-off floor,
                            // which the message states); no ratio without a converged reference.
                            const Run& ref = rs[0];
                            const double t_ref = ref.res.converged() ? ref.res.timings.total : -1;
                            const double t_ref_target = time_to(ref.samples, target);
                            for (size_t k = 0; k < rs.size(); ++k) {
                                const Run& r = rs[k];
                                double gmin = std::numeric_limits<double>::infinity();
                                for (const auto& x : r.samples) gmin = std::min(gmin, x.gmax);
                                const double tt = time_to(r.samples, target);
                                // Never reached: the target lies beyond the time the run took, so the ratio is at
                                // least that time over Newton's.
                                const bool lower = tt < 0;
                                const double t_other = lower ? r.res.timings.total : tt;
                                std::string ratio = "", same = "";
                                if (k > 0 && t_ref > 0) ratio = std::to_string(t_other / t_ref);
                                if (k > 0 && t_ref_target > 0) same = std::to_string(t_other / t_ref_target);
                                std::string msg = r.res.message;
                                std::replace(msg.begin(), msg.end(), ',', ';');
                                std::replace(msg.begin(), msg.end(), '"', '\'');
                                os << case_id(c) << "," << sc << "," << c.L << "," << q << "," << a << "," << gamma
                                   << "," << seed << ",\"" << arg["prune"] << "\"," << net.fibers.size() << ","
                                   << dof_full << "," << c.dof << "," << r.solver << "," << (k == 0 ? "ref" : "other")
                                   << "," << to_string(r.res.status) << "," << r.res.iterations << ","
                                   << r.res.evaluations << "," << r.res.factorizations << "," << r.res.timings.total
                                   << "," << (k == 0 ? ref_budget : budget) << "," << (k == 0 ? tol_abs : target)
                                   << "," << std::setprecision(17) << r.res.energy << "," << std::setprecision(6)
                                   << (r.res.energy - best) / scale << "," << r.res.grad_max << "," << gmin << ","
                                   << target << "," << (tt < 0 ? std::string("") : std::to_string(tt)) << ","
                                   << t_ref << "," << ratio << "," << (k > 0 && lower ? 1 : 0) << "," << same
                                   << ",\"" << msg << "\"\n";
                                if (k > 0)
                                    std::fprintf(stderr, "  %s: t(max|g| <= %g) %s, ratio to newton %s%s\n",
                                                 r.solver.c_str(), target,
                                                 lower ? "not reached" : std::to_string(tt).c_str(),
                                                 lower ? ">= " : "", ratio.c_str());
                                // Running minimum of max|g|, thinned to drops of >= 2% (plus the first and last).
                                double gm = std::numeric_limits<double>::infinity(), gl = gm;
                                for (size_t i = 0; i < r.samples.size(); ++i) {
                                    const auto& x = r.samples[i];
                                    gm = std::min(gm, x.gmax);
                                    if (i == 0 || i + 1 == r.samples.size() || gm < 0.98 * gl) {
                                        tr << case_id(c) << "," << r.solver << "," << std::setprecision(6) << x.t
                                           << "," << x.evals << "," << gm << "," << std::setprecision(17) << x.energy
                                           << "\n";
                                        gl = gm;
                                    }
                                }
                            }
                            os.flush();
                            tr.flush();
                        }
        return 0;
    }

    std::vector<std::pair<Case, double>> cases;  // with the time budget per run
    for (size_t li = 0; li < Ls.size(); ++li)
        for (double q : qs)
            for (double a : as)
                for (double gamma : gammas)
                    for (const auto& sc : schemes)
                        cases.push_back({Case{Ls[li], q, a, gamma, sc}, budgets[std::min(li, budgets.size() - 1)]});

    const bool wp = mode == "wp";
    std::ofstream runs(out + (wp ? "/runs.csv" : "/stability.csv"));
    std::ofstream trace;
    runs << "case,scheme,L,q,a,gamma,dof,shortest_segment,solver,status,iterations,evaluations,factorizations,"
            "seconds,budget_s,energy,energy_best,rel_energy_err,grad_max,tol,message\n";
    if (wp) {
        trace.open(out + "/trace.csv");
        trace << "case,scheme,L,a,dof,solver,t,evals,grad_min,rel_energy_err\n";
    }
    for (auto& [c, budget] : cases) {
        DiscretizationParams dp;
        dp.scheme = parse_scheme(c.scheme), dp.aspect_ratio = c.a, dp.trim_ends = pruning.ends;
        const Model model = discretize(make_network(c.L, c.q, seed, pruning), dp);
        const NetworkEnergy energy(model);
        const Eigen::Matrix2d F = deformation(StrainKind::Shear, c.gamma);
        const Eigen::VectorXd q0 = energy.affine_map(energy.dofs(model.x), Eigen::Matrix2d::Identity(), F);
        c.dof = energy.num_dofs();
        double tol = tol_abs;
        if (rel_tol > 0) {
            StrainedEnergy f0(energy, F);
            Eigen::VectorXd g0;
            f0.gradient(q0, g0);
            tol = rel_tol * g0.lpNorm<Eigen::Infinity>();
        }
        c.shortest = summarize(model).shortest_segment;
        std::vector<Run> rs;
        for (const auto& name : solvers) {
            SolverOptions opt;
            opt.tol = tol, opt.max_iter = max_iter, opt.max_seconds = budget, opt.verbose = verbose;
            auto solver = bench_solver(name, opt);
            StrainedEnergy obj(energy, F);
            Recorder rec(obj);
            Eigen::VectorXd q = q0;
            Run r;
            r.solver = name;
            try {
                r.res = solver->minimize(rec, q);
            } catch (const std::exception& e) {
                r.res.status = SolveStatus::Failed, r.res.solver = name, r.res.message = std::string("exception: ") + e.what();
                r.res.energy = std::numeric_limits<double>::quiet_NaN();
            }
            r.samples = std::move(rec.samples);
            std::fprintf(stderr, "%-28s %-14s %-18s it %7d  t %7.3fs  E %.15g  max|g| %.2e  %s\n", case_id(c).c_str(),
                         name.c_str(), to_string(r.res.status).c_str(), r.res.iterations, r.res.timings.total,
                         r.res.energy, r.res.grad_max, r.res.message.c_str());
            rs.push_back(std::move(r));
        }
        double best = std::numeric_limits<double>::infinity();
        for (const auto& r : rs) {
            for (const auto& s : r.samples) best = std::min(best, s.energy);
            if (std::isfinite(r.res.energy)) best = std::min(best, r.res.energy);
        }
        const double scale = std::max(std::abs(best), 1e-300);
        for (const auto& r : rs) {
            std::string msg = r.res.message;
            std::replace(msg.begin(), msg.end(), ',', ';');
            std::replace(msg.begin(), msg.end(), '"', '\'');
            runs << case_id(c) << "," << c.scheme << "," << c.L << "," << c.q << "," << c.a << "," << c.gamma << ","
                 << c.dof << "," << c.shortest << "," << r.solver << "," << to_string(r.res.status) << ","
                 << r.res.iterations << "," << r.res.evaluations << "," << r.res.factorizations << ","
                 << r.res.timings.total << "," << budget << "," << std::setprecision(17) << r.res.energy << ","
                 << best << "," << std::setprecision(6) << (r.res.energy - best) / scale << "," << r.res.grad_max
                 << "," << tol << ",\"" << msg << "\"\n";
            if (!wp) continue;
            // Running minima, thinned to points where either dropped by >= 2% (plus the first and last).
            double gmin = std::numeric_limits<double>::infinity(), emin = gmin, gl = gmin, el = gmin;
            for (size_t i = 0; i < r.samples.size(); ++i) {
                const auto& s = r.samples[i];
                gmin = std::min(gmin, s.gmax);
                emin = std::min(emin, (s.energy - best) / scale);
                const bool last = i + 1 == r.samples.size();
                if (i == 0 || last || gmin < 0.98 * gl || emin < 0.98 * el) {
                    trace << case_id(c) << "," << c.scheme << "," << c.L << "," << c.a << "," << c.dof << ","
                          << r.solver << "," << std::setprecision(6) << s.t << "," << s.evals << "," << gmin << ","
                          << std::max(emin, 0.0) << "\n";
                    gl = gmin, el = emin;
                }
            }
        }
        runs.flush();
        trace.flush();
    }
    return 0;
}
