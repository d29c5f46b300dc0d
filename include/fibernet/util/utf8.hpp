#pragma once
// UTF-8 validation for text files fibernet reads and echoes into its JSON results (a law table in the wet summary):
// such a file must be UTF-8, and the reader names the first byte that is not.
#include <cstddef>
#include <string>

namespace fibernet {

// The offset of the first byte of `text` that does not start or continue a well-formed UTF-8 sequence (RFC 3629:
// no overlong forms, no surrogates, nothing above U+10FFFF), or std::string::npos when all of it is UTF-8.
std::size_t invalid_utf8_at(const std::string& text);

}  // namespace fibernet
