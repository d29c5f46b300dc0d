#include "scan_comm.hpp"

#include <cstdlib>

#include "fibernet/util/error.hpp"

namespace fibernet::cli {

#ifndef FIBERNET_WITH_MPI
bool built_with_mpi() { return false; }
#endif

bool take_report(SampleQueue& queue, std::size_t index, const SampleReport& r, DispatchOutcome& out) {
    if (!r.input_error.empty() && out.input_error.empty()) out.input_error = r.input_error;
    if (!r.output_error.empty() && out.output_error.empty()) out.output_error = r.output_error;
    out.interrupted = out.interrupted || r.interrupted;
    const bool stop = r.interrupted || !r.input_error.empty() || !r.output_error.empty();
    if (stop) queue.stop();
    else queue.finished(index, r.ok, r.seconds);
    return stop;
}

namespace {
class SerialComm : public ScanComm {
public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    std::string kind() const override { return "serial"; }
    std::string share(const std::string& m) override { return m; }
    void barrier() override {}
    DispatchOutcome run(SampleQueue* queue, const SampleRunner& runner) override {
        DispatchOutcome out;
        while (auto i = queue->next())
            if (take_report(*queue, *i, runner(*i), out)) break;
        return out;
    }
};

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
        if (std::getenv(v)) return true;
    return false;
}
}  // namespace

std::unique_ptr<ScanComm> serial_scan_comm() { return std::make_unique<SerialComm>(); }

std::unique_ptr<ScanComm> mpi_scan_comm();  // scan_mpi.cpp

std::unique_ptr<ScanComm> start_scan_comm() {
    if (!launched_by_mpi()) return serial_scan_comm();
    if (!built_with_mpi())
        throw InputError("this fibernet was built without MPI (cmake -DFIBERNET_MPI=ON), yet started by an MPI "
                         "launcher: every rank would run the whole scan; run it without mpirun, or split it with --shard");
    return mpi_scan_comm();
}

#ifndef FIBERNET_WITH_MPI
std::unique_ptr<ScanComm> mpi_scan_comm() { return nullptr; }
#endif

}  // namespace fibernet::cli
