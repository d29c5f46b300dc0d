#pragma once
// Network files (docs/formats.md, "network"): a line-based text format that round-trips exactly
// (every double written with 17 significant digits).
#include <iosfwd>
#include <string>

#include "fibernet/network/network.hpp"

namespace fibernet {

void write_network(std::ostream& os, const Network& net);
// `source` names the stream in error messages (a file name). Throws InputError with source:line.
Network read_network(std::istream& is, const std::string& source);

// File versions: save writes to a temporary file and renames it, so a failed run leaves no partial file.
void save_network(const Network& net, const std::string& path);
Network load_network(const std::string& path);

// Writes `content` to `path` atomically (temporary file + rename). Shared by every writer of results.
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace fibernet
