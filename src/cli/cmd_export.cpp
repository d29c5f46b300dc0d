// fibernet export: a model (a scene's, at rest, or a state read with --model) as a fibernet model file, a LAMMPS data
// file with its input script, or VTK PolyData for ParaView (docs/formats.md).
#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common.hpp"
#include "fibernet/export/lammps.hpp"
#include "fibernet/export/vtp.hpp"
#include "fibernet/model/model_io.hpp"
#include "fibernet/network/network_io.hpp"
#include "fibernet/rigidity/body_pin.hpp"
#include "fibernet/rigidity/rigidity.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet_version.hpp"

namespace fibernet::cli {

namespace {

struct ExportArgs {
    std::string out, format = "model", model_file;
    bool quiet = false;
};

// What is exported: the model, its state (displacements) and deformation, and per-fiber fields where the network
// is known (rigid clusters by the pebble game, in an open box).
struct ExportState {
    Model model;
    Eigen::VectorXd u;
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    VtpFields fields;
    std::string source;
};

ExportState from_scene(const SceneFlags& flags, bool with_clusters) {
    Scene s = flags.resolve();
    Network net = scene_network(s);
    ExportState st{discretize(net, s.discretization), {}, Eigen::Matrix2d::Identity(), {}, s.source};
    st.u = Eigen::VectorXd::Zero(st.model.x.size());
    if (with_clusters && !net.periodic) {  // the pebble game counts open boxes (docs/rigidity.md)
        const RigidityResult r = analyze_rigidity(body_pin_framework(net));
        if (r.cluster.size() == net.fibers.size()) st.fields.per_fiber.push_back({"rigid_cluster", r.cluster});
    }
    return st;
}

ExportState from_model_file(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError("--model " + path + ": cannot be read");
    ExportState st;
    st.model = read_model(in, path, &st.u, &st.F);
    st.source = path;
    return st;
}

void write_lammps_files(const ExportState& st, const std::string& base, bool quiet) {
    std::ostringstream data, input;
    const std::string data_path = base + ".data";
    const std::string data_name = data_path.substr(data_path.find_last_of('/') + 1);  // beside the script
    const LammpsExport info = write_lammps(data, input, st.model, st.u, st.F, data_name,
                                           "fibernet " + std::string(FIBERNET_VERSION) + " (" + FIBERNET_GIT_COMMIT + ") export of " + st.source);
    write_file_atomic(data_path, data.str());
    write_file_atomic(base + ".in", input.str());
    if (info.softcore_segments)
        std::cerr << "export: warning: " << info.softcore_segments
                  << " segments are in the softcore branch (eps < -0.95), which LAMMPS' harmonic bonds do not have\n";
    if (!quiet)
        std::cerr << "export: " << data_path << " and " << base << ".in (" << info.bond_types << " bond types, "
                  << info.angle_types << " angle types); run it from their directory (the script reads " << data_name
                  << "): lmp -in " << base.substr(base.find_last_of('/') + 1) << ".in\n";
}

void run_export(const SceneFlags& flags, const ExportArgs& a) {
    const bool scene_given = !flags.scene_file.empty() || std::any_of(flags.opts.begin(), flags.opts.end(),
                                                                    [](CLI::Option* o) { return o->count() > 0; });
    if (!a.model_file.empty() && scene_given)
        throw InputError("--model " + a.model_file + " is a state of its own: give it without a scene or scene flags");
    if (a.format == "lammps" && a.out.empty())
        throw InputError("--format lammps writes two files: give -o BASE (BASE.data and BASE.in)");
    if (a.format == "lammps") check_outputs({{"-o (data)", a.out + ".data"}, {"-o (input)", a.out + ".in"}});
    else check_outputs({{"--output", a.out}});
    const ExportState st = a.model_file.empty() ? from_scene(flags, a.format == "vtp") : from_model_file(a.model_file);
    std::ostringstream os;
    try {  // a state the format cannot hold: named with the file it came from
        if (a.format == "lammps") {
            write_lammps_files(st, a.out, a.quiet);
            return;
        }
        if (a.format == "vtp") {
            const NetworkEnergy e(st.model);
            write_vtp(os, e, e.dofs_of_displacements(st.u), st.F, st.fields);
        } else {
            write_model(os, st.model, st.u, st.F);
        }
    } catch (const InputError& e) {
        throw InputError((a.model_file.empty() ? st.source : "--model " + a.model_file) + ": " + e.what());
    }
    if (a.out.empty()) std::cout << os.str();
    else write_file_atomic(a.out, os.str());
    if (!a.quiet) std::cerr << json_text(to_json(summarize(st.model))) << "\n";
}

}  // namespace

void register_export(CLI::App& app) {
    auto* cmd = app.add_subcommand("export",
                                   "write the discretized model: fibernet model file, LAMMPS data + input, or VTK .vtp");
    auto flags = std::make_shared<SceneFlags>();
    auto args = std::make_shared<ExportArgs>();
    flags->add(cmd, false);
    cmd->add_option("--model", args->model_file,
                    "export this model file's state (e.g. from fibernet relax -o) instead of a scene at rest");
    cmd->add_option("--format", args->format, "model (default) | lammps (-o BASE: BASE.data, BASE.in) | vtp (ParaView)")
        ->check(CLI::IsMember({"model", "lammps", "vtp"}));
    cmd->add_option("-o,--output", args->out, "file to write (default: standard output; lammps: the base name)");
    cmd->add_flag("-q,--quiet", args->quiet, "no statistics on stderr");
    cmd->callback([flags, args] { run_export(*flags, *args); });
}

}  // namespace fibernet::cli
