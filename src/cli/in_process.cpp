#include "in_process.hpp"
#include "unknown_flags.hpp"

#include <algorithm>

#include "common.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet::cli {

void register_commands(CLI::App& app) {
    register_generate(app);
    register_export(app);
    register_info(app);
    register_rigidity(app);
    register_compare(app);
    register_percolation(app);
    register_modulus(app);
    register_relax(app);
    register_wet(app);
    register_sweep(app);
    register_scan(app);
}

namespace {
std::string help_text(CLI::App& app) {
    for (CLI::App* sub : app.get_subcommands()) return sub->help();
    return app.help();
}
}  // namespace

CommandOutcome run_command(CLI::App& app, const std::vector<std::string>& argv, bool with_provenance) {
    CommandOutcome out;
    // The capture, the exit code and the recorded command line are the process's: put them back however this ends.
    // (A scan run from Python nests: its samples' captures must leave the scan's own in place.)
    struct Restore {
        std::vector<std::string> argv = command_argv();
        nlohmann::json* capture = json_capture();
        bool provenance = capture_provenance();
        int code = exit_code();
        ~Restore() {
            json_capture() = capture, capture_provenance() = provenance, exit_code() = code;
            command_argv() = argv;
        }
    } restore;
    forget_scene();
    json_capture() = &out.result;
    capture_provenance() = with_provenance;
    exit_code() = 0;
    command_argv() = argv;
    std::vector<std::string> reversed(argv.rbegin(), argv.rend());  // CLI11 takes a reversed vector
    try {
        check_command_line(app, argv);
        app.parse(reversed);
        out.exit_code = exit_code();
    } catch (const CLI::CallForHelp&) {  // --help: the command's help as the result
        out.result = {{"help", help_text(app)}};
    } catch (const CLI::CallForAllHelp&) {
        out.result = {{"help", help_text(app)}};
    } catch (const CLI::ParseError& e) {
        throw InputError(std::string("the arguments of ") + (argv.empty() ? "fibernet" : argv[0]) + ": " + e.what());
    } catch (const InputError&) {
        throw;
    } catch (const OutputError&) {
        throw;
    } catch (const std::exception& e) {
        out.exit_code = 3, out.error = e.what(), out.result = nullptr;
    }
    return out;
}

}  // namespace fibernet::cli
