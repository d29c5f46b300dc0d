#include "scan_comm.hpp"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <thread>
#include <vector>

#include "fibernet/util/error.hpp"

namespace fibernet::cli {

#ifndef FIBERNET_WITH_MPI
bool built_with_mpi() { return false; }
#endif

bool take_report(SampleQueue& queue, std::size_t index, const SampleReport& r, DispatchOutcome& out,
                 const ReportSink& sink) {
    if (!r.input_error.empty() && out.input_error.empty()) out.input_error = r.input_error;
    if (!r.output_error.empty() && out.output_error.empty()) out.output_error = r.output_error;
    out.interrupted = out.interrupted || r.interrupted;
    const bool stop = r.interrupted || !r.input_error.empty() || !r.output_error.empty();
    if (stop) {
        queue.stop();
    } else {
        if (sink) sink(index, r);
        queue.finished(index, r.ok, r.seconds);
    }
    return stop;
}

void run_local(SampleQueue& queue, const SampleRunner& runner, int threads, std::mutex& lock, DispatchOutcome& out,
               const ReportSink& sink) {
    std::exception_ptr error;
    auto loop = [&] {
        try {
            while (auto i = queue.next()) {
                const SampleReport r = runner(*i);
                std::lock_guard<std::mutex> guard(lock);
                if (take_report(queue, *i, r, out, sink)) break;
            }
        } catch (...) {  // a sink that could not write: stop the others, rethrow after them
            std::lock_guard<std::mutex> guard(lock);
            if (!error) error = std::current_exception();
            queue.stop();
        }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(loop);
    loop();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

namespace {
class SerialComm : public ScanComm {
public:
    int rank() const override { return 0; }
    int size() const override { return 1; }
    std::string kind() const override { return "serial"; }
    std::string share(const std::string& m) override { return m; }
    void barrier() override {}
    DispatchOutcome run(SampleQueue* queue, const SampleRunner& runner, int threads, const ReportSink& sink) override {
        DispatchOutcome out;
        std::mutex lock;
        run_local(*queue, runner, threads, lock, out, sink);
        return out;
    }
};

bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE", "MPI_LOCALNRANKS"})
        if (std::getenv(v)) return true;
    return false;
}
}  // namespace

void end_if_not_root(std::unique_ptr<ScanComm>& comm, int code) {
    if (comm->rank() == 0) return;
    comm.reset();
    std::fflush(nullptr);
    std::_Exit(code);
}

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
