#pragma once
// A fibernet command run inside this process, exactly as `fibernet <argv...>` runs it, with the JSON it would print
// captured: for fibernet scan's samples and for the Python package (python/fibernet).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace fibernet::cli {

// Registers every subcommand on `app` (main.cpp's command set).
void register_commands(CLI::App& app);

struct CommandOutcome {
    int exit_code = 0;       // the command's: 0 success, 1 not converged / failed, 130 interrupted, 3 internal error
    nlohmann::json result;   // the command's JSON (null if it threw)
    std::string error;       // the message of an internal error
};

// Runs argv (argv[0] the command name) on `app`, which must hold that command. with_provenance: the JSON carries its
// provenance as on stdout (a scan's samples leave it to the scan's manifest). An InputError (the command's refusal of
// its input; a CLI11 parse error becomes one) and an OutputError propagate; any other exception is exit 3.
// Not reentrant: the commands share process state (the exit code, the capture); callers serialize.
CommandOutcome run_command(CLI::App& app, const std::vector<std::string>& argv, bool with_provenance);

}  // namespace fibernet::cli
