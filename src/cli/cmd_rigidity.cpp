// fibernet rigidity: pebble-game rigidity of an open network (DESIGN.md §2, issue 4) as JSON: floppy modes,
// independent and redundant constraints, rigid clusters; with clamps (the default) also d, the top clamp's
// degrees of freedom with the bottom clamp grounded, rigid and connectivity spanning. --svg draws the
// (clamped) network coloured by rigid cluster.
#include <chrono>

#include "common.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/network/clamp.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/cluster_svg.hpp"
#include "fibernet/rigidity/rigidity.hpp"

namespace fibernet::cli {

namespace {
nlohmann::json counts(const RigidityResult& r) {
    nlohmann::json j = {{"bodies", r.bodies},
                        {"pins", r.pins},
                        {"bars", r.bars},
                        {"independent", r.independent},
                        {"redundant", r.redundant},
                        {"floppy_modes", r.floppy_modes},
                        {"rigid_clusters", r.clusters},
                        {"largest_rigid_cluster", r.largest_cluster}};
    if (r.clamped) {
        j["d"] = r.d;
        j["rigid_spanning"] = r.rigid_spanning;
        j["carries_shear"] = r.carries_shear;
        j["connected_spanning"] = r.connected_spanning;
        j["floppy_modes_bottom_grounded"] = r.floppy_grounded;
        j["floppy_modes_both_clamps_held"] = r.floppy_both_grounded;
    }
    return j;
}
}  // namespace

void register_rigidity(CLI::App& app) {
    auto* cmd = app.add_subcommand("rigidity", "pebble-game rigidity of an open network: floppy modes, rigid clusters, "
                                               "clamp degrees of freedom d and spanning (JSON)");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, false);
    cmd->add_flag("-q,--quiet", "accepted by every command; this one prints nothing on stderr but errors");
    auto svg = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    auto no_clamps = std::make_shared<bool>(false);
    auto clusters = std::make_shared<bool>(false);
    cmd->add_option("--svg", *svg, "write an SVG of the network coloured by rigid cluster to this file");
    cmd->add_option("--out", *out, "write the JSON to this file instead of stdout");
    cmd->add_flag("--no-clamps", *no_clamps, "analyse the open network only (no clamps, no d)");
    cmd->add_flag("--clusters", *clusters, "also list the rigid cluster of every fiber");
    cmd->callback([=] {
        Scene s = flags->resolve();
        refuse_trimmed_ends(s, "rigidity", "the pebble game treats whole fibers as rigid rods");
        check_outputs({{"--svg", *svg}, {"--out", *out}});
        auto t0 = std::chrono::steady_clock::now();
        const Network net = scene_network(s);
        const double t_net = seconds_since(t0);
        refuse_periodic(s, net, "rigidity counts open boxes with clamps");
        t0 = std::chrono::steady_clock::now();
        const RigidityResult open = analyze_rigidity(body_pin_framework(net));
        const double t_open = seconds_since(t0);
        nlohmann::json j = {{"scene", s.source}, {"network", to_json(statistics(net))}, {"open", counts(open)}};
        j["open"]["note"] = "floppy_modes counts every zero mode of the rigid-fiber framework, the 3 rigid motions of "
                            "each connected piece included";
        if (*clusters) j["open"]["cluster_of_fiber"] = open.cluster;
        j["seconds"] = {{"network", t_net}, {"pebble_game_open", t_open}};
        RigidityResult clamped;
        ClampedNetwork cl;
        if (!*no_clamps) {
            t0 = std::chrono::steady_clock::now();
            cl = clamp_network(net);
            clamped = analyze_rigidity(body_pin_framework(cl));
            j["seconds"]["pebble_game_clamped"] = seconds_since(t0);
            j["clamped"] = counts(clamped);
            j["clamped"]["fibers_inside"] = clamped.fibers;
            j["clamped"]["clamp_pins"] = static_cast<int>(cl.pins.size());
            if (*clusters) {
                std::vector<int> of_fiber(net.fibers.size(), -1);  // -1: fiber lies outside the clamped strip
                for (size_t i = 0; i < cl.original_fiber.size(); ++i) of_fiber[cl.original_fiber[i]] = clamped.cluster[i];
                j["clamped"]["cluster_of_fiber"] = of_fiber;
            }
        }
        if (!svg->empty())
            write_file_atomic(*svg, *no_clamps ? rigid_cluster_svg(net, open) : rigid_cluster_svg(cl.net, clamped));
        emit_json(j, *out);
    });
}

}  // namespace fibernet::cli
