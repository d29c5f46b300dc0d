#pragma once
// A scene written back as TOML (docs/formats.md, "scene"): every key, so the text alone says what was computed and
// `fibernet <command> that.toml` computes it again. An ensemble (fibernet scan) writes each sample's scene this way,
// with the keys it varies replaced by the values of the sample.
#include <map>
#include <string>
#include <vector>

#include "fibernet/scene/scene.hpp"

namespace fibernet {

// Every scalar key a scene has, as "table.key" (network.L, model.a, wet.beta, ...), in the order to_toml writes them.
// [model].prune (an array) is written but not listed: an ensemble cannot vary it.
const std::vector<std::string>& scene_keys();

// The scene as TOML text. `replace` maps "table.key" to a TOML value literal (e.g. "8", "\"even\"") written instead
// of the scene's own value; a key not in scene_keys() is an InputError. Paths are written as given (load_scene has
// made a scene's relative paths relative to the working directory).
std::string to_toml(const Scene& s, const std::map<std::string, std::string>& replace = {});

// A number as TOML text that reads back as the same double (shortest round trip; always a float literal).
std::string toml_float(double v);

}  // namespace fibernet
