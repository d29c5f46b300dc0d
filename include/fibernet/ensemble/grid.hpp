#pragma once
// The samples of an ensemble (fibernet scan, docs/scan.md): a Cartesian grid over scene keys, one axis per --vary,
// the last axis fastest. A sample is its index into that grid; its scene is the base scene with the axes' values
// in, so a sample's result depends only on its index and the grid, never on how the ensemble is split.
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace fibernet {

struct GridAxis {
    std::string name;                 // as given (the CSV column), e.g. "q" or "model.a"
    std::string key;                  // the scene key, "table.key" (scene_keys())
    std::vector<std::string> values;  // TOML literals: 8, 0.5, "even", true
    std::vector<std::string> labels;  // the same as CSV fields (strings unquoted)
    // Axes of one list of points (parse_points) share a group >= 0 and one coordinate: they vary together, the
    // k-th value of each at the k-th point. -1: an axis of its own.
    int group = -1;
    std::string source;  // where the values came from, for messages: "--vary q=4,8" or the points file's name
};

// The scene key a name stands for: "table.key" itself, or a key's bare name where one table has it; "seed" is the
// network's seed (the wet draw's is wet.seed). InputError naming `where` otherwise.
std::string grid_key(const std::string& name, const std::string& where);

// "name=v1,v2,..." (a list), "name=first:last" (integers, step 1) or "name=first:last:step" (numbers; values
// first + k step up to last, written to 12 significant digits). Each value must be given once.
GridAxis parse_axis(const std::string& spec, const std::string& where);

// A list of points (--points FILE): a CSV whose header names scene keys (as --vary does) and whose rows are the
// points, e.g. "L,q" then "10,8" and "20,16". One axis per column, all in `group`. Each point must be given once.
std::vector<GridAxis> parse_points(const std::string& csv_text, const std::string& where, int group);

struct Grid {
    std::vector<GridAxis> axes;

    std::size_t size() const;  // product of the lengths of the axes and groups (1 with no axes)
    // The value index on each axis of sample `index` (< size()).
    std::vector<std::size_t> coordinates(std::size_t index) const;
    // The scene keys and TOML literals that sample `index` sets.
    std::map<std::string, std::string> replacements(std::size_t index) const;
    // Whether axis k draws replicas (a seed, network.seed or wet.seed, on an axis of its own; a seed in a list of
    // points is part of the point): statistics average over these axes.
    bool replica_axis(std::size_t k) const;
    // The grid point of a sample: its index with the replica axes left out (samples that differ only in seeds share it).
    std::size_t point(std::size_t index) const;
};

// Checks a grid: no key varied twice, the axes of a group of one length, at most `max_samples` samples.
// InputError naming `where` otherwise.
void check_grid(const Grid& g, std::size_t max_samples, const std::string& where);

}  // namespace fibernet
