// fibernet compare: the exact per-network check of pebble-game rigidity against the elastic model (issue 4
// part 3, DESIGN.md §2) on one network or on --samples consecutive seeds: floppy modes == Hessian nullity on the
// open network, G > g-cut exactly when d < 3 with clamps, clamped nullity == floppy modes with both clamps held.
// Dense eigen-decompositions: for small networks. Exit code 1 if any network disagrees.
#include <chrono>
#include <cmath>
#include <cstdio>

#include "common.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/rigidity/compare.hpp"

namespace fibernet::cli {

namespace {
nlohmann::json row(std::uint64_t seed, const RigidityComparison& c) {
    return {{"seed", seed},
            {"fibers", c.fibers},
            {"crosslinks", c.crosslinks},
            {"dofs", c.dofs},
            {"floppy_modes", c.floppy_modes},
            {"hessian_nullity", c.nullity},
            {"largest_zero_eigenvalue", c.largest_zero},
            {"smallest_nonzero_eigenvalue", c.smallest_nonzero},
            {"d", c.d},
            {"clamped_shear_modulus", c.G},
            {"floppy_modes_both_clamps_held", c.floppy_both_grounded},
            {"clamped_hessian_nullity", c.clamped_nullity},
            {"agrees", c.agrees()}};
}
}  // namespace

void register_compare(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "compare", "check pebble-game rigidity against the elastic Hessian, network by network (JSON)");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, false);
    auto samples = std::make_shared<int>(1);
    auto zero_cut = std::make_shared<double>(kZeroEigenvalueCut);
    auto g_cut = std::make_shared<double>(kShearModulusCut);
    auto out = std::make_shared<std::string>();
    auto max_dofs = std::make_shared<int>(3000);
    cmd->add_option("--samples", *samples, "networks to check: seeds seed, seed+1, ... (default 1)");
    cmd->add_option("--zero-cut", *zero_cut, "eigenvalues of the Jacobi-scaled Hessian <= this are zero (default 1e-12)");
    cmd->add_option("--g-cut", *g_cut, "clamped shear moduli > this are nonzero (default 7e-7)");
    cmd->add_option("--max-dofs", *max_dofs, "refuse networks with more coordinates than this (dense, default 3000)");
    cmd->add_option("--out", *out, "write the JSON to this file instead of stdout");
    auto quiet = std::make_shared<bool>(false);
    cmd->add_flag("-q,--quiet", *quiet, "no progress lines on stderr (default: one per network)");
    cmd->footer("Without a scene file the discretization defaults to the tested one: --scheme even --h 10 --a 3.");
    cmd->callback([=] {
        Scene s = flags->resolve();
        refuse_trimmed_ends(s, "compare", "the comparison needs the whole fibers of the pebble game");
        if (flags->scene_file.empty()) {
            if (!flags->given("--scheme")) s.discretization.scheme = Scheme::Even;
            if (!flags->given("--h")) s.discretization.h = 10;
            if (!flags->given("--a")) s.discretization.aspect_ratio = 3;
        }
        check_value(*samples >= 1 && *samples <= 1000000, *samples, "command line", "--samples", "must be in [1, 1e6]");
        check_value(*zero_cut > 0, *zero_cut, "command line", "--zero-cut", "must be > 0");
        check_value(*g_cut > 0, *g_cut, "command line", "--g-cut", "must be > 0");
        if (!s.network_file.empty() && *samples != 1)
            throw InputError("command line: --samples " + std::to_string(*samples) + " needs a generated network, not --network");
        check_outputs({{"--out", *out}});
        const auto t0 = std::chrono::steady_clock::now();
        int agree = 0;
        double max_zero = 0, min_nonzero = 0, max_G_free = 0, min_G_rigid = 0;
        bool any_rigid = false;
        nlohmann::json rows = nlohmann::json::array(), bad = nlohmann::json::array();
        for (int i = 0; i < *samples; ++i) {
            Scene si = s;
            si.mikado.seed = s.mikado.seed + static_cast<std::uint64_t>(i);
            const Network net = scene_network(si);
            refuse_periodic(s, net, "the comparison needs an open box");
            const long coords = static_cast<long>(discretize(net, si.discretization).x.size());
            if (coords > *max_dofs)
                throw InputError(s.source + ": the model has " + std::to_string(coords) + " coordinates, more than --max-dofs " +
                                 std::to_string(*max_dofs) + " for dense eigen-decompositions (use a smaller L or a larger --h)");
            const auto t_sample = std::chrono::steady_clock::now();
            const RigidityComparison c = compare_rigidity(net, si.discretization, *zero_cut, *g_cut);
            if (!*quiet)
                std::fprintf(stderr,
                             "compare: network %d of %d (seed %llu): %d fibers, %ld coordinates, %ld floppy modes, "
                             "Hessian nullity %ld, d = %d, G = %.3g: %s, %.2f s\n",
                             i + 1, *samples, static_cast<unsigned long long>(si.mikado.seed), c.fibers, coords,
                             c.floppy_modes, c.nullity, c.d, c.G, c.agrees() ? "agrees" : "DISAGREES",
                             seconds_since(t_sample));
            agree += c.agrees();
            max_zero = std::max({max_zero, c.largest_zero, c.clamped_largest_zero});
            for (double v : {c.smallest_nonzero, c.clamped_smallest_nonzero})
                if (v > 0) min_nonzero = min_nonzero == 0 ? v : std::min(min_nonzero, v);
            if (c.d < 3) min_G_rigid = any_rigid ? std::min(min_G_rigid, c.G) : c.G, any_rigid = true;
            else max_G_free = std::max(max_G_free, std::abs(c.G));
            auto r = row(si.mikado.seed, c);
            if (!c.agrees()) bad.push_back(r);
            if (*samples <= 20) rows.push_back(r);
        }
        nlohmann::json j = {{"scene", s.source},
                            {"networks", *samples},
                            {"agree", agree},
                            {"agreement_rate", static_cast<double>(agree) / *samples},
                            {"cuts", {{"zero_eigenvalue", *zero_cut}, {"shear_modulus", *g_cut}}},
                            {"gaps",
                             {{"largest_zero_eigenvalue", max_zero},
                              {"smallest_nonzero_eigenvalue", min_nonzero},
                              {"largest_abs_G_with_d_3", max_G_free},
                              // null when no network had d < 3
                              {"smallest_G_with_d_below_3", any_rigid ? nlohmann::json(min_G_rigid) : nlohmann::json()}}},
                            {"disagreements", bad},
                            {"seconds", seconds_since(t0)}};
        if (*samples <= 20) j["rows"] = rows;
        emit_json(j, *out);
        if (agree != *samples) exit_code() = 1;
    });
}

}  // namespace fibernet::cli
