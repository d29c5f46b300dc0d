#pragma once
// The samples left to run, handed out one at a time as workers come free (dynamic load balancing: sample times
// differ by 100x across a grid), with the counts and the progress line (ETA) of the run. Thread-safe: the threads of
// one process and, under MPI, rank 0's scheduler on behalf of the other ranks take from one queue.
#include <chrono>
#include <cstddef>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace fibernet {

class SampleQueue {
public:
    // todo: the indices to run, in order; progress lines ("<label>: 37/96 samples ...") go to stderr every
    // `report_seconds` (none if < 0).
    SampleQueue(std::vector<std::size_t> todo, double report_seconds, std::string label = "scan");
    std::optional<std::size_t> next();  // nullopt once every sample is handed out, or after stop()
    // Up to `max` samples for a worker that asks over a network: as many as take about `target_seconds` at the mean
    // sample time so far (one while nothing has finished), but at most a quarter of what is left per worker, so
    // that the last samples still spread over the workers. Empty once every sample is handed out, or after stop().
    std::vector<std::size_t> next_batch(std::size_t max, double target_seconds, int workers);
    void finished(std::size_t index, bool ok, double seconds);
    void stop();                        // hand out no more samples (an interrupt, an input error)
    bool stopped() const;
    std::size_t size() const { return todo_.size(); }
    std::size_t done() const;
    std::size_t failed() const;
    double busy_seconds() const;        // the sum of the finished samples' own times
    std::string progress_line() const;  // "scan: 37/96 samples (2 failed), 45 s, ETA 1 min 10 s"

private:
    std::string line_locked() const;
    mutable std::mutex mu_;
    std::vector<std::size_t> todo_;
    std::size_t next_ = 0, done_ = 0, failed_ = 0;
    double busy_ = 0, report_seconds_, last_report_ = 0;
    std::string label_;
    bool stopped_ = false;
    std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// "1 h 02 min", "3 min 10 s", "12 s": a duration for a progress line.
std::string human_duration(double seconds);

}  // namespace fibernet
