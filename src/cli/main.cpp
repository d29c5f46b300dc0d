// fibernet: command-line entry. Each subcommand lives in its own cmd_<name>.cpp and registers itself here.
// Exit codes: 0 success, 1 a computation that did not succeed (e.g. a solver that did not converge),
// 2 bad input (flags, values, files), 3 an internal error, 4 a result that could not be written (names the file).
#include <CLI/CLI.hpp>
#include <iostream>

#include "common.hpp"
#include "in_process.hpp"
#include "unknown_flags.hpp"
#include "fibernet_version.hpp"
#include "fibernet/util/allocator.hpp"
#include "fibernet/util/error.hpp"
#include "fibernet/util/parallel.hpp"

int main(int argc, char** argv) {
    using namespace fibernet;
    keep_freed_memory();
    CLI::App app{"fibernet: mechanics of random fiber networks by implicit energy minimization", "fibernet"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string("fibernet ") + FIBERNET_VERSION + " (" + FIBERNET_GIT_COMMIT + ")");
    cli::register_commands(app);
    for (int i = 1; i < argc; ++i) cli::command_argv().push_back(argv[i]);
    if (argc == 1) {  // nothing asked: the usage, as an input error (CLI11 alone says only "A subcommand is required")
        std::cerr << app.help() << "\nfibernet: error: give a command (fibernet <command> --help for its flags)\n";
        return 2;
    }
    try {
        (void)thread_count();  // a bad FIBERNET_THREADS is an input error before any work
        // CLI11 says only "A subcommand is required" for a word that names none: name it and the commands.
        if (argc > 1 && argv[1][0] != '-') {
            std::string names;
            bool known = false;
            for (const CLI::App* sub : app.get_subcommands({})) {
                names += (names.empty() ? "" : ", ") + sub->get_name();
                known = known || sub->check_name(argv[1]);
            }
            if (!known) throw InputError(std::string("unknown command '") + argv[1] + "' (expected one of: " + names + ")");
        }
        cli::check_command_line(app, std::vector<std::string>(argv + 1, argv + argc));
        app.parse(argc, argv);
        cli::flush_stdout();  // results on stdout count only once they are out (a full device fails here)
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "fibernet: error: " << e.what() << "\n";
        return 2;
    } catch (const InputError& e) {
        std::cerr << "fibernet: error: " << e.what() << "\n";
        return 2;
    } catch (const OutputError& e) {
        std::cerr << "fibernet: error: " << e.what() << "\n";
        return 4;
    } catch (const std::exception& e) {
        std::cerr << "fibernet: internal error: " << e.what() << "\n";
        return 3;
    }
    return cli::exit_code();
}
