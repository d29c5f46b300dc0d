// fibernet modulus: equilibrium at the scene's strain, then the linear shear and bulk moduli from one
// factorization (docs/moduli.md), normalised by the affine prediction. Exit 1 (JSON with status, moduli null)
// when the equilibrium or the modulus solve did not converge.
#include <algorithm>
#include <chrono>

#include "common.hpp"
#include "fibernet/mechanics/equilibrium.hpp"
#include "fibernet/mechanics/moduli.hpp"
#include "fibernet/mechanics/stress.hpp"
#include "fibernet/solve/solver.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::cli {

nlohmann::json solve_json(const SolveResult& r, double tol) {
    return {{"name", r.solver},
            {"status", to_string(r.status)},
            {"message", r.message},
            {"iterations", r.iterations},
            {"factorizations", r.factorizations},
            {"evaluations", r.evaluations},
            {"local_solves", r.local_solves},
            {"local_iterations", r.local_iterations},
            {"local_factorizations", r.local_factorizations},
            {"eliminating_iterations", r.eliminating_iterations},
            {"grad_max", r.grad_max},
            {"grad_floor_bound", r.grad_floor},
            {"tol", tol},
            {"seconds",
             {{"assembly", r.timings.assembly},
              {"factorization", r.timings.factorization},
              {"solve", r.timings.solve},
              {"line_search", r.timings.line_search},
              {"total", r.timings.total}}}};
}

nlohmann::json stress_json(const Stress& s) {
    return {{"xx", s.sigma(0, 0)}, {"xy", s.sigma(0, 1)}, {"yx", s.sigma(1, 0)}, {"yy", s.sigma(1, 1)},
            {"area", s.area}};
}

namespace {
nlohmann::json number_or_null(double v, bool ok) { return ok && std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }
bool info_shift_grown(const nlohmann::json& lin) { return lin.is_object() && lin.value("shift_grown", false); }
}  // namespace

void register_modulus(CLI::App& app) {
    auto* cmd = app.add_subcommand("modulus", "equilibrium and linear shear/bulk moduli of a network (JSON)");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, true);
    auto verbose = std::make_shared<bool>(false);
    auto start = std::make_shared<std::string>("affine");
    cmd->add_option("--start", *start, "start of a strained solve: affine (default) | linear (affine + linear response)")
        ->check(CLI::IsMember({"affine", "linear"}));
    cmd->add_flag("-v,--verbose", *verbose, "solver progress on stderr (a line per iteration)");
    auto quiet = std::make_shared<bool>(false);
    cmd->add_flag("-q,--quiet", *quiet, "no progress lines on stderr");
    cmd->callback([flags, verbose, quiet, start] {
        if (*verbose && *quiet) throw InputError("--verbose and --quiet contradict each other");
        const auto t_all = std::chrono::steady_clock::now();
        Scene s = flags->resolve();
        SolverOptions so = dry_solver_options(s);
        so.verbose = *verbose;
        auto solver = make_solver(s.solver.name, so);  // unknown name: InputError before any work

        auto t0 = std::chrono::steady_clock::now();
        Network net = scene_network(s);
        const double t_net = seconds_since(t0);
        t0 = std::chrono::steady_clock::now();
        Model m = discretize(net, s.discretization);
        NetworkEnergy e(m);
        const double t_model = seconds_since(t0);

        const Eigen::Matrix2d F = deformation(s.strain, s.gamma);
        const Progress progress("modulus", !*quiet);
        progress.start(net, e, s);
        Equilibrium eq = relax(e, F, *solver, nullptr, Eigen::Matrix2d::Identity(), *start == "linear");
        const bool conv = eq.converged();
        progress.solved(eq.result);

        nlohmann::json moduli = nullptr, stress_j = nullptr, lin = nullptr;
        bool ok = conv;
        if (conv) {
            const Stress st = stress(e, eq.q, F);
            stress_j = stress_json(st);
            std::vector<StrainMode> modes = {shear_mode(F, st.area), bulk_mode(F, st.area)};
            if (s.strain != StrainKind::Shear) modes.push_back(path_mode(s.strain, st.area));
            ModuliInfo info;
            ModuliOptions mo;
            // What the solver accepted (tol, or Newton's round-off floor, measured on the Hessian it used).
            mo.equilibrium_tol = std::max({mo.equilibrium_tol, s.solver.tol, eq.result.grad_max});
            // The solver's factorization, already analyzed for this pattern, if it shares one (else null: its own).
            LinearSolver* shared = solver->factorization_for(e.hessian_pattern());
            const auto mods = linear_moduli(e, eq.q, F, modes, mo, &info, shared);
            moduli = nlohmann::json::object();
            for (const auto& M : mods) {
                ok = ok && M.ok;
                moduli[M.name] = number_or_null(M.value, M.ok);
                moduli[M.name + "_affine"] = M.affine;
                moduli[M.name + "_ratio"] = number_or_null(M.affine != 0 ? M.value / M.affine : NAN, M.ok);
                moduli[M.name + "_error"] = number_or_null(M.error, M.ok);
                moduli[M.name + "_state_error"] = number_or_null(M.state_error, M.ok && info.state_checked);
                moduli[M.name + "_refinements"] = M.refinements;
            }
            lin = {{"shift", info.delta},
                   {"shift_grown", info.shift_grown},
                   {"factorizations", info.factorizations},
                   {"message", info.message},
                   {"state_checked", info.state_checked},
                   {"state_step", info.state_step},
                   {"seconds",
                    {{"assembly", info.seconds_assembly},
                     {"factorization", info.seconds_factorization},
                     {"one_factorization", info.seconds_one_factorization},
                     {"solve", info.seconds_solve},
                     {"affine", info.seconds_affine},
                     {"state", info.seconds_state},
                     {"total", info.seconds_total}}}};
        }
        emit_json({{"scene", s.source},
                   {"status", ok ? "converged" : (conv ? "modulus_failed" : to_string(eq.result.status))},
                   {"strain", to_string(s.strain)},
                   {"gamma", s.gamma},
                   {"units", "seed units: length ls = lf/10, energy = bending energy of unit length at unit curvature; "
                             "moduli and stress in energy per area"},
                   {"moduli", moduli},
                   {"stress", stress_j},
                   {"energy", {{"total", eq.energy}, {"stretch", eq.stretch}, {"bend", eq.bend}}},
                   {"network", to_json(statistics(net))},
                   {"model", to_json(summarize(m))},
                   {"prune", prune_rules(s)},
                   {"scheme", to_string(s.discretization.scheme)},
                   {"solver", solve_json(eq.result, s.solver.tol)},
                   {"start", eq.start},
                   {"linear_solve", lin},
                   {"seconds",
                    {{"network", t_net}, {"model", t_model}, {"equilibrium", eq.result.timings.total},
                     {"total", seconds_since(t_all)}}}});
        progress.line(ok ? "done" : conv ? "the linear moduli failed (status modulus_failed)" : "not converged", t_all);
        // A hint even with -q (the run failed), only for the CG's round-off stop (not a saddle or an unstable state).
        const std::string why = lin.is_null() ? std::string() : lin["message"].get<std::string>();
        if (conv && !ok && s.discretization.scheme == Scheme::Seed && why.find("conjugate gradients") != std::string::npos)
            std::fprintf(stderr, "modulus: %s; the seed scheme's very short segments (shortest %.2g seed units here) make "
                                 "H ill-conditioned on large networks: --scheme even avoids them (docs/moduli.md)\n",
                         why.c_str(), summarize(m).shortest_segment);
        // Accepted moduli of an H that needed a larger shift to factor: say that their errors may be understated.
        if (ok && info_shift_grown(lin) && s.discretization.scheme == Scheme::Seed)
            std::fprintf(stderr, "modulus: warning: H + delta I factored only at a shift grown to %.2g; the seed scheme's "
                                 "very short segments (shortest %.2g seed units here) leave H ill-conditioned at round-off, "
                                 "and the errors may be understated: --scheme even avoids them (docs/moduli.md)\n",
                         lin["shift"].get<double>(), summarize(m).shortest_segment);
        if (!ok) exit_code() = 1;
    });
}

}  // namespace fibernet::cli
