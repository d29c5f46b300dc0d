#pragma once
// Wall-clock seconds: a scope's added to a running total (the smooth wet energy's list and pattern builds, reported in
// the time split of a wet run), and a steady clock's reading for differences.
#include <chrono>

namespace fibernet {

// Seconds on the steady clock since its epoch: only differences mean anything.
inline double wall_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Seconds on the steady clock since t0.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

class ScopedSeconds {
public:
    explicit ScopedSeconds(double& total) : total_(total), t0_(std::chrono::steady_clock::now()) {}
    ~ScopedSeconds() { total_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }
    ScopedSeconds(const ScopedSeconds&) = delete;
    ScopedSeconds& operator=(const ScopedSeconds&) = delete;

private:
    double& total_;
    std::chrono::steady_clock::time_point t0_;
};

}  // namespace fibernet
