#pragma once
// Shared by the end-to-end tests of the `fibernet` executable (FIBERNET_EXE): run it with its output captured in a
// per-binary temporary directory, and read files back.
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace clitest {

// A fresh directory per test binary, made once.
inline std::string tmpdir() {
    static std::string d = [] {
        char tmpl[] = "/tmp/fibernet_test_XXXXXX";
        return std::string(mkdtemp(tmpl));
    }();
    return d;
}

// Runs `fibernet ARGS` with stdout and stderr in tmpdir()/stdout and tmpdir()/stderr; returns the exit code.
inline int run(const std::string& args) {
    const std::string cmd =
        std::string(FIBERNET_EXE) + " " + args + " >" + tmpdir() + "/stdout 2>" + tmpdir() + "/stderr";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

inline std::string slurp(const std::string& p) {
    std::ifstream is(p);
    return std::string((std::istreambuf_iterator<char>(is)), std::istreambuf_iterator<char>());
}
inline bool exists(const std::string& p) { return std::ifstream(p).good(); }
inline void write(const std::string& p, const std::string& s) { std::ofstream(p) << s; }

}  // namespace clitest
