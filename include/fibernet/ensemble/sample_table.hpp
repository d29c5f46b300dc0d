#pragma once
// An ensemble's results as tables (docs/scan.md, "Files"): samples.csv, one row per finished sample in index order,
// and summary.csv, the mean and standard error over the replicas (seeds) of each grid point. The columns are the
// grid's axes, the sample's status, and every number, boolean and string of the job's JSON result under its dotted
// path (moduli.G, solver.iterations; the objects of a list of at most 16 by index, runs.0.pores.count); other arrays
// and timings ("seconds") stay in samples.jsonl, so the rows are the same bit for bit however the ensemble was run.
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "fibernet/ensemble/grid.hpp"

namespace fibernet {

// The scalars of a JSON object by dotted path, in the object's key order, with the objects of lists of at most 16
// objects by index; other arrays and "seconds" members are left out.
std::vector<std::pair<std::string, nlohmann::json>> flatten_result(const nlohmann::json& result);

// A scalar as a CSV field: integers as such, other numbers with 17 significant digits (they read back exactly),
// true/false, null empty, strings quoted where they hold a comma, quote or newline.
std::string csv_field(const nlohmann::json& v);

// samples.csv from journal records in index order (each with index, params, status, exit_code, result).
std::string samples_csv(const Grid& grid, const std::vector<const nlohmann::json*>& records);

// summary.csv: per grid point (the non-replica axes), the samples, those with exit code 0, and for each numeric
// column of those: mean and standard error of the mean (sample standard deviation / sqrt(n); empty for n < 2).
std::string summary_csv(const Grid& grid, const std::vector<const nlohmann::json*>& records);

}  // namespace fibernet
