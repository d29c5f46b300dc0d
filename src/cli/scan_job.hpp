#pragma once
// One sample of `fibernet scan`: the job's own command (modulus, relax, sweep, rigidity, wet) run in this process on
// the sample's scene file, exactly as `fibernet <job> <scene> -q <job args>` runs it, with its JSON captured.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "in_process.hpp"

namespace fibernet::cli {

// The commands a scan can run per sample.
const std::vector<std::string>& scan_jobs();

using JobOutcome = CommandOutcome;

// Runs `job` with argv {scene_file, -q (where the command has it), args...}. An InputError (a refusal of the scene or
// the arguments) and an OutputError propagate: they concern every sample, not this one.
JobOutcome run_job(const std::string& job, const std::string& scene_file, const std::vector<std::string>& args);

// Checks the job's arguments before any work: the command must parse them (with a stand-in scene), and they may not
// set what the scan sets (scene values, outputs). InputError naming the argument otherwise.
void check_job_args(const std::string& job, const std::vector<std::string>& args);

}  // namespace fibernet::cli
