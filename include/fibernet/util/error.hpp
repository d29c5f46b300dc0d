#pragma once
// Errors a user can cause (bad flags, values, files). The CLI maps InputError to exit code 2 and
// writes no output file; the message always names the bad value and where it came from.
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fibernet {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A result that could not be written (a full device, a lost directory): the CLI maps it to exit code 4. The
// message names the file.
class OutputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Formats a value for an error message with full precision.
template <class T>
std::string show(const T& v) {
    std::ostringstream os;
    os.precision(17);
    os << v;
    return os.str();
}

// Throws InputError("<where>: <name> = <v> <must>") unless v is finite and ok holds.
inline void check_value(bool ok, double v, const std::string& where, const std::string& name, const std::string& must) {
    if (!std::isfinite(v)) throw InputError(where + ": " + name + " = " + show(v) + " is not a finite number");
    if (!ok) throw InputError(where + ": " + name + " = " + show(v) + " " + must);
}

}  // namespace fibernet
