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
        WetInputs in = read_inputs(*flags, *w, o_ms->count() > 0);
        Scene& s = in.s;
        const std::vector<double>& betas = in.betas;
        WetRunOptions& opt = in.opt;
        const std::string& law_text = in.law_text;
        const std::string& network_text = in.network_text;

        const Network net = scene_network(s);
        if (s.wet.free_box && !net.periodic)
            throw InputError(s.source + ": the free box needs a periodic network (an open network has no box stress)");
        const Model m = discretize(net, s.discretization);
        const Eigen::Matrix2d F = deformation(s.strain, s.gamma);
        std::optional<StartState> start;  // checked before any output
        if (!s.wet.start_state.empty()) {
            if (betas.size() != 1)
                throw InputError("--start-state '" + s.wet.start_state + "' continues one relaxation: give one beta (" +
                                 std::to_string(betas.size()) + " given)");
            start = read_start_state(s.wet.start_state, m, F);
            opt.wet_start = start->q;
        }
        if (!w->out.empty()) {  // made (like mkdir -p) before any work, so a bad path costs no relaxation
            std::error_code ec;
            std::filesystem::create_directories(w->out, ec);
            if (ec || !std::filesystem::is_directory(w->out))
                throw InputError("--out-dir '" + w->out + "': cannot create the directory" +
                                 (ec ? " (" + ec.message() + ")" : std::string(" (a file of that name exists)")));
        }

        nlohmann::json runs = nlohmann::json::array();
        std::ostringstream sweep;
        WetPictures pictures;
        sweep << "beta,status,bridges,moves,ruptures,formed,merged,rounds,E_stretch,E_bend,E_capillary,pores,mean_pore_area,"
                 "mean_pore_diameter,bundled_fibers,largest_bundle,G_dry,G_wet,G_dry_fd,G_wet_fd";
        if (opt.free_box.enabled) sweep << ",free_box,s,areal_shrinkage,free_box_residual,free_box_iterations,G_free_box";
        sweep << "\n";
        sweep.precision(10);
        bool ok = true;
        WetState dry_state;
        // Everything the results depend on (docs/formats.md, "Wet scenes": summary.json), so that a run can be
        // repeated and a rerun told apart from it (bench/run_wet_pores.sh compares them before it skips a seed).
        nlohmann::json parameters = scene_parameters(s);  // which network the summary describes
        if (!s.network_file.empty()) parameters["network_file_fnv1a"] = fnv1a_bytes(network_text);
        const nlohmann::json wet_settings = wet_settings_json(s, betas, law_text, opt, start ? &*start : nullptr);
        const nlohmann::json command = command_line();
        auto summary = [&](bool complete) {
            return nlohmann::json{{"scene", s.source},
                                {"command", command},
                                {"parameters", parameters},
                                {"prune", prune_rules(s)},
                                {"network", to_json(statistics(net))},
                                {"model", to_json(summarize(m))},
                                {"wet", wet_settings},
                                {"strain", to_string(s.strain)},
                                {"gamma", s.gamma},
                                {"solver", {{"name", s.solver.name}, {"tol", s.solver.tol}, {"max_iter", s.solver.max_iter},
                                            {"eliminate", s.wet.newton_eliminate},
                                            {"eliminate_hops", s.wet.newton_eliminate && s.wet.model == "smooth"
                                                                   ? nlohmann::json(s.wet.eliminate_hops)
                                                                   : nlohmann::json()}}},
                                {"runs", runs},
                                {"complete", complete},
                                {"seconds", seconds_since(t_all)}};
        };
        // The smooth relaxation's checkpoints (wet_checkpoint.hpp), written with the interrupt handler held off.
        WetCheckpoints checkpoints(w->out.empty() ? "" : w->out + "/",
                                   opt.model == WetModel::Smooth ? s.wet.checkpoint_seconds : 0.0, m, F,
                                   {{"parameters", parameters}, {"wet", wet_settings}}, command_argv(),
                                   start ? &*start : nullptr, !w->quiet, [](const std::function<void()>& write) {
                                       hold();
                                       write();
                                       release();
                                   });
        if (checkpoints.enabled())
            opt.observe_wet = [&checkpoints](const Eigen::VectorXd& q, double e, double g) { checkpoints.observe(q, e, g); };
        // Before beta k: the files of the betas before it (at k = 0, none: the directory's previous results are
        // replaced at once, so an interrupted or failed rerun leaves no stale "complete" summary, rows or pictures),
        // and what an interrupt during beta k prints.
        const std::string dir = w->out.empty() ? "" : w->out + "/";
        auto checkpoint = [&](size_t k) {
            if (!dir.empty()) {
                if (k == 0) {  // drawn at the end only; until then no pictures (or states) of another run
                    std::vector<std::string> stale = {"network.svg", "pores.svg"};
                    std::error_code ec;
                    for (const auto& f : std::filesystem::directory_iterator(dir, ec)) {
                        const std::string n = f.path().filename().string();
                        const std::string ext = n.size() > 10 ? n.substr(n.size() - 4) : "";
                        if (n.rfind("state_", 0) == 0 && (ext == ".txt" || ext == ".vtp"))
                            stale.push_back(n);
                    }
                    for (const auto& f : stale) {
                        std::filesystem::remove(dir + f, ec);
                        if (ec) throw InputError("--out-dir '" + w->out + "': cannot remove the previous " + f + " (" +
                                                 ec.message() + ")");
                    }
                    checkpoints.remove_stale();
                }
                // The tables first, the summary last: a summary never lists a beta whose rows are not written yet.
                write_file_atomic(dir + "sweep.csv", sweep.str());
                write_file_atomic(dir + "pores.csv", pictures.pore_csv.str());
                emit_json(summary(false), dir + "summary.json");
            }
            nlohmann::json r = summary(false);
            r["interrupted"] = true;
            r["provenance"] = provenance();
            g_report = json_text(r, 2) + "\n";
            std::ostringstream m;
            m << "wet: interrupted during beta = " << betas[k] << " (" << k + 1 << " of " << betas.size() << "); "
              << (k == 0 ? std::string("no beta finished")
                         : std::to_string(k) + " finished beta(s) kept" +
                               (dir.empty() ? std::string("") : " in " + w->out + " (summary.json: complete false, "
                                                                                   "sweep.csv, pores.csv)") +
                               " and reported on stdout")
              << "\n";
            if (checkpoints.enabled())
                m << "wet: beta " << betas[k] << "'s relaxation continues from its last checkpoint, if one was written (every "
                  << s.wet.checkpoint_seconds << " s): --start-state " << dir << "checkpoint_" << k
                  << ".txt (the command is in checkpoint_" << k << ".json)\n";
            g_message = m.str();
        };
        // A fresh run: fibernet scan runs this command once per sample in one process, and the last run's final
        // write left the state held (kWriting), where hold() would wait for ever.
        g_state = kRunning, g_pending = false;
        hold();  // before the handler exists: nothing to report until checkpoint(0) has run
        // Inside fibernet scan (its JSON captured) the scan's handler stays: an interrupt ends the scan after this
        // sample, not the process in the middle of it.
        std::optional<InterruptScope> interrupts;
        if (!json_capture()) interrupts.emplace();
        checkpoint(0);
        release();
        const auto t_betas = std::chrono::steady_clock::now();
        for (size_t k = 0; k < betas.size(); ++k) {
            opt.params.beta = betas[k];
            if (!w->quiet) {
                // ETA: the betas left at the mean time of those done (larger betas usually take longer: a floor).
                char line[160];
                if (k == 0) std::snprintf(line, sizeof line, "wet: beta = %g (1 of %zu)", betas[k], betas.size());
                else
                    std::snprintf(line, sizeof line, "wet: beta = %g (%zu of %zu), ETA %.0f s", betas[k], k + 1,
                                  betas.size(), seconds_since(t_betas) / k * (betas.size() - k));
                progress_line(line);
            }
            checkpoints.begin(k, betas[k]);
            const WetRun r = run_wet(net, m, F, opt, k == 0 ? nullptr : &dry_state);
            // An unconverged relaxation leaves its last state to continue from (never as a result: no state_<k>.txt).
            const std::string left = r.wet.converged || opt.model != WetModel::Smooth
                                         ? std::string()
                                         : checkpoints.keep_last(r.wet.q, r.smooth.energy, r.smooth.grad_max);
            hold();  // beta k is finished: from here until its files are written, an interrupt waits
            if (!left.empty())
                std::fprintf(stderr, "wet: beta = %g did not converge; its last state is %s%s (continue with "
                             "--start-state)\n", betas[k], dir.c_str(), left.c_str());
            if (!w->quiet) {
                char line[400];
                std::snprintf(line, sizeof line, "wet: beta = %g: %s, %zu bridges, %d solver iterations, %.1f s",
                              betas[k], r.active.message.c_str(), r.active.bridges.size(), r.active.solver_iterations,
                              r.active.seconds_solve + r.active.seconds_events);
                progress_line(line);
            }
            if (k == 0) dry_state = r.dry;
            const bool wet_good = r.dry.converged && r.wet.converged && r.active.stable;
            const bool box_good = !opt.free_box.enabled || r.free_box.converged;
            // Moduli asked for and not computed (a linear solve that failed) fail the run, as in `fibernet modulus`.
            const bool moduli_good =
                !opt.moduli || (std::isfinite(dry_state.shear_modulus) && std::isfinite(r.wet.shear_modulus));
            const bool good = wet_good && box_good && moduli_good;
            const char* bad = !wet_good ? "not_stable" : !box_good ? "free_box_not_converged" : "modulus_failed";
            ok = ok && good;
            sweep_row(sweep, betas[k], good ? "ok" : bad, r, dry_state, opt.free_box.enabled);
            pictures.add(r, betas[k], k + 1 == betas.size(), m, F);
            runs.push_back(run_json(betas[k], good ? "stable" : bad, r, dry_state, opt, s.solver.tol));
            // Finished betas survive an interrupt: the tables and summary.json (complete: false) are rewritten
            // (atomically) after each one; the pictures and stdout come at the end. After the last beta the handler
            // stays held off: the results are complete.
            // The wet equilibrium itself (model file, docs/formats.md): the fibers' state, exact; its bridges are in
            // the summary's counts and the pictures.
            if (!dir.empty() && r.wet.converged) {
                runs.back()["state"] = write_state(dir, k, betas[k], m, F, r);
                checkpoints.discard();  // state_<k>.txt supersedes them
            }
            if (!left.empty()) runs.back()["checkpoint"] = left;
            if (k + 1 < betas.size()) checkpoint(k + 1), release();
        }
        const nlohmann::json j = summary(true);
        if (!dir.empty()) {
            write_file_atomic(dir + "sweep.csv", sweep.str());
            write_file_atomic(dir + "pores.csv", pictures.pore_csv.str());
            write_file_atomic(dir + "network.svg", network_svg(m, pictures.panels));
            write_file_atomic(dir + "pores.svg", histogram_svg(pictures.hist_names, pictures.hist_values, "pore equivalent diameter (seed units)"));
            emit_json(j, dir + "summary.json");
        }
        emit_json(j);
        if (!ok) exit_code() = 1;
    });
}

}  // namespace fibernet::cli
