#include "fibernet/util/blas_threads.hpp"

#include <algorithm>
#include <mutex>

#include "fibernet/util/parallel.hpp"

extern "C" void openblas_set_num_threads(int);  // OpenBLAS (CHOLMOD's BLAS, CMakeLists.txt)
extern "C" int openblas_get_num_threads(void);

namespace fibernet {

namespace {
// OpenBLAS's own count, read before main (OpenBLAS reads OPENBLAS_NUM_THREADS when it is loaded, before this).
const int own_count = openblas_get_num_threads();
std::mutex setting;
}  // namespace

int BlasThreads::own() { return std::max(1, own_count); }

BlasThreads::BlasThreads(double flops) {
    const bool large = flops >= kThreadedFlops && !in_parallel_section();
    set_ = large ? std::max(1, std::min(thread_count(), own())) : 1;
    // Each factorization sets the count it needs and none puts one back, so that factorizations side by side (all
    // of one count inside a parallel section) never leave another count behind.
    std::lock_guard<std::mutex> lock(setting);
    if (openblas_get_num_threads() != set_) openblas_set_num_threads(set_);
}

}  // namespace fibernet
