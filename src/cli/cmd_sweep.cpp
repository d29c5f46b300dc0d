// fibernet sweep: quasistatic strain sweep with an adaptive step (include/fibernet/mechanics/sweep.hpp).
// One CSV row per accepted step, flushed at once, and a checkpoint after every step: Ctrl-C (SIGINT/SIGTERM)
// stops after the step in progress, and --resume continues with results identical to an uninterrupted run.
#include <atomic>
#include <csignal>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "common.hpp"
#include "fibernet/mechanics/sweep.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::cli {

namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

const char* kHeader =
    "step,gamma,sigma_xx,sigma_xy,sigma_yy,stress_path,K,K_affine,energy,stretch,bend,iterations,factorizations,"
    "retries,grad_max,seconds";

std::string csv_row(const SweepRow& r) {
    std::ostringstream os;
    os << std::setprecision(17) << r.step << ',' << r.t << ',' << r.sigma(0, 0) << ',' << r.sigma(0, 1) << ','
       << r.sigma(1, 1) << ',' << r.stress_path << ',' << r.K << ',' << r.K_affine << ',' << r.energy << ','
       << r.stretch << ',' << r.bend << ',' << r.iterations << ',' << r.factorizations << ',' << r.retries << ','
       << r.grad_max << ',' << std::setprecision(4) << r.seconds;
    return os.str();
}

void write_checkpoint(const std::string& path, const SweepParams& p, int rows, const SweepState& s) {
    std::ostringstream os;
    os << std::setprecision(17) << "fibernet-sweep-checkpoint 1\nkind " << to_string(p.kind) << "\nt_max " << p.t_max
       << "\ndofs " << s.q.size() << "\nrows " << rows << "\nstep " << s.step << "\nt " << s.t << "\nnext_step "
       << s.next_step << "\nq\n";
    for (int i = 0; i < s.q.size(); ++i) os << s.q[i] << '\n';
    write_file_atomic(path, os.str());
}

SweepState read_checkpoint(const std::string& path, const SweepParams& p, int dofs, int& rows) {
    std::ifstream is(path);
    if (!is) throw InputError("--resume: checkpoint '" + path + "' cannot be opened");
    auto fail = [&](const std::string& m) -> void { throw InputError(path + ": " + m); };
    std::string key, kind;
    int version = 0, n = 0;
    double t_max = 0;
    SweepState s;
    if (!(is >> key >> version) || key != "fibernet-sweep-checkpoint" || version != 1) fail("not a sweep checkpoint");
    if (!(is >> key >> kind) || key != "kind") fail("missing kind");
    if (kind != to_string(p.kind)) fail("strain kind '" + kind + "' differs from this run's '" + to_string(p.kind) + "'");
    if (!(is >> key >> t_max) || key != "t_max") fail("missing t_max");
    if (t_max != p.t_max) fail("gamma_max = " + show(t_max) + " differs from this run's " + show(p.t_max));
    if (!(is >> key >> n) || key != "dofs") fail("missing dofs");
    if (n != dofs) fail("dofs = " + std::to_string(n) + " differs from this model's " + std::to_string(dofs));
    if (!(is >> key >> rows) || key != "rows") fail("missing rows");
    if (!(is >> key >> s.step) || key != "step") fail("missing step");
    if (!(is >> key >> s.t) || key != "t") fail("missing t");
    if (!(is >> key >> s.next_step) || key != "next_step") fail("missing next_step");
    if (!(is >> key) || key != "q") fail("missing q");
    s.q.resize(n);
    for (int i = 0; i < n; ++i)
        if (!(is >> s.q[i]) || !std::isfinite(s.q[i])) fail("q[" + std::to_string(i) + "] is missing or not finite");
    return s;
}

// Keeps the header and the first `rows` data rows (a row written after the last checkpoint is dropped).
void truncate_csv(const std::string& path, int rows) {
    std::ifstream is(path);
    if (!is) throw InputError("--resume: output '" + path + "' cannot be opened");
    std::string line, kept;
    int n = -1;
    while (n < rows && std::getline(is, line)) kept += line + "\n", ++n;
    if (n < rows) throw InputError("--resume: '" + path + "' has fewer rows than its checkpoint says");
    write_file_atomic(path, kept);
}
}  // namespace

void register_sweep(CLI::App& app) {
    auto* cmd = app.add_subcommand("sweep", "quasistatic strain sweep: CSV row per step, checkpoint, --resume");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, true);
    auto p = std::make_shared<SweepParams>();
    auto out = std::make_shared<std::string>();
    auto ckpt = std::make_shared<std::string>();
    auto resume = std::make_shared<bool>(false);
    auto quiet = std::make_shared<bool>(false);
    cmd->add_option("--gamma-max", p->t_max, "final strain (negative: compression)")->required();
    cmd->add_option("--step", p->step, "first step (default 0.01)");
    cmd->add_option("--min-step", p->min_step, "smallest step before giving up (default 1e-6)");
    cmd->add_option("--max-step", p->max_step, "largest step (default 0.05)");
    cmd->add_option("-o,--output", *out, "CSV file, one row per accepted step")->required();
    cmd->add_option("--checkpoint", *ckpt, "checkpoint file (default OUTPUT.ckpt)");
    cmd->add_flag("--resume", *resume, "continue an interrupted sweep from its checkpoint");
    cmd->add_flag("-q,--quiet", *quiet, "no progress lines on stderr");
    cmd->callback([=] {
        Scene s = flags->resolve();
        if (flags->given("--gamma")) throw InputError("command line: sweep takes --gamma-max, not --gamma");
        p->kind = s.strain;
        p->check("command line");
        if (ckpt->empty()) *ckpt = *out + ".ckpt";
        SolverOptions so;
        so.tol = s.solver.tol, so.max_iter = s.solver.max_iter;
        auto solver = make_solver(s.solver.name, so);
        SolverOptions so_snap = so;  // the snap-through budget at the smallest step (docs/sweep.md)
        so_snap.max_iter = 10 * so.max_iter;
        auto snap = make_solver(s.solver.name, so_snap);
        Network net = scene_network(s);
        Model m = discretize(net, s.discretization);
        NetworkEnergy e(m);

        int rows = 0;
        SweepState start;
        if (*resume) {
            start = read_checkpoint(*ckpt, *p, e.num_dofs(), rows);
            truncate_csv(*out, rows);
            std::cerr << "sweep: resuming at step " << start.step << ", gamma = " << start.t << "\n";
        } else {
            write_file_atomic(*out, std::string(kHeader) + "\n");
        }
        std::ofstream csv(*out, std::ios::app);
        if (!csv) throw InputError("cannot append to '" + *out + "'");
        SweepCallbacks cb;
        cb.stop = &g_stop;
        cb.on_step = [&](const SweepRow& r, const SweepState& st) {
            csv << csv_row(r) << '\n' << std::flush;
            write_checkpoint(*ckpt, *p, ++rows, st);
            if (!*quiet)
                std::cerr << "sweep: step " << r.step << "  gamma = " << r.t << "  s = " << r.stress_path
                          << "  K = " << r.K << "  iterations = " << r.iterations << "  retries = " << r.retries
                          << "  " << r.seconds << " s\n";
        };
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        const SweepOutcome o = run_sweep(e, *p, *solver, cb, *resume ? &start : nullptr, snap.get());
        std::signal(SIGINT, SIG_DFL);
        std::signal(SIGTERM, SIG_DFL);
        emit_json({{"status", o.completed ? "completed" : o.interrupted ? "interrupted" : "failed"},
                   {"message", o.message},
                   {"rows", rows},
                   {"output", *out},
                   {"checkpoint", *ckpt},
                   {"model", to_json(summarize(m))}});
        if (o.interrupted) exit_code() = 130;
        else if (!o.completed) exit_code() = 1;
    });
}

}  // namespace fibernet::cli
