// Pebble-game timings (issue 4, "Performance"): clamped open Mikado networks of 1e4, 1e5 and 1e6 fibers at a
// density near the rigidity threshold (q = 7, pl = 1; docs/percolation) and well above it (q = 10). Times the
// framework construction and the pebble game (bars, d, rigid clusters) separately from the network generation;
// best of `reps` runs. Prints a markdown table and the scaling exponent t ~ N^alpha from 1e4 to 1e6.
// Usage: bench_pebble [max_fibers=1e6] [reps=3]
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "fibernet/network/clamp.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/rigidity.hpp"

using namespace fibernet;
using Clock = std::chrono::steady_clock;

static double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int main(int argc, char** argv) {
    const double max_n = argc > 1 ? std::atof(argv[1]) : 1e6;
    const int reps = argc > 2 ? std::atoi(argv[2]) : 3;
    std::printf("| fibers N | q | L | crosslinks | generate (s) | framework (s) | pebble game (s) | pebble game CPU (s) | redundant | d | largest rigid cluster |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (double q : {7.0, 10.0}) {
        std::vector<double> ns, ts;
        for (double n = 1e4; n <= max_n * 1.0001; n *= 10) {
            const double L = std::sqrt(n / q);
            double t_gen = 1e300, t_fw = 1e300, t_game = 1e300, c_game = 1e300;  // CPU time: less sensitive to a loaded machine
            RigidityResult r;
            long crosslinks = 0;
            for (int k = 0; k < reps; ++k) {
                auto t0 = Clock::now();
                const Network net = generate_mikado({L, q, 1.0, static_cast<std::uint64_t>(k + 1), false});
                t_gen = std::min(t_gen, since(t0));
                crosslinks = net.num_crosslinks();
                t0 = Clock::now();
                const BodyPinFramework fw = body_pin_framework(clamp_network(net));
                t_fw = std::min(t_fw, since(t0));
                t0 = Clock::now();
                const std::clock_t c0 = std::clock();
                r = analyze_rigidity(fw);
                c_game = std::min(c_game, double(std::clock() - c0) / CLOCKS_PER_SEC);
                t_game = std::min(t_game, since(t0));
            }
            std::printf("| %.0e | %g | %.1f | %ld | %.3f | %.3f | %.3f | %.3f | %ld | %d | %d |\n", n, q, L, crosslinks, t_gen,
                        t_fw, t_game, c_game, r.redundant, r.d, r.largest_cluster);
            std::fflush(stdout);
            ns.push_back(n), ts.push_back(c_game);
        }
        if (ns.size() >= 2)
            std::printf("\nq = %g: pebble-game CPU time ~ N^%.2f (from N = %.0e to %.0e)\n\n", q,
                        std::log(ts.back() / ts.front()) / std::log(ns.back() / ns.front()), ns.front(), ns.back());
    }
}
