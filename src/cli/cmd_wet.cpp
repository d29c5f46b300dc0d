// fibernet wet: dry network -> relax -> wet -> relax under capillary load (issue 6). JSON summary on stdout; with
// -o DIR also summary.json, sweep.csv, pores.csv, network.svg (dry | wet), pores.svg (pore-size distributions) and
// state_<k>.txt and state_<k>.vtp, beta k's wet equilibrium as a model file and for ParaView (with its bridges).
// With --free-box (or [wet] free_box = true) each beta's wet state is then taken to its zero-stress box (drying
// shrinkage; docs/wet.md, "Free box"), one progress line per outer iteration on stderr.
// Exit 1 when a relaxation did not reach a stable equilibrium or the free box did not converge (results still
// reported, marked). With -o, the directory's previous results are invalidated at the start, and the tables and
// summary.json (complete: false) are rewritten after every beta; SIGINT/SIGTERM end the run at once with the finished
// betas kept and reported (exit 130), and the smooth model's relaxation in progress in its last checkpoint
// (wet_checkpoint.hpp: --checkpoint-seconds, --start-state).
#include <algorithm>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <optional>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common.hpp"
#include "wet_checkpoint.hpp"
#include "fibernet/export/vtp.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/energy/capillary.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/hash.hpp"
#include "fibernet/wet/wet_run.hpp"
#include "fibernet/wet/wet_svg.hpp"

namespace fibernet::cli {

nlohmann::json solve_json(const SolveResult& r, double tol);  // cmd_modulus.cpp

namespace {
// Interrupts (SIGINT, SIGTERM). A beta's relaxation cannot be stopped midway (run_wet has no stop hook, and one beta
// can take minutes; the smooth model's writes checkpoints instead), so the handler ends the process at once with what
// is finished: the report of the finished betas (prepared after each one) on stdout, a line on stderr, exit 130; their
// files are on disk already. The handler may run
// on any thread (OpenMP, OpenBLAS, FIBERNET_THREADS workers), so the main thread holds it off with g_state while it
// writes files or changes the prepared texts (kWriting): a signal then is only noted (g_pending) and the writer exits
// when done. Whoever moves kRunning -> kExiting exits; the other waits for it.
enum : int { kRunning = 0, kWriting = 1, kExiting = 2 };
std::atomic<int> g_state{kRunning};
std::atomic<bool> g_pending{false};
std::string g_report, g_message;  // changed only in kWriting, read only in kExiting

void write_all(int fd, const std::string& s) {  // write(2) only: async-signal-safe
    const char* p = s.data();
    size_t n = s.size();
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return;
        p += w, n -= static_cast<size_t>(w);
    }
}

[[noreturn]] void exit_interrupted() {
    write_all(STDOUT_FILENO, g_report);
    write_all(STDERR_FILENO, g_message);
    _exit(130);
}

extern "C" void on_wet_signal(int) {
    const int saved = errno;
    for (;;) {
        int expected = kRunning;
        if (g_state.compare_exchange_strong(expected, kExiting)) exit_interrupted();
        if (expected == kExiting) break;  // a second signal, or the writer is exiting already
        g_pending = true;                  // kWriting: the writer exits when done
        if (g_state.load() == kWriting) break;
        // The writer finished before it could see g_pending: exit here, or let it (whoever wins the exchange).
    }
    errno = saved;
}

// hold() holds the handler off (kWriting) while the main thread writes files or the prepared texts; release() lets it
// act again, and ends the run at once if an interrupt came meanwhile (the files are complete by then).
void hold() {
    int expected = kRunning;
    if (!g_state.compare_exchange_strong(expected, kWriting))
        for (;;) pause();  // the handler is exiting the process
}

void release() {
    g_state = kRunning;
    if (g_pending) {
        int expected = kRunning;
        if (g_state.compare_exchange_strong(expected, kExiting)) exit_interrupted();
        for (;;) pause();
    }
}

// Installs the handler for the loop over betas and puts the previous dispositions back when the command ends (also by
// an exception). A SIGINT ignored from the start stays ignored: a shell script's background job gets it so, and
// Ctrl-C meant for the script must not end it (SIGTERM still does).
struct InterruptScope {
    struct sigaction old_int {}, old_term {};
    InterruptScope() {
        struct sigaction sa {};
        sa.sa_handler = on_wet_signal;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESTART;
        sigaction(SIGINT, nullptr, &old_int);
        if (old_int.sa_handler != SIG_IGN) sigaction(SIGINT, &sa, nullptr);
        sigaction(SIGTERM, &sa, &old_term);
    }
    ~InterruptScope() {
        sigaction(SIGINT, &old_int, nullptr);
        sigaction(SIGTERM, &old_term, nullptr);
    }
};

// --betas: comma-separated lists (one or more of them). CLI11's own split drops empty entries ("0,,0.1" ran two
// betas), so the lists are split here and every entry must be a number.
std::vector<double> parse_betas(const std::vector<std::string>& lists) {
    std::vector<double> betas;
    for (const std::string& list : lists) {
        const std::string where = "command line: --betas '" + list + "'";
        size_t start = 0;
        for (int entry = 1;; ++entry) {
            const size_t comma = list.find(',', start);
            std::string t = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
            const size_t a = t.find_first_not_of(" \t"), b = t.find_last_not_of(" \t");
            t = a == std::string::npos ? "" : t.substr(a, b - a + 1);
            if (t.empty()) throw InputError(where + ": entry " + std::to_string(entry) + " is empty");
            char* end = nullptr;
            const double v = std::strtod(t.c_str(), &end);
            if (*end) throw InputError(where + ": entry " + std::to_string(entry) + ", '" + t + "', is not a number");
            check_value(v >= 0 && std::isfinite(v), v, where, "beta", "must be finite and >= 0");
            betas.push_back(v);
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
    }
    return betas;
}

// This process's arguments (Linux /proc), so a summary says how it was made; null where /proc is missing.
nlohmann::json command_line() {
    std::ifstream is("/proc/self/cmdline", std::ios::binary);
    if (!is) return nullptr;
    nlohmann::json args = nlohmann::json::array();
    for (std::string a; std::getline(is, a, '\0');) args.push_back(a);
    return args.empty() ? nlohmann::json() : args;
}

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

nlohmann::json pore_json(const PoreStats& p) {
    double sum = 0, dsum = 0, amax = 0;
    for (const auto& q : p.pores) sum += q.area, dsum += q.diameter, amax = std::max(amax, q.area);
    const double n = static_cast<double>(p.pores.size());
    return {{"count", p.pores.size()}, {"mean_area", n ? num(sum / n) : nlohmann::json()},
            {"mean_diameter", n ? num(dsum / n) : nlohmann::json()}, {"largest_area", amax},
            {"remainder_area", p.remainder}, {"box_area", p.box_area}, {"wall_width", p.wall_width},
            {"walls", p.walls}, {"wall_area", p.wall_area}, {"island_faces", p.island_faces},
            {"island_area", p.island_area}, {"islands", p.islands}, {"open_faces", p.open_faces},
            {"open_area", p.open_area}, {"cover", p.cover()}};
}

nlohmann::json energy_json(const WetSplit& e) {
    return {{"total", e.total()}, {"stretch", e.stretch}, {"bend", e.bend}, {"capillary", e.capillary}};
}

nlohmann::json matrix_json(const Eigen::Matrix2d& M) {
    return nlohmann::json::array({nlohmann::json::array({M(0, 0), M(0, 1)}), nlohmann::json::array({M(1, 0), M(1, 1)})});
}

nlohmann::json stress_json(const Stress& s, double sc) {
    const double xy = 0.5 * (s.sigma(0, 1) + s.sigma(1, 0));
    return {{"sigma", {{"xx", s.sigma(0, 0)}, {"yy", s.sigma(1, 1)}, {"xy", xy}}},
            {"relative", {{"xx", s.sigma(0, 0) / sc}, {"yy", s.sigma(1, 1) / sc}, {"xy", xy / sc},
                          {"mean_normal", 0.5 * (s.sigma(0, 0) + s.sigma(1, 1)) / sc}}},
            {"area", s.area}};
}

nlohmann::json free_box_json(const FreeBoxResult& f, const FreeBoxOptions& o) {
    nlohmann::json j = {{"attempted", f.attempted},
                        {"converged", f.converged},
                        {"message", f.message},
                        {"shape", o.isotropic ? "isotropic" : "full"},
                        {"controlled", o.isotropic ? "mean normal stress" : "sigma_xx, sigma_yy, sigma_xy"},
                        {"tol", o.tol}};
    if (!f.attempted) return j;
    nlohmann::json hist = nlohmann::json::array();
    for (const auto& it : f.history)
        hist.push_back({{"iteration", it.iteration}, {"F", matrix_json(it.F)},
                        {"sigma_relative", {it.sigma[0], it.sigma[1], it.sigma[2]}}, {"residual", it.residual},
                        {"energy", it.energy}, {"step", it.step}, {"trials", it.trials}, {"rounds", it.relax_rounds},
                        {"solver_iterations", it.solver_iterations}, {"seconds", it.seconds}});
    nlohmann::json eig = nlohmann::json::array();
    for (int k = 0; k < f.stiffness_eigenvalues.size(); ++k) eig.push_back(f.stiffness_eigenvalues[k]);
    // Stable: no eigenvalue below -1e-6 sigma_c (round-off of the finite differences, well below any real mode).
    const bool stable = f.stiffness_eigenvalues.size() && f.stiffness_eigenvalues.minCoeff() >= -1e-6 * f.stress_scale;
    nlohmann::json bh = nlohmann::json::object();
    for (const auto& [size, count] : f.bundles.histogram) bh[std::to_string(size)] = count;
    j.update({{"F0", matrix_json(f.F0)},
              {"F", matrix_json(f.F)},
              {"s", f.s},
              {"det_ratio", f.F.determinant() / f.F0.determinant()},
              {"areal_shrinkage", f.areal_shrinkage},
              {"stress_scale", f.stress_scale},
              {"stress_fixed_box", stress_json(f.stress0, f.stress_scale)},
              {"stress", stress_json(f.stress, f.stress_scale)},
              {"bracketed", f.bracketed},
              {"snap", f.snap ? nlohmann::json({{"s", {f.snap_s[0], f.snap_s[1]}},
                                                {"residual", {f.snap_residual[0], f.snap_residual[1]}}})
                              : nlohmann::json()},
              {"residual_fixed_box", f.residual0},
              {"residual", f.residual},
              {"stiffness_eigenvalues", eig},
              {"stable", f.stiffness_eigenvalues.size() ? nlohmann::json(stable) : nlohmann::json()},
              {"iterations", f.iterations},
              {"relaxations", f.relaxations},
              {"stiffness_solves", f.stiffness_solves},
              {"stiffness_retries", f.stiffness_retries},
              {"solver_iterations", f.solver_iterations},
              {"energy", energy_json(f.energy)},
              {"bridges", f.bridges.size()},
              {"events",
               {{"moves", f.events.moves}, {"ruptures", f.events.ruptures}, {"formed", f.events.formed},
                {"merged", f.events.merged}, {"locked", f.events.locked}, {"capped", f.events.capped}}},
              {"pores", pore_json(f.pores)},
              {"shear_modulus", num(f.shear_modulus)},
              {"shear_modulus_error", num(f.shear_modulus_error)},
              {"bundles",
               {{"bundled_fibers", f.bundles.bundled_fibers}, {"count", f.bundles.sizes.size()},
                {"largest", f.bundles.sizes.empty() ? 1 : f.bundles.sizes.front()}, {"size_histogram", bh}}},
              {"history", hist},
              {"seconds", f.seconds}});
    return j;
}
struct WetFlags {
    std::vector<std::string> betas;
    std::string out;
    bool no_moduli = false, verbose = false, quiet = false;
    double modulus_strain = 0;
};

// The workflow's options from the scene and the command's flags; the law file's text in law_text (recorded in the
// summary: the file may change or go). The moduli's strain is set by the caller.
WetRunOptions run_options(const Scene& s, const WetFlags& w, std::string& law_text) {
    WetRunOptions opt;
    if (!s.wet.law.empty()) {
        opt.params.law = CapillaryLaw::read(s.wet.law);
        law_text = file_bytes(s.wet.law, "capillary law file");
    }
    opt.rule.which = parse_wet_which(s.wet.crossings);
    opt.rule.fraction = s.wet.fraction, opt.rule.seed = s.wet.seed;
    opt.solver = s.solver.name;
    opt.solver_options.tol = s.solver.tol, opt.solver_options.max_iter = s.solver.max_iter;
    opt.solver_options.eliminate = s.wet.newton_eliminate;
    if (s.wet.model == "smooth") opt.solver_options.elimination.hops = s.wet.eliminate_hops;
    if (s.wet.schwarz_block > 0) {
        opt.solver_options.eliminate = true;
        opt.solver_options.elimination.block = s.wet.schwarz_block;
        opt.solver_options.elimination.overlap = s.wet.schwarz_overlap;
    }
    opt.solver_options.verbose = w.verbose;
    opt.active_set.verbose = w.verbose || !w.quiet;
    opt.active_set.max_rounds = s.wet.max_rounds;
    opt.active_set.round_iterations = s.wet.round_iterations;
    opt.active_set.newton_ldl = s.wet.newton_ldl;
    opt.active_set.local_fraction = s.wet.local_fraction;
    opt.active_set.local_threshold = s.wet.local_threshold;
    opt.active_set.local_hops = s.wet.local_hops;
    opt.active_set.bundle_partners = s.wet.bundle_partners;
    opt.model = parse_wet_model(s.wet.model);
    opt.smooth.skin = s.wet.skin;
    opt.smooth.bundle_partners = s.wet.bundle_partners;
    opt.smooth.pair.crossing_width = s.wet.crossing_width;  // 0: from the model (run_wet)
    opt.smooth.pair.contact = s.wet.contact_distance;
    opt.smooth.pair.overlap_width = 0;  // the fiber radius
    opt.smooth_relax.round_iterations = s.wet.round_iterations;
    opt.smooth_relax.max_rounds = s.wet.max_rounds;
    opt.smooth_relax.ldl = s.wet.newton_ldl;
    opt.smooth_relax.projected = s.wet.newton_projected;
    opt.smooth_relax.progress = w.verbose || !w.quiet;
    opt.moduli = !w.no_moduli;
    opt.free_box.enabled = s.wet.free_box;
    opt.free_box.isotropic = s.wet.free_box_shape == "isotropic";
    opt.free_box.tol = s.wet.free_box_tol;
    opt.free_box.progress = !w.quiet;
    return opt;
}

// summary.json's `wet` block: every [wet] setting the results depend on (docs/formats.md, "Wet scenes").
nlohmann::json wet_settings_json(const Scene& s, const std::vector<double>& betas, const std::string& law_text,
                                 const WetRunOptions& opt, const StartState* start) {
    const bool fraction = s.wet.crossings == "fraction";
    return nlohmann::json{
        {"betas", betas},
        {"law", s.wet.law.empty() ? "cos2" : s.wet.law},
        {"law_table", s.wet.law.empty() ? nlohmann::json() : nlohmann::json(law_text)},
        {"law_fnv1a", s.wet.law.empty() ? nlohmann::json() : nlohmann::json(fnv1a_bytes(law_text))},
        {"crossings", s.wet.crossings},
        {"fraction", s.wet.fraction},
        {"seed", fraction ? nlohmann::json(s.wet.seed) : nlohmann::json()},  // no draw otherwise
        {"max_rounds", s.wet.max_rounds},
        {"round_iterations", s.wet.round_iterations},
        {"newton_ldl", s.wet.newton_ldl},
        {"newton_projected", s.wet.newton_projected},
        {"local_fraction", s.wet.local_fraction},
        {"local_threshold", s.wet.local_threshold},
        {"local_hops", s.wet.local_hops},
        {"bundle_partners", s.wet.bundle_partners},
        {"model", s.wet.model},
        {"crossing_width", s.wet.crossing_width},
        {"contact_distance", s.wet.contact_distance},
        {"skin", s.wet.skin},
        {"checkpoint_seconds", s.wet.checkpoint_seconds},
        {"start_state", start ? start->record : nlohmann::json()},
        {"free_box", s.wet.free_box},
        {"free_box_shape", s.wet.free_box ? nlohmann::json(s.wet.free_box_shape) : nlohmann::json()},
        {"free_box_tol", s.wet.free_box ? nlohmann::json(s.wet.free_box_tol) : nlohmann::json()},
        {"moduli", opt.moduli},
        {"modulus_strain", opt.moduli ? nlohmann::json(opt.modulus_strain) : nlohmann::json()}};
}

// One row of sweep.csv (its header in register_wet).
void sweep_row(std::ostream& sweep, double beta, const char* status, const WetRun& r, const WetState& dry_state,
               bool free_box) {
    const auto& pw = r.wet.pores.pores;
    double sum = 0, dsum = 0;
    for (const auto& p : pw) sum += p.area, dsum += p.diameter;
    const int largest = r.bundles.sizes.empty() ? 1 : r.bundles.sizes.front();
    sweep << beta << "," << status << "," << r.active.bridges.size() << ","
          << r.active.events.moves << "," << r.active.events.ruptures << "," << r.active.events.formed << ","
          << r.active.events.merged << "," << r.active.rounds << "," << r.wet.energy.stretch << ","
          << r.wet.energy.bend << "," << r.wet.energy.capillary << "," << pw.size() << ","
          << (pw.empty() ? 0 : sum / pw.size()) << "," << (pw.empty() ? 0 : dsum / pw.size()) << ","
          << r.bundles.bundled_fibers << "," << largest << "," << dry_state.shear_modulus << ","
          << r.wet.shear_modulus << "," << dry_state.shear_modulus_fd << "," << r.wet.shear_modulus_fd;
    if (free_box)
        sweep << "," << (r.free_box.converged ? "converged" : "not_converged") << "," << r.free_box.s << ","
              << r.free_box.areal_shrinkage << "," << r.free_box.residual << "," << r.free_box.iterations << ","
              << r.free_box.shear_modulus;
    sweep << "\n";
}

// One run of summary.json's `runs` (docs/formats.md, "Wet scenes"); tol: the solver's, for its status.
nlohmann::json run_json(double beta, const char* status, const WetRun& r, const WetState& dry_state,
                        const WetRunOptions& opt, double tol) {
    const int largest = r.bundles.sizes.empty() ? 1 : r.bundles.sizes.front();
    nlohmann::json hist = nlohmann::json::object();
    for (const auto& [size, count] : r.bundles.histogram) hist[std::to_string(size)] = count;
    return nlohmann::json{{"beta", beta},
         {"status", status},
         {"message", r.active.message},
         {"energy", {{"dry", energy_json(r.dry.energy)}, {"wet", energy_json(r.wet.energy)}}},
         {"bridges", {{"initial", r.initial_bridges.size()}, {"final", r.active.bridges.size()}}},
         {"events",
          {{"moves", r.active.events.moves}, {"ruptures", r.active.events.ruptures},
           {"formed", r.active.events.formed}, {"merged", r.active.events.merged},
           {"locked", r.active.events.locked}, {"capped", r.active.events.capped}, {"rounds", r.active.rounds}, {"cycling", r.active.cycling},
           {"cycles_broken", r.active.cycles_broken}, {"frozen_pairs", r.active.frozen_pairs},
           {"local_rounds", r.active.local_rounds}, {"local_iterations", r.active.local_iterations}}},
         {"bundles",
          {{"bundled_fibers", r.bundles.bundled_fibers}, {"count", r.bundles.sizes.size()},
           {"largest", largest}, {"size_histogram", hist}, {"aligned_bridges", r.bundles.aligned_bridges}}},
         {"pores", {{"dry", pore_json(r.dry.pores)}, {"wet", pore_json(r.wet.pores)}}},
         {"shear_modulus", {{"dry", num(dry_state.shear_modulus)}, {"wet", num(r.wet.shear_modulus)}}},
         {"shear_modulus_error", {{"dry", num(dry_state.shear_modulus_error)}, {"wet", num(r.wet.shear_modulus_error)}}},
         {"shear_modulus_second_difference",
          {{"dry", num(dry_state.shear_modulus_fd)}, {"wet", num(r.wet.shear_modulus_fd)},
           {"strain", opt.moduli ? nlohmann::json(opt.modulus_strain) : nlohmann::json()}}},
         {"solver", solve_json(r.active.last, tol)},
         {"free_box", opt.free_box.enabled ? free_box_json(r.free_box, opt.free_box) : nlohmann::json()},
         {"solver_iterations", r.active.solver_iterations},
         {"smooth", opt.model != WetModel::Smooth ? nlohmann::json()
                                                 : nlohmann::json{{"rounds", r.smooth.rounds},
                                                                  {"grad_max", r.smooth.grad_max},
                                                                  {"list_builds", r.smooth.list_builds},
                                                                  {"pattern_builds", r.smooth.pattern_builds},
                                                                  {"stale_patterns", r.smooth.stale_patterns},
                                                                  {"factorizations", r.smooth.factorizations},
                                                                  {"local_solves", r.smooth.local_solves},
                                                                  {"local_iterations", r.smooth.local_iterations},
                                                                  {"eliminating_iterations",
                                                                   r.smooth.eliminating_iterations},
                                                                  {"seconds_patterns", r.smooth.seconds_patterns},
                                                                  {"seconds_lists", r.smooth.seconds_lists},
                                                                  {"seconds_solver",
                                                                   {{"assembly", r.smooth.timings.assembly},
                                                                    {"factorization",
                                                                     r.smooth.timings.factorization},
                                                                    {"line_search", r.smooth.timings.line_search},
                                                                    {"total", r.smooth.timings.total}}}}},
         {"seconds",
          {{"dry", r.seconds_dry}, {"wet_solve", r.seconds_wet_solve}, {"events", r.seconds_events},
           {"pores", r.seconds_pores}, {"moduli", r.seconds_moduli},
           // parts: of wet_solve, the local rounds and, in them, building their pieces; of events, the bridge
           // update and the next set's gradient
           {"wet_local", r.active.seconds_local}, {"local_setup", r.active.seconds_local_setup},
           {"bridge_update", r.active.seconds_update}, {"gradient", r.active.seconds_gradient}}}};
}

// Beta k's wet equilibrium as a model file (docs/formats.md: the fibers' state, exact) and for ParaView with the
// bridges as vertices ("VTK"), written atomically into dir; returns the model file's name.
std::string write_state(const std::string& dir, size_t k, double beta, const Model& m, const Eigen::Matrix2d& F,
                        const WetRun& r) {
    const NetworkEnergy e(m);
    std::ostringstream state;
    write_model(state, m, e.displacements(r.wet.q, F), F);
    const std::string name = "state_" + std::to_string(k) + ".txt";
    write_file_atomic(dir + name, state.str());
    VtpFields vf;
    const Eigen::VectorXd x = e.positions(r.wet.q, F);
    for (const Bridge& b : r.active.bridges)
        vf.bridges.push_back(bridge_point(m, b, x, F * m.box.B0())), vf.bridge_locked.push_back(b.locked);
    vf.scalars = {{"beta", beta}};
    std::ostringstream vtp;
    write_vtp(vtp, e, r.wet.q, F, vf);
    write_file_atomic(dir + "state_" + std::to_string(k) + ".vtp", vtp.str());
    return name;
}

// pores.csv's rows, pores.svg's histograms and network.svg's panels (dry, then the last beta's wet state and its free
// box), gathered beta by beta.
struct WetPictures {
    std::ostringstream pore_csv;
    std::vector<SvgPanel> panels;
    std::vector<std::string> hist_names;
    std::vector<std::vector<double>> hist_values;
    bool dry_written = false;

    WetPictures() {
        pore_csv << "state,beta,area,diameter\n";
        pore_csv.precision(10);
    }
    void add(const WetRun& r, double beta, bool last, const Model& m, const Eigen::Matrix2d& F) {
        const Eigen::Matrix2d B = F * m.box.B0();
        const auto& pw = r.wet.pores.pores;
        if (!dry_written) {
            for (const auto& p : r.dry.pores.pores) pore_csv << "dry,0," << p.area << "," << p.diameter << "\n";
            std::vector<double> d;
            for (const auto& p : r.dry.pores.pores) d.push_back(p.diameter);
            hist_names.push_back("dry"), hist_values.push_back(d);
            NetworkEnergy e(m);
            panels.push_back({"dry", e.positions(r.dry.q, F), B, {}, {}, {}});
            dry_written = true;
        }
        for (const auto& p : pw) pore_csv << "wet," << beta << "," << p.area << "," << p.diameter << "\n";
        std::vector<double> d;
        for (const auto& p : pw) d.push_back(p.diameter);
        std::ostringstream name;
        name << "wet, beta = " << beta;
        hist_names.push_back(name.str()), hist_values.push_back(d);
        if (r.free_box.attempted) {
            std::vector<double> fd;
            for (const auto& p : r.free_box.pores.pores) {
                pore_csv << "free_box," << beta << "," << p.area << "," << p.diameter << "\n";
                fd.push_back(p.diameter);
            }
            hist_names.push_back(name.str() + ", free box"), hist_values.push_back(fd);
        }
        if (last) {
            NetworkEnergy e(m);
            std::vector<int> size(m.chains.size(), 0);
            for (int lab : r.bundles.bundle_of_fiber) ++size[lab];
            panels.push_back({name.str() + " (bridges red, bundles coloured)", e.positions(r.wet.q, F), B,
                              r.active.bridges, r.bundles.bundle_of_fiber, size});
            if (r.free_box.attempted) {
                std::vector<int> fsize(m.chains.size(), 0);
                for (int lab : r.free_box.bundles.bundle_of_fiber) ++fsize[lab];
                std::ostringstream fname;
                fname << name.str() << ", free box (" << (r.free_box.converged ? "" : "NOT converged, ")
                      << "areal shrinkage " << r.free_box.areal_shrinkage << ")";
                panels.push_back({fname.str(), e.positions(r.free_box.q, r.free_box.F),
                                  r.free_box.F * m.box.B0(), r.free_box.bridges, r.free_box.bundles.bundle_of_fiber,
                                  fsize});
            }
        }
    }
};

// What a wet run is given: the scene with the command's flags, checked whole; the betas; the workflow's options; and
// the law and network files' text, recorded in the summary (the files may change or go). InputError for bad input,
// before any work.
struct WetInputs {
    Scene s;
    std::vector<double> betas;
    WetRunOptions opt;
    std::string law_text, network_text;
};

WetInputs read_inputs(const SceneFlags& flags, const WetFlags& w, bool strain_given) {
    WetInputs in;
    Scene& s = in.s;
    in.s = flags.resolve(false);  // checked whole below, with the [wet] flags in
    refuse_trimmed_ends(s, "wet", "capillary bridges sit on the end arms");
    if (flags.given("--eliminate"))  // else silently without effect here
        throw InputError("command line: --eliminate and --no-eliminate set the dry solves' [solver] eliminate; the "
                         "wet relaxation's is --wet-eliminate ([wet] newton_eliminate, off by default)");
    if (flags.scene_file.empty() && !flags.given("--pl")) s.mikado.pl = 0.5;  // the thesis's wet networks
    s.source = flags.scene_file.empty() ? "command line" : flags.scene_file + " + command line";
    s.check();
    record_scene(s);
    in.betas = w.betas.empty() ? std::vector<double>{s.wet.beta} : parse_betas(w.betas);
    for (double b : in.betas) s.check_beta(b, "command line", "--betas entry");

    in.opt = run_options(s, w, in.law_text);
    if (!s.network_file.empty()) in.network_text = file_bytes(s.network_file, "network file");
    if (w.verbose && w.quiet) throw InputError("--verbose and --quiet contradict each other");
    // The smooth model's pair sum lets fibers stack without bound; at strong wetting its answer then depends on the
    // solver's path (docs/wet.md, "The partner cap in the smooth model"). Said once, quiet or not.
    if (in.opt.model == WetModel::Smooth && s.wet.bundle_partners == 0 &&
        *std::max_element(in.betas.begin(), in.betas.end()) >= 0.1)
        std::fprintf(stderr,
                     "wet: note: the smooth model without a partner cap at beta >= 0.1: fibers can stack without "
                     "bound and the equilibrium found depends on the solver's path; --bundle-partners 2 caps it "
                     "(docs/wet.md, \"The partner cap in the smooth model\")\n");
    if (strain_given) {
        check_value(std::isfinite(w.modulus_strain) && w.modulus_strain > 0 && w.modulus_strain <= 0.1,
                    w.modulus_strain, "--modulus-strain", "modulus strain", "must be in (0, 0.1]");
        if (w.no_moduli) throw InputError("--modulus-strain given with --no-moduli");
        in.opt.modulus_strain = w.modulus_strain;
    }
    make_solver(in.opt.solver, in.opt.solver_options);  // an unknown solver is an InputError before any work
    if (!s.wet.free_box && (flags.given("--free-box-shape") || flags.given("--free-box-tol")))
        throw InputError(std::string(flags.given("--free-box-shape") ? "--free-box-shape" : "--free-box-tol") +
                         " given without --free-box (or [wet] free_box = true)");
    return in;
}

// Checked before any output: the network (the free box needs a periodic one).
Network wet_network(const Scene& s) {
    Network net = scene_network(s);
    if (s.wet.free_box && !net.periodic)
        throw InputError(s.source + ": the free box needs a periodic network (an open network has no box stress)");
    return net;
}

// --out-dir: made (like mkdir -p) before any work, so a bad path costs no relaxation; returned with its '/' ("" for
// none).
std::string made_out_dir(const std::string& out) {
    if (out.empty()) return "";
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    if (ec || !std::filesystem::is_directory(out))
        throw InputError("--out-dir '" + out + "': cannot create the directory" +
                         (ec ? " (" + ec.message() + ")" : std::string(" (a file of that name exists)")));
    return out + "/";
}

// One `fibernet wet` run (register_wet's callback): the betas in turn; after each, its row, pores and state, and the
// tables and summary rewritten (complete: false) with what an interrupt then reports; at the end the pictures and the
// complete summary. The constructor checks what is left to check (InputError) before anything is written.
class WetSweep {
public:
    WetSweep(WetInputs in, const WetFlags& w, std::chrono::steady_clock::time_point t_all)
        : in_(std::move(in)), w_(w), t_all_(t_all), net_(wet_network(in_.s)), m_(discretize(net_, in_.s.discretization)),
          F_(deformation(in_.s.strain, in_.s.gamma)), start_(start_state()), dir_(made_out_dir(w.out)),
          parameters_(parameters()), wet_settings_(wet_settings_json(in_.s, in_.betas, in_.law_text, in_.opt,
                                                                     start_ ? &*start_ : nullptr)),
          command_(command_line()),
          checkpoints_(dir_, in_.opt.model == WetModel::Smooth ? in_.s.wet.checkpoint_seconds : 0.0, m_, F_,
                       {{"parameters", parameters_}, {"wet", wet_settings_}}, command_argv(),
                       start_ ? &*start_ : nullptr, !w.quiet, [](const std::function<void()>& write) {
                           hold();
                           write();
                           release();
                       }) {
        if (start_) in_.opt.wet_start = start_->q;
        if (checkpoints_.enabled()) {
            in_.opt.observe_wet = [this](const Eigen::VectorXd& q, double e, double g) { checkpoints_.observe(q, e, g); };
            in_.opt.observe_wet_within = [this](const Eigen::VectorXd& q, const std::function<double()>& e) {
                checkpoints_.observe_within(q, e);
            };
        }
        sweep_ << "beta,status,bridges,moves,ruptures,formed,merged,rounds,E_stretch,E_bend,E_capillary,pores,"
                  "mean_pore_area,mean_pore_diameter,bundled_fibers,largest_bundle,G_dry,G_wet,G_dry_fd,G_wet_fd";
        if (in_.opt.free_box.enabled)
            sweep_ << ",free_box,s,areal_shrinkage,free_box_residual,free_box_iterations,G_free_box";
        sweep_ << "\n";
        sweep_.precision(10);
    }
    WetSweep(const WetSweep&) = delete;
    WetSweep& operator=(const WetSweep&) = delete;

    // False when some beta is not a stable equilibrium, its free box did not converge or its moduli failed.
    bool run() {
        // A fresh run: fibernet scan runs this command once per sample in one process, and the last run's final
        // write left the state held (kWriting), where hold() would wait for ever.
        g_state = kRunning, g_pending = false;
        hold();  // before the handler exists: nothing to report until before_beta(0) has run
        // Inside fibernet scan (its JSON captured) the scan's handler stays: an interrupt ends the scan after this
        // sample, not the process in the middle of it.
        std::optional<InterruptScope> interrupts;
        if (!json_capture()) interrupts.emplace();
        before_beta(0);
        release();
        t_betas_ = std::chrono::steady_clock::now();
        for (size_t k = 0; k < in_.betas.size(); ++k) {
            run_beta(k);
            // After the last beta the handler stays held off: the results are complete.
            if (k + 1 < in_.betas.size()) before_beta(k + 1), release();
        }
        finish();
        return ok_;
    }

private:
    // --start-state, checked before any output: one beta only.
    std::optional<StartState> start_state() const {
        if (in_.s.wet.start_state.empty()) return std::nullopt;
        if (in_.betas.size() != 1)
            throw InputError("--start-state '" + in_.s.wet.start_state + "' continues one relaxation: give one beta (" +
                             std::to_string(in_.betas.size()) + " given)");
        return read_start_state(in_.s.wet.start_state, m_, F_);
    }

    // Everything the results depend on (docs/formats.md, "Wet scenes": summary.json), so that a run can be repeated
    // and a rerun told apart from it (bench/run_wet_pores.sh compares them before it skips a seed).
    nlohmann::json parameters() const {
        nlohmann::json p = scene_parameters(in_.s);  // which network the summary describes
        if (!in_.s.network_file.empty()) p["network_file_fnv1a"] = fnv1a_bytes(in_.network_text);
        return p;
    }

    nlohmann::json summary(bool complete) const {
        const Scene& s = in_.s;
        const SolverOptions& elimination = in_.opt.solver_options;  // as run_options set it from the scene
        const int sweep = elimination.elimination.block;
        return nlohmann::json{{"scene", s.source},
                              {"command", command_},
                              {"parameters", parameters_},
                              {"prune", prune_rules(s)},
                              {"network", to_json(statistics(net_))},
                              {"model", to_json(summarize(m_))},
                              {"wet", wet_settings_},
                              {"strain", to_string(s.strain)},
                              {"gamma", s.gamma},
                              {"solver", {{"name", s.solver.name}, {"tol", s.solver.tol}, {"max_iter", s.solver.max_iter},
                                          {"eliminate", elimination.eliminate},
                                          {"schwarz_block", sweep ? nlohmann::json(sweep) : nlohmann::json()},
                                          {"schwarz_overlap", sweep ? nlohmann::json(elimination.elimination.overlap)
                                                                    : nlohmann::json()},
                                          {"eliminate_hops", s.wet.newton_eliminate && s.wet.model == "smooth"
                                                                 ? nlohmann::json(s.wet.eliminate_hops)
                                                                 : nlohmann::json()}}},
                              {"runs", runs_},
                              {"complete", complete},
                              {"seconds", seconds_since(t_all_)}};
    }

    // At the start: the directory's previous results are replaced at once, so an interrupted or failed rerun leaves
    // no stale "complete" summary, rows or pictures (drawn at the end only; until then none of another run).
    void remove_previous() const {
        std::vector<std::string> stale = {"network.svg", "pores.svg"};
        std::error_code ec;
        for (const auto& f : std::filesystem::directory_iterator(dir_, ec)) {
            const std::string n = f.path().filename().string();
            const std::string ext = n.size() > 10 ? n.substr(n.size() - 4) : "";
            if (n.rfind("state_", 0) == 0 && (ext == ".txt" || ext == ".vtp")) stale.push_back(n);
        }
        for (const auto& f : stale) {
            std::filesystem::remove(dir_ + f, ec);
            if (ec) throw InputError("--out-dir '" + w_.out + "': cannot remove the previous " + f + " (" + ec.message() + ")");
        }
        checkpoints_.remove_stale();
    }

    // Before beta k (the handler held off): the files of the betas before it (at k = 0, none), and what an interrupt
    // during beta k prints.
    void before_beta(size_t k) {
        if (!dir_.empty()) {
            if (k == 0) remove_previous();
            // The tables first, the summary last: a summary never lists a beta whose rows are not written yet.
            write_file_atomic(dir_ + "sweep.csv", sweep_.str());
            write_file_atomic(dir_ + "pores.csv", pictures_.pore_csv.str());
            emit_json(summary(false), dir_ + "summary.json");
        }
        nlohmann::json r = summary(false);
        r["interrupted"] = true;
        r["provenance"] = provenance();
        g_report = json_text(r, 2) + "\n";
        g_message = interrupt_message(k);
    }

    std::string interrupt_message(size_t k) const {
        const std::vector<double>& betas = in_.betas;
        std::ostringstream m;
        m << "wet: interrupted during beta = " << betas[k] << " (" << k + 1 << " of " << betas.size() << "); "
          << (k == 0 ? std::string("no beta finished")
                     : std::to_string(k) + " finished beta(s) kept" +
                           (dir_.empty() ? std::string("")
                                         : " in " + w_.out + " (summary.json: complete false, sweep.csv, pores.csv)") +
                           " and reported on stdout")
          << "\n";
        if (checkpoints_.enabled())
            m << "wet: beta " << betas[k] << "'s relaxation continues from its last checkpoint, if one was written (every "
              << in_.s.wet.checkpoint_seconds << " s): --start-state " << dir_ << "checkpoint_" << k
              << ".txt (the command is in checkpoint_" << k << ".json)\n";
        return m.str();
    }

    void progress_before(size_t k) const {
        if (w_.quiet) return;
        const std::vector<double>& betas = in_.betas;
        // ETA: the betas left at the mean time of those done (larger betas usually take longer: a floor).
        char line[160];
        if (k == 0) std::snprintf(line, sizeof line, "wet: beta = %g (1 of %zu)", betas[k], betas.size());
        else
            std::snprintf(line, sizeof line, "wet: beta = %g (%zu of %zu), ETA %.0f s", betas[k], k + 1, betas.size(),
                          seconds_since(t_betas_) / k * (betas.size() - k));
        progress_line(line);
    }

    // Beta k relaxed, then (the handler held off until the caller releases it) its row, pores, run and state.
    void run_beta(size_t k) {
        WetRunOptions& opt = in_.opt;
        const double beta = in_.betas[k];
        opt.params.beta = beta;
        progress_before(k);
        checkpoints_.begin(k, beta);
        const WetRun r = run_wet(net_, m_, F_, opt, k == 0 ? nullptr : &dry_state_);
        // An unconverged relaxation leaves its last state to continue from (never as a result: no state_<k>.txt).
        const std::string left = r.wet.converged || opt.model != WetModel::Smooth
                                     ? std::string()
                                     : checkpoints_.keep_last(r.wet.q, r.smooth.energy, r.smooth.grad_max);
        hold();  // beta k is finished: from here until its files are written, an interrupt waits
        if (!left.empty())
            std::fprintf(stderr, "wet: beta = %g did not converge; its last state is %s%s (continue with "
                         "--start-state)\n", beta, dir_.c_str(), left.c_str());
        if (!w_.quiet) {
            char line[400];
            std::snprintf(line, sizeof line, "wet: beta = %g: %s, %zu bridges, %d solver iterations, %.1f s", beta,
                          r.active.message.c_str(), r.active.bridges.size(), r.active.solver_iterations,
                          r.active.seconds_solve + r.active.seconds_events);
            progress_line(line);
        }
        if (k == 0) dry_state_ = r.dry;
        const char* status = run_status(r);
        const bool good = std::string(status) == "stable";
        ok_ = ok_ && good;
        sweep_row(sweep_, beta, good ? "ok" : status, r, dry_state_, opt.free_box.enabled);
        pictures_.add(r, beta, k + 1 == in_.betas.size(), m_, F_);
        runs_.push_back(run_json(beta, status, r, dry_state_, opt, in_.s.solver.tol));
        // The wet equilibrium itself (model file, docs/formats.md): the fibers' state, exact; its bridges are in the
        // summary's counts and the pictures.
        if (!dir_.empty() && r.wet.converged) {
            runs_.back()["state"] = write_state(dir_, k, beta, m_, F_, r);
            checkpoints_.discard();  // state_<k>.txt supersedes them
        }
        if (!left.empty()) runs_.back()["checkpoint"] = left;
    }

    // "stable", or why not: moduli asked for and not computed (a linear solve that failed) fail the run, as in
    // `fibernet modulus`.
    const char* run_status(const WetRun& r) const {
        const WetRunOptions& opt = in_.opt;
        if (!(r.dry.converged && r.wet.converged && r.active.stable)) return "not_stable";
        if (opt.free_box.enabled && !r.free_box.converged) return "free_box_not_converged";
        if (opt.moduli && !(std::isfinite(dry_state_.shear_modulus) && std::isfinite(r.wet.shear_modulus)))
            return "modulus_failed";
        return "stable";
    }

    // The pictures and the complete summary; the summary on stdout.
    void finish() const {
        const nlohmann::json j = summary(true);
        if (!dir_.empty()) {
            write_file_atomic(dir_ + "sweep.csv", sweep_.str());
            write_file_atomic(dir_ + "pores.csv", pictures_.pore_csv.str());
            write_file_atomic(dir_ + "network.svg", network_svg(m_, pictures_.panels));
            write_file_atomic(dir_ + "pores.svg", histogram_svg(pictures_.hist_names, pictures_.hist_values,
                                                                "pore equivalent diameter (seed units)"));
            emit_json(j, dir_ + "summary.json");
        }
        emit_json(j);
    }

    WetInputs in_;
    const WetFlags& w_;
    const std::chrono::steady_clock::time_point t_all_;
    const Network net_;
    const Model m_;
    const Eigen::Matrix2d F_;
    const std::optional<StartState> start_;
    const std::string dir_;  // --out-dir with its '/', or ""
    const nlohmann::json parameters_, wet_settings_, command_;
    WetCheckpoints checkpoints_;
    nlohmann::json runs_ = nlohmann::json::array();
    std::ostringstream sweep_;
    WetPictures pictures_;
    WetState dry_state_;
    std::chrono::steady_clock::time_point t_betas_;
    bool ok_ = true;
};

}  // namespace

void register_wet(CLI::App& app) {
    auto* cmd = app.add_subcommand("wet", "wet a network: capillary bridges, bundles, pores, moduli dry and wet");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, true, true);  // with [wet]'s flags: --beta, --law, --crossings, --fraction, --wet-seed, ...
    cmd->get_option("--pl")->description("crosslink probability in [0, 1] (default 0.5 here, as the thesis's wet networks)");
    auto w = std::make_shared<WetFlags>();
    // Split by parse_betas, not by CLI11's delimiter, which drops empty entries.
    cmd->add_option("--betas", w->betas, "a beta sweep, comma-separated, e.g. --betas 0,0.1,0.3,1 (overrides --beta)");
    cmd->add_option("-o,--out-dir", w->out,
                    "write summary.json, sweep.csv, pores.csv, network.svg, pores.svg and each beta's wet equilibrium "
                    "state_<k>.txt (a model file) and state_<k>.vtp (ParaView) here (created if missing)");
    cmd->add_flag("--no-moduli", w->no_moduli, "skip the dry and wet shear moduli");
    auto* o_ms = cmd->add_option("--modulus-strain", w->modulus_strain,
                                 "shear strain h of the moduli's second difference of relaxed energies at +-h, "
                                 "reported beside the exact linear moduli (default 1e-4; docs/wet.md)");
    cmd->add_flag("-v,--verbose", w->verbose, "solver progress on stderr (one line per Newton iteration)");
    cmd->add_flag("-q,--quiet", w->quiet, "no progress lines on stderr (default: one per beta and per active-set round)");
    cmd->callback([=] {
        const auto t_all = std::chrono::steady_clock::now();
        WetSweep sweep(read_inputs(*flags, *w, o_ms->count() > 0), *w, t_all);
        if (!sweep.run()) exit_code() = 1;
    });
}

}  // namespace fibernet::cli
