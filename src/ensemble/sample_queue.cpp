#include "fibernet/ensemble/sample_queue.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace fibernet {

std::string human_duration(double s) {
    char b[64];
    if (!std::isfinite(s) || s < 0) return "?";
    const long t = std::lround(s);
    if (t >= 3600) std::snprintf(b, sizeof b, "%ld h %02ld min", t / 3600, (t % 3600) / 60);
    else if (t >= 60) std::snprintf(b, sizeof b, "%ld min %02ld s", t / 60, t % 60);
    else std::snprintf(b, sizeof b, "%ld s", t);
    return b;
}

SampleQueue::SampleQueue(std::vector<std::size_t> todo, double report_seconds, std::string label)
    : todo_(std::move(todo)), report_seconds_(report_seconds), label_(std::move(label)) {}

std::optional<std::size_t> SampleQueue::next() {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopped_ || next_ >= todo_.size()) return std::nullopt;
    return todo_[next_++];
}

std::vector<std::size_t> SampleQueue::next_batch(std::size_t max, double target_seconds, int workers) {
    std::lock_guard<std::mutex> lock(mu_);
    std::vector<std::size_t> out;
    if (stopped_ || next_ >= todo_.size()) return out;
    const std::size_t left = todo_.size() - next_;
    std::size_t n = 1;
    if (done_ > 0 && busy_ > 0) {
        const double mean = busy_ / static_cast<double>(done_);
        n = static_cast<std::size_t>(std::max(1.0, std::min(static_cast<double>(max), target_seconds / mean)));
    }
    n = std::min(n, std::max<std::size_t>(1, left / (4 * static_cast<std::size_t>(std::max(1, workers)))));
    for (std::size_t k = 0; k < n; ++k) out.push_back(todo_[next_++]);
    return out;
}

void SampleQueue::finished(std::size_t, bool ok, double seconds) {
    std::lock_guard<std::mutex> lock(mu_);
    ++done_;
    if (!ok) ++failed_;
    busy_ += seconds;
    if (report_seconds_ < 0) return;
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    if (t - last_report_ >= report_seconds_ || done_ == todo_.size()) {
        last_report_ = t;
        std::cerr << line_locked() << "\n";
    }
}

void SampleQueue::stop() {
    std::lock_guard<std::mutex> lock(mu_);
    stopped_ = true;
}
bool SampleQueue::stopped() const {
    std::lock_guard<std::mutex> lock(mu_);
    return stopped_;
}
std::size_t SampleQueue::done() const {
    std::lock_guard<std::mutex> lock(mu_);
    return done_;
}
std::size_t SampleQueue::failed() const {
    std::lock_guard<std::mutex> lock(mu_);
    return failed_;
}
double SampleQueue::busy_seconds() const {
    std::lock_guard<std::mutex> lock(mu_);
    return busy_;
}
std::string SampleQueue::progress_line() const {
    std::lock_guard<std::mutex> lock(mu_);
    return line_locked();
}

std::string SampleQueue::line_locked() const {
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    std::string s = label_ + ": " + std::to_string(done_) + "/" + std::to_string(todo_.size()) + " samples";
    if (failed_ > 0) s += " (" + std::to_string(failed_) + " failed)";
    s += ", " + human_duration(t);
    if (done_ > 0 && done_ < todo_.size())
        s += ", ETA " + human_duration(t / static_cast<double>(done_) * static_cast<double>(todo_.size() - done_));
    return s;
}

}  // namespace fibernet
