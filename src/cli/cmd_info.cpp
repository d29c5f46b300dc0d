// fibernet info: network statistics and model summary as JSON, with the time each stage took.
#include <chrono>

#include "common.hpp"

namespace fibernet::cli {

void register_info(CLI::App& app) {
    auto* cmd = app.add_subcommand("info", "print network statistics and the model summary (JSON)");
    auto flags = std::make_shared<SceneFlags>();
    flags->add(cmd, false);
    cmd->add_flag("-q,--quiet", "accepted by every command; this one prints nothing on stderr but errors");
    cmd->callback([flags] {
        Scene s = flags->resolve();
        auto t0 = std::chrono::steady_clock::now();
        Network net = scene_network(s);
        const double tn = seconds_since(t0);
        t0 = std::chrono::steady_clock::now();
        Model m = discretize(net, s.discretization);
        const double tm = seconds_since(t0);
        emit_json({{"scene", s.source},
                   {"network", to_json(statistics(net))},
                   {"model", to_json(summarize(m))},
                   {"scheme", to_string(s.discretization.scheme)},
                   {"seconds", {{"network", tn}, {"discretize", tm}}}});
    });
}

}  // namespace fibernet::cli
