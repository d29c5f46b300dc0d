#pragma once
// The processes of a `fibernet scan` (docs/scan.md, "MPI"): this process alone, or the ranks of an MPI job. Rank 0
// owns the queue of samples and hands them out one at a time as ranks come free (dynamic load balancing); it also
// runs samples itself on a second thread, so K ranks are K workers. Every rank writes its finished samples to a
// journal of its own; only indices and short reports travel over MPI.
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "fibernet/ensemble/sample_queue.hpp"

namespace fibernet::cli {

struct SampleReport {
    bool ok = true;            // the sample's command exited 0
    double seconds = 0;
    bool interrupted = false;  // the sample was interrupted (not journaled): stop handing out samples
    std::string input_error;   // the job refused its input: stop, and the scan exits 2 with this message
    std::string output_error;  // a file could not be written: stop, exit 4
    std::string payload;       // what rank 0 records for the sample (fibernet percolation's CSV row), if anything
};
using SampleRunner = std::function<SampleReport(std::size_t index)>;
// Called on rank 0, one report at a time, for every finished sample of any rank (before the queue counts it).
using ReportSink = std::function<void(std::size_t index, const SampleReport&)>;

struct DispatchOutcome {
    bool interrupted = false;
    std::string input_error, output_error;  // the first reported, if any
};

class ScanComm {
public:
    virtual ~ScanComm() = default;
    virtual int rank() const = 0;
    virtual int size() const = 0;
    virtual std::string kind() const = 0;  // "serial" | "mpi"
    // Rank 0's verdict (e.g. "the directory is ready") on every rank: its message, empty for "go on".
    virtual std::string share(const std::string& message_on_root) = 0;
    virtual void barrier() = 0;
    // Runs the samples of `queue` (rank 0's; nullptr on the others) until it is empty or stopped: on rank 0 on
    // `threads` threads (a runner that is not thread-safe: 1), on the other ranks one at a time.
    virtual DispatchOutcome run(SampleQueue* queue, const SampleRunner& runner, int threads = 1,
                                const ReportSink& sink = {}) = 0;
};

// MPI when this process was started by an MPI launcher (mpirun, mpiexec, srun) and fibernet was built with MPI;
// otherwise serial. A launcher without MPI support in the build is an InputError (the ranks would each run it all).
std::unique_ptr<ScanComm> start_scan_comm();
bool built_with_mpi();

// On a rank other than 0: ends it quietly with `code` (rank 0 reports for all): MPI finalized, process exited.
// On rank 0: returns.
void end_if_not_root(std::unique_ptr<ScanComm>& comm, int code);

// The serial case, also the sample loop of every rank.
std::unique_ptr<ScanComm> serial_scan_comm();
// Feeds a report into the sink, the queue and the outcome; true when the queue should stop. Not thread-safe.
bool take_report(SampleQueue& queue, std::size_t index, const SampleReport& r, DispatchOutcome& out,
                 const ReportSink& sink);
// Runs samples from the queue on `threads` threads of this process (the calling one included) until it is empty or
// stopped; `lock` serializes the reports (take_report).
void run_local(SampleQueue& queue, const SampleRunner& runner, int threads, std::mutex& lock, DispatchOutcome& out,
               const ReportSink& sink);

}  // namespace fibernet::cli
