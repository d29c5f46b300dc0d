// fibernet relax: the equilibrium at the scene's strain, written in the model export format (-o), and its
// stress as JSON. Exit 1 (no model file, stress null) when the solver did not converge.
#include <chrono>
#include <sstream>

#include "common.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/mechanics/stress.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::cli {

nlohmann::json solve_json(const SolveResult& r, double tol);  // cmd_modulus.cpp
nlohmann::json stress_json(const Stress& s);

void register_relax(CLI::App& app) {
    auto* cmd = app.add_subcommand("relax", "equilibrium at the scene's strain: model file (-o) and stress (JSON)");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, true);
    auto out = std::make_shared<std::string>();
    auto verbose = std::make_shared<bool>(false);
    auto start = std::make_shared<std::string>("affine");
    cmd->add_option("--start", *start, "start of a strained solve: affine (default) | linear (affine + linear response)")
        ->check(CLI::IsMember({"affine", "linear"}));
    cmd->add_option("-o,--output", *out, "write the equilibrium model here (export format, docs/formats.md)");
    cmd->add_flag("-v,--verbose", *verbose, "solver progress on stderr (a line per iteration)");
    auto quiet = std::make_shared<bool>(false);
    cmd->add_flag("-q,--quiet", *quiet, "no progress lines on stderr");
    cmd->callback([flags, out, verbose, quiet, start] {
        const auto t_all = std::chrono::steady_clock::now();
        if (*verbose && *quiet) throw InputError("--verbose and --quiet contradict each other");
        Scene s = flags->resolve();
        check_outputs({{"--output", *out}});  // before the solve, not after it
        SolverOptions so = dry_solver_options(s);
        so.verbose = *verbose;
        auto solver = make_solver(s.solver.name, so);
        Network net = scene_network(s);
        Model m = discretize(net, s.discretization);
        NetworkEnergy e(m);
        const Eigen::Matrix2d F = deformation(s.strain, s.gamma);
        const Progress progress("relax", !*quiet);
        progress.start(net, e, s);
        Equilibrium eq = relax(e, F, *solver, nullptr, Eigen::Matrix2d::Identity(), *start == "linear");
        progress.solved(eq.result);
        nlohmann::json st = nullptr;
        if (eq.converged()) {
            st = stress_json(stress(e, eq.q, F));
            if (!out->empty()) {
                std::ostringstream os;
                write_model(os, m, e.displacements(eq.q, F), F);
                write_file_atomic(*out, os.str());
            }
        } else {
            exit_code() = 1;
        }
        emit_json({{"scene", s.source},
                   {"status", to_string(eq.result.status)},
                   {"strain", to_string(s.strain)},
                   {"gamma", s.gamma},
                   {"stress", st},
                   {"energy", {{"total", eq.energy}, {"stretch", eq.stretch}, {"bend", eq.bend}}},
                   {"model", to_json(summarize(m))},
                   {"prune", prune_rules(s)},
                   {"solver", solve_json(eq.result, s.solver.tol)},
                   {"start", eq.start},
                   {"output", eq.converged() && !out->empty() ? nlohmann::json(*out) : nlohmann::json()}});
        progress.line(eq.converged() ? "done" : "not converged", t_all);
    });
}

}  // namespace fibernet::cli
