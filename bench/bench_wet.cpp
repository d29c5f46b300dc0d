// Wet relaxation benchmark (issue 6, "Performance"): a Mikado network of N fibers (density q, pl = 0.5, seed
// scheme) relaxed dry, wetted at all crossings and relaxed under capillary load with mobile bridges.
// Prints one JSON line per run with the time split: dry Newton, wet Newton, event handling, pore analysis.
//   bench_wet [N=1000] [q=10] [beta=0.01] [max_rounds=1000] [newton_max_iter=500] [scheme=seed] [seed=1] [move_margin=0.1]
//             [round_iterations=10] [warm_start=1] [newton_ldl=1] [local_fraction=0.25] [local_threshold=0.1]
//             [local_hops=3] [model=events]
// The "newton" block sums the wet solves' time split over all rounds.
// Environment: BENCH_VERBOSE=1 prints a line per active-set round, BENCH_NEWTON_VERBOSE=1 a line per Newton iteration.
// Smooth model (model=smooth): BENCH_PATTERN_DISTANCE, BENCH_SKIN, BENCH_MAX_STEP override SmoothWetParams'
// pattern_distance and skin and SmoothRelaxOptions' max_step; BENCH_ANGLES="lo hi" the blend's angles (degrees).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/wet/wet_run.hpp"

using namespace fibernet;

int main(int argc, char** argv) {
    const int N = argc > 1 ? std::atoi(argv[1]) : 1000;
    const double q = argc > 2 ? std::atof(argv[2]) : 10;
    const double beta = argc > 3 ? std::atof(argv[3]) : 0.01;
    const int rounds = argc > 4 ? std::atoi(argv[4]) : ActiveSetOptions{}.max_rounds;
    const int max_iter = argc > 5 ? std::atoi(argv[5]) : 500;
    const std::string scheme = argc > 6 ? argv[6] : "seed";
    const unsigned seed = argc > 7 ? static_cast<unsigned>(std::atoi(argv[7])) : 1u;
    const double move_margin = argc > 8 ? std::atof(argv[8]) : ActiveSetOptions{}.move_margin;
    const int round_iterations = argc > 9 ? std::atoi(argv[9]) : ActiveSetOptions{}.round_iterations;
    const bool warm_start = argc > 10 ? std::atoi(argv[10]) != 0 : ActiveSetOptions{}.warm_start;
    const bool newton_ldl = argc > 11 ? std::atoi(argv[11]) != 0 : ActiveSetOptions{}.newton_ldl;
    const double local_fraction = argc > 12 ? std::atof(argv[12]) : ActiveSetOptions{}.local_fraction;
    const double local_threshold = argc > 13 ? std::atof(argv[13]) : ActiveSetOptions{}.local_threshold;
    const int local_hops = argc > 14 ? std::atoi(argv[14]) : ActiveSetOptions{}.local_hops;
    const WetModel model = parse_wet_model(argc > 15 ? argv[15] : "events");
    const auto t0 = std::chrono::steady_clock::now();
    MikadoParams mp;
    mp.q = q, mp.pl = 0.5, mp.seed = seed;
    mp.L = std::sqrt(N / q);  // N = q L^2 (fiber lengths)
    const Network net = generate_mikado(mp);
    DiscretizationParams dp;
    dp.scheme = parse_scheme(scheme);
    const Model m = discretize(net, dp);
    const double t_build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    WetRunOptions opt;
    opt.params.beta = beta;
    opt.moduli = false;
    opt.active_set.max_rounds = rounds;
    opt.active_set.move_margin = move_margin;
    opt.active_set.round_iterations = round_iterations;
    opt.active_set.warm_start = warm_start;
    opt.active_set.newton_ldl = newton_ldl;
    opt.active_set.local_fraction = local_fraction;
    opt.active_set.local_threshold = local_threshold;
    opt.active_set.local_hops = local_hops;
    opt.model = model;
    opt.smooth_relax.round_iterations = round_iterations;
    opt.smooth_relax.progress = std::getenv("BENCH_VERBOSE") != nullptr;
    if (const char* v = std::getenv("BENCH_PATTERN_DISTANCE")) opt.smooth.pattern_distance = std::atof(v);
    if (const char* v = std::getenv("BENCH_SKIN")) opt.smooth.skin = std::atof(v);
    if (const char* v = std::getenv("BENCH_MAX_STEP")) opt.smooth_relax.max_step = std::atof(v);
    if (const char* v = std::getenv("BENCH_ANGLES"))
        std::sscanf(v, "%lf %lf", &opt.smooth.pair.angle_lo_deg, &opt.smooth.pair.angle_hi_deg);
    opt.active_set.verbose = std::getenv("BENCH_VERBOSE") != nullptr;  // a line per active-set round on stderr
    opt.solver_options.tol = 1e-8;
    opt.solver_options.max_iter = max_iter;
    opt.solver_options.verbose = std::getenv("BENCH_NEWTON_VERBOSE") != nullptr;  // a line per Newton iteration
    const WetRun r = run_wet(net, m, Eigen::Matrix2d::Identity(), opt);
    const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf(
        "{\"fibers\": %zu, \"q\": %g, \"beta\": %g, \"nodes\": %d, \"bridges_initial\": %zu, \"bridges_final\": %zu, "
        "\"rounds\": %d, \"local_rounds\": %d, \"local_iterations\": %d, \"E_total\": %.10g, \"E_capillary\": %.10g, \"stable\": %s, \"cycling\": %s, \"cycles_broken\": %d, \"newton_iterations\": %d, \"events\": %d, "
        "\"seconds\": {\"build\": %.3f, \"dry\": %.3f, \"wet_newton\": %.3f, \"wet_local\": %.3f, \"events\": %.3f, \"update\": %.3f, \"gradient\": %.3f, \"local_setup\": %.3f, \"pores\": %.3f, "
        "\"total\": %.3f}, \"newton\": {\"factorizations\": %d, \"assembly\": %.3f, "
        "\"factorization\": %.3f, \"solve\": %.3f, \"line_search\": %.3f, \"total\": %.3f}, \"newton_local\": {\"assembly\": %.3f, "
        "\"factorization\": %.3f, \"solve\": %.3f, \"line_search\": %.3f, \"total\": %.3f}, \"model\": \"%s\", "
        "\"smooth\": {\"list_builds\": %d, \"pattern_builds\": %d, \"stale_patterns\": %d, \"grad_max\": %.3g, "
        "\"seconds_patterns\": %.3f}, \"message\": \"%s\"}\n",
        net.fibers.size(), q, beta, m.num_nodes(), r.initial_bridges.size(), r.active.bridges.size(), r.active.rounds, r.active.local_rounds, r.active.local_iterations, r.wet.energy.total(), r.wet.energy.capillary,
        r.active.stable ? "true" : "false", r.active.cycling ? "true" : "false", r.active.cycles_broken, r.active.solver_iterations,
        r.active.events.total(), t_build, r.seconds_dry, r.seconds_wet_solve, r.active.seconds_local, r.seconds_events, r.active.seconds_update, r.active.seconds_gradient, r.active.seconds_local_setup, r.seconds_pores, total,
        r.active.factorizations, r.active.timings.assembly, r.active.timings.factorization, r.active.timings.solve,
        r.active.timings.line_search, r.active.timings.total, r.active.timings_local.assembly,
        r.active.timings_local.factorization, r.active.timings_local.solve, r.active.timings_local.line_search,
        r.active.timings_local.total, to_string(model).c_str(), r.smooth.list_builds, r.smooth.pattern_builds,
        r.smooth.stale_patterns, r.smooth.grad_max, r.smooth.seconds_patterns, r.active.message.c_str());
    return 0;
}
