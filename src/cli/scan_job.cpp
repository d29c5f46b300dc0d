#include "scan_job.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <functional>
#include <map>
#include <set>

#include "common.hpp"
#include "in_process.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::cli {

namespace {
const std::map<std::string, Registrar>& registrars() {
    static const std::map<std::string, Registrar> r = {{"modulus", register_modulus}, {"relax", register_relax},
                                                       {"rigidity", register_rigidity}, {"sweep", register_sweep},
                                                       {"wet", register_wet}};
    return r;
}

// Arguments a scan sets itself: the scene flags, wet's [wet] ones included (from SceneFlags::add, which declares them
// from scene_options(); their values come from the scene file and the grid), and the outputs.
const std::set<std::string>& reserved() {
    static const std::set<std::string> r = [] {
        std::set<std::string> names = {"-o",    "--out",     "--out-dir",    "--output", "--svg", "--table", "--summary",
                                       "--checkpoint", "--resume", "--vtk", "-v", "--verbose", "-q", "--quiet"};
        CLI::App app;
        SceneFlags flags;
        flags.add(app.add_subcommand("any"), true, true);
        for (const CLI::Option* o : flags.opts) {
            for (const auto& l : o->get_lnames()) names.insert("--" + l);
            for (const auto& sn : o->get_snames()) names.insert("-" + sn);
        }
        return names;
    }();
    return r;
}

CLI::App* make_command(CLI::App& app, const std::string& job) {
    const auto it = registrars().find(job);
    if (it == registrars().end()) {
        std::string names;
        for (const auto& j : scan_jobs()) names += (names.empty() ? "" : ", ") + j;
        throw InputError("command line: --job " + job + " is not a job a scan runs (expected one of: " + names + ")");
    }
    it->second(app);
    return app.get_subcommand(job);
}

std::vector<std::string> argv_of(CLI::App* cmd, const std::string& job, const std::string& scene,
                                 const std::vector<std::string>& args) {
    std::vector<std::string> v = {job, scene};
    if (cmd->get_option_no_throw("--quiet")) v.push_back("--quiet");
    v.insert(v.end(), args.begin(), args.end());
    return v;
}

void parse(CLI::App& app, std::vector<std::string> argv) {
    std::reverse(argv.begin(), argv.end());  // CLI11 takes a reversed vector
    app.parse(argv);
}
}  // namespace

const std::vector<std::string>& scan_jobs() {
    static const std::vector<std::string> j = {"modulus", "relax", "rigidity", "sweep", "wet"};
    return j;
}

void check_job_args(const std::string& job, const std::vector<std::string>& args) {
    for (const auto& a : args) {
        std::string flag = a.substr(0, a.find('='));
        if (flag.size() > 2 && flag[0] == '-' && flag[1] != '-') flag = flag.substr(0, 2);  // -oPATH is -o PATH
        if (reserved().count(flag))
            throw InputError("command line: --job-args " + a + ": a scan sets " + flag +
                             " itself (scene values come from the scene and --vary; outputs go to -o)");
    }
    CLI::App app;
    CLI::App* cmd = make_command(app, job);
    // Parse only: stop after the options are parsed and checked, before the command's callback runs. The callback is
    // kept, not replaced: it owns (through shared pointers) the variables the options write to, and replacing it
    // freed them before the parse wrote into them.
    struct Parsed {};
    app.parse_complete_callback([] { throw Parsed{}; });
    std::vector<std::string> full = args;
    if (job == "sweep") full.insert(full.end(), {"-o", "sweep.csv"});  // the scan gives each sample's CSV
    try {
        parse(app, argv_of(cmd, job, "/dev/null", full));  // a stand-in scene that exists
    } catch (const Parsed&) {
    } catch (const CLI::ParseError& e) {
        throw InputError("command line: --job-args for " + job + ": " + e.what());
    }
}

JobOutcome run_job(const std::string& job, const std::string& scene_file, const std::vector<std::string>& args) {
    CLI::App app;
    CLI::App* cmd = make_command(app, job);
    return run_command(app, argv_of(cmd, job, scene_file, args), false);
}

}  // namespace fibernet::cli
