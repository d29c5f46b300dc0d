#pragma once
// OpenBLAS's threads for one sparse factorization, by its size.
//
// Debian's OpenBLAS (its pthreads build) starts one thread per core, wakes them for every BLAS call above its own
// size thresholds and keeps them spinning a while after. CHOLMOD's supernodal factorization of a small or medium
// matrix makes thousands of such calls, each too small to gain from a second thread: a smooth-model wet relaxation of
// 128 fibers, whose local solves factor matrices of a few thousand rows, took about 3x as long with OpenBLAS's
// default threads as with one, most of it in the kernel (docs/benchmarks.md, "OpenBLAS's and CHOLMOD's threads").
// A large factorization (the whole Hessian of an L = 40 network) does gain. So while a BlasThreads lives, OpenBLAS
// runs on one thread if the factorization takes fewer than kThreadedFlops floating-point operations (CHOLMOD's count
// from its analysis), and otherwise on thread_count() threads, at most as many as it had (OPENBLAS_NUM_THREADS, or a
// scan's one thread per rank, stay upper bounds). Inside a parallel section of fibernet's own (parallel.hpp: solves
// that run side by side) it is always one, so that concurrent factorizations never set different counts.
// OpenBLAS's count is one per process: each guard sets the count its factorization needs, and the count stays after
// it (BLAS calls outside fibernet's factorizations get the last one). A program that factors large matrices from
// several threads of its own, outside fibernet's parallel sections, should set FIBERNET_THREADS=1.
namespace fibernet {

class BlasThreads {
public:
    static constexpr double kThreadedFlops = 1e7;

    explicit BlasThreads(double flops);
    BlasThreads(const BlasThreads&) = delete;
    BlasThreads& operator=(const BlasThreads&) = delete;

    // The count this guard set, and OpenBLAS's own count when the process started (its upper bound).
    int threads() const { return set_; }
    static int own();

private:
    int set_ = 1;
};

}  // namespace fibernet
