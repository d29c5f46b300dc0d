#pragma once
// `fibernet` in the background for the end-to-end tests that signal a running command (FIBERNET_EXE): its own pid, so
// that a signal reaches it and not a shell, with stdout and stderr in clitest::tmpdir()/bg_stdout and bg_stderr.
#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <functional>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

#include "cli_run.hpp"

namespace clitest {

// `fibernet ARGS...` started in the background; returns its pid.
inline pid_t start_background(const std::vector<std::string>& args) {
    const pid_t pid = fork();
    if (pid == 0) {
        const int o = open((tmpdir() + "/bg_stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int e = open((tmpdir() + "/bg_stderr").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(o, 1), dup2(e, 2);
        std::signal(SIGINT, SIG_DFL);  // a test run in the background of a script inherits SIGINT ignored
        std::vector<char*> argv{const_cast<char*>(FIBERNET_EXE)};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(FIBERNET_EXE, argv.data());
        _exit(127);
    }
    return pid;
}

// Polls until `ready` holds while the process still runs (true), or it exits or 300 s pass (false; a run still
// going is killed).
inline bool wait_until(pid_t pid, const std::function<bool()>& ready) {
    const auto t0 = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(300)) {
        if (ready()) return true;
        if (waitpid(pid, nullptr, WNOHANG) == pid) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
    return false;
}

}  // namespace clitest
