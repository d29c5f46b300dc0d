#pragma once
// The processes of a `fibernet scan` (docs/scan.md, "MPI"): this process alone, or the ranks of an MPI job. Rank 0
// owns the queue of samples and hands them out one at a time as ranks come free (dynamic load balancing); it also
// runs samples itself on a second thread, so K ranks are K workers. Every rank writes its finished samples to a
// journal of its own; only indices and short reports travel over MPI.
#include <functional>
#include <memory>
#include <string>

#include "fibernet/ensemble/sample_queue.hpp"

namespace fibernet::cli {

struct SampleReport {
    bool ok = true;            // the sample's command exited 0
    double seconds = 0;
    bool interrupted = false;  // the sample was interrupted (not journaled): stop handing out samples
    std::string input_error;   // the job refused its input: stop, and the scan exits 2 with this message
    std::string output_error;  // a file could not be written: stop, exit 4
};
using SampleRunner = std::function<SampleReport(std::size_t index)>;

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
    // Runs the samples of `queue` (rank 0's; nullptr on the others) until it is empty or stopped.
    virtual DispatchOutcome run(SampleQueue* queue, const SampleRunner& runner) = 0;
};

// MPI when this process was started by an MPI launcher (mpirun, mpiexec, srun) and fibernet was built with MPI;
// otherwise serial. A launcher without MPI support in the build is an InputError (the ranks would each run it all).
std::unique_ptr<ScanComm> start_scan_comm();
bool built_with_mpi();

// The serial case, also the sample loop of every rank.
std::unique_ptr<ScanComm> serial_scan_comm();
// Feeds a report into the queue and the outcome; true when the queue should stop.
bool take_report(SampleQueue& queue, std::size_t index, const SampleReport& r, DispatchOutcome& out);

}  // namespace fibernet::cli
