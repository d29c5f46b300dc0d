#pragma once
// A command line's mistakes named before CLI11 parses it: CLI11 validates the positional scene file before it
// reports an unknown flag, so `fibernet modulus --L 4 --density 8` would say "File does not exist: 8" (the unknown
// flag's value taken as the scene). This check says which flag is unknown, suggests the nearest one, and says
// when a word taken as the scene file follows a flag that takes no value.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace fibernet::cli {

// args: the command and its arguments (argv from 1 on). Throws InputError naming the first unknown flag (with "did you
// mean"), or a word read as the scene file after a flag that takes no value when no such file exists. Leaves
// everything else to CLI11's parse.
void check_command_line(const CLI::App& app, const std::vector<std::string>& args);

// The flag of `command` nearest to `unknown` ("--density" -> "--q", whose description names density;
// "--seeds" -> "--seed"), or "" when none is near.
std::string nearest_flag(const CLI::App& command, const std::string& unknown);

}  // namespace fibernet::cli
