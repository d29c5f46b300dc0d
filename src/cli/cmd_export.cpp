// fibernet export: discretize a network and write the model (docs/formats.md, "model").
#include <iostream>
#include <sstream>

#include "common.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/network_io.hpp"

namespace fibernet::cli {

void register_export(CLI::App& app) {
    auto* cmd = app.add_subcommand("export", "write the discretized model (nodes, segments, hinges, supernodes)");
    auto flags = std::make_shared<SceneFlags>();
    auto out = std::make_shared<std::string>();
    flags->add(cmd, false);
    cmd->add_option("-o,--output", *out, "model file to write (default: standard output)");
    auto quiet = std::make_shared<bool>(false);
    cmd->add_flag("-q,--quiet", *quiet, "no statistics on stderr");
    cmd->callback([flags, out, quiet] {
        Scene s = flags->resolve();
        Network net = scene_network(s);
        Model m = discretize(net, s.discretization);
        std::ostringstream os;
        write_model(os, m);
        if (out->empty()) std::cout << os.str();
        else write_file_atomic(*out, os.str());
        if (!*quiet) std::cerr << json_text(to_json(summarize(m))) << "\n";
    });
}

}  // namespace fibernet::cli
