// fibernet generate: make a Mikado network and write it (docs/formats.md, "network").
#include <chrono>
#include <iostream>

#include "common.hpp"
#include "fibernet/network/network_io.hpp"

namespace fibernet::cli {

void register_generate(CLI::App& app) {
    auto* cmd = app.add_subcommand("generate", "generate a Mikado network; writes the network file, stats on stderr");
    auto flags = std::make_shared<SceneFlags>();
    auto out = std::make_shared<std::string>();
    flags->add(cmd, false);
    cmd->add_option("-o,--output", *out, "network file to write (default: standard output)");
    auto quiet = std::make_shared<bool>(false);
    cmd->add_flag("-q,--quiet", *quiet, "no statistics on stderr");
    cmd->callback([flags, out, quiet] {
        Scene s = flags->resolve();
        const auto t0 = std::chrono::steady_clock::now();
        Network net = scene_network(s);
        const double t = seconds_since(t0);
        if (out->empty()) write_network(std::cout, net);
        else save_network(net, *out);
        nlohmann::json j = to_json(statistics(net));
        j["generation_seconds"] = t;
        if (!*quiet) std::cerr << json_text(j) << "\n";
    });
}

}  // namespace fibernet::cli
