// The MPI transport of fibernet scan (scan_comm.hpp): compiled only with FIBERNET_MPI (CMakeLists.txt).
#ifdef FIBERNET_WITH_MPI
#include <mpi.h>

#include <chrono>
#include <exception>
#include <cstdint>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "scan_comm.hpp"

namespace fibernet::cli {

bool built_with_mpi() { return true; }

namespace {
constexpr int kRequest = 1, kReply = 2;

nlohmann::json report_json(std::size_t index, const SampleReport& r) {
    return {{"index", index}, {"ok", r.ok}, {"seconds", r.seconds}, {"interrupted", r.interrupted},
            {"input_error", r.input_error}, {"output_error", r.output_error}, {"payload", r.payload}};
}
SampleReport report_of(const nlohmann::json& j) {
    SampleReport r;
    r.ok = j.value("ok", false), r.seconds = j.value("seconds", 0.0), r.interrupted = j.value("interrupted", false);
    r.input_error = j.value("input_error", std::string()), r.output_error = j.value("output_error", std::string());
    r.payload = j.value("payload", std::string());
    return r;
}

class MpiComm : public ScanComm {
public:
    MpiComm() {
        int provided = 0;
        MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
        threaded_ = provided >= MPI_THREAD_FUNNELED;
        // PMPI_: Debian's sequential MUMPS (linked by Ipopt) exports stand-ins for MPI_Init, MPI_Comm_rank,
        // MPI_Finalize and MPI_Wtime that return rank 0 and do nothing; the profiling names reach Open MPI's own.
        PMPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &size_);
    }
    ~MpiComm() override { PMPI_Finalize(); }
    int rank() const override { return rank_; }
    int size() const override { return size_; }
    std::string kind() const override { return "mpi"; }

    std::string share(const std::string& m) override {
        long long n = static_cast<long long>(m.size());
        MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
        std::string s = rank_ == 0 ? m : std::string(static_cast<std::size_t>(n), '\0');
        if (n > 0) MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
        return s;
    }
    void barrier() override { MPI_Barrier(MPI_COMM_WORLD); }

    DispatchOutcome run(SampleQueue* queue, const SampleRunner& runner, int threads, const ReportSink& sink) override {
        return rank_ == 0 ? schedule(*queue, runner, threads, sink) : work(runner);
    }

private:
    // Ranks > 0: ask for samples with the reports of the last ones, run them, until told none are left.
    DispatchOutcome work(const SampleRunner& runner) {
        nlohmann::json reports = nlohmann::json::array();
        for (;;) {
            const std::string msg = reports.dump();
            MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, kRequest, MPI_COMM_WORLD);
            MPI_Status st;
            MPI_Probe(0, kReply, MPI_COMM_WORLD, &st);
            int n = 0;
            MPI_Get_count(&st, MPI_LONG_LONG, &n);
            std::vector<long long> batch(static_cast<std::size_t>(n));
            MPI_Recv(batch.data(), n, MPI_LONG_LONG, 0, kReply, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            if (batch.empty()) return {};
            reports = nlohmann::json::array();
            for (long long index : batch) {
                const SampleReport r = runner(static_cast<std::size_t>(index));
                reports.push_back(report_json(static_cast<std::size_t>(index), r));
                if (r.interrupted || !r.input_error.empty() || !r.output_error.empty()) break;  // the rest stay unrun
            }
        }
    }

    // Rank 0: a worker thread of its own takes from the queue while this thread answers the other ranks. The
    // probe polls (with a 1 ms sleep) rather than blocking: a blocking receive spins a core in Open MPI.
    DispatchOutcome schedule(SampleQueue& queue, const SampleRunner& runner, int threads, const ReportSink& sink) {
        DispatchOutcome out;
        std::mutex mu;
        std::thread local;
        std::exception_ptr local_error;
        if (threaded_)
            local = std::thread([&] {
                try {
                    run_local(queue, runner, threads, mu, out, sink);
                } catch (...) {
                    local_error = std::current_exception();
                }
            });
        try {
            answer_requests(queue, mu, out, sink);
        } catch (...) {  // stop the local thread before the exception leaves (a joinable thread would terminate)
            queue.stop();
            if (local.joinable()) local.join();
            throw;
        }
        if (local.joinable()) local.join();
        if (local_error) std::rethrow_exception(local_error);
        if (!threaded_) run_local(queue, runner, threads, mu, out, sink);  // no second thread: what is left, now
        return out;
    }

    // Answers the other ranks until each has been told that no samples are left.
    void answer_requests(SampleQueue& queue, std::mutex& mu, DispatchOutcome& out, const ReportSink& sink) {
        int active = size_ - 1;
        while (active > 0) {
            int flag = 0;
            MPI_Status st;
            MPI_Iprobe(MPI_ANY_SOURCE, kRequest, MPI_COMM_WORLD, &flag, &st);
            if (!flag) {
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
                continue;
            }
            int n = 0;
            MPI_Get_count(&st, MPI_CHAR, &n);
            std::string text(static_cast<std::size_t>(n), '\0');
            MPI_Recv(text.data(), n, MPI_CHAR, st.MPI_SOURCE, kRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            const nlohmann::json reports = nlohmann::json::parse(text, nullptr, false);
            if (reports.is_array()) {
                std::lock_guard<std::mutex> lock(mu);
                for (const auto& j : reports) take_report(queue, j.at("index").get<std::size_t>(), report_of(j), out, sink);
            }
            // Batches of about 50 ms of samples: a request's round trip (up to the 1 ms poll) is then small beside
            // the work it brings, while samples of a second or more still go one at a time.
            std::vector<long long> batch;
            for (std::size_t i : queue.next_batch(256, 0.05, size_)) batch.push_back(static_cast<long long>(i));
            MPI_Send(batch.data(), static_cast<int>(batch.size()), MPI_LONG_LONG, st.MPI_SOURCE, kReply, MPI_COMM_WORLD);
            if (batch.empty()) --active;
        }
    }

    int rank_ = 0, size_ = 1;
    bool threaded_ = false;
};
}  // namespace

std::unique_ptr<ScanComm> mpi_scan_comm() { return std::make_unique<MpiComm>(); }

}  // namespace fibernet::cli
#endif
