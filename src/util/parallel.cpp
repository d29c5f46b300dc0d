#include "fibernet/util/parallel.hpp"

#include <omp.h>

#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "fibernet/util/error.hpp"

namespace fibernet {

namespace {
std::atomic<int> override_count{0};
thread_local bool parallel_section = false;

// fibernet has no OpenMP loop of its own; CHOLMOD's supernodal factorization has, and asks for a number of threads
// fixed when it was built (CHOLMOD_OMP_NUM_THREADS, 4 in Debian's), whatever OMP_NUM_THREADS says. fibernet's own
// CHOLMOD calls run those regions inline (inline_openmp.hpp); for any other region (a loader that bound CHOLMOD to
// libgomp directly, another library), on one thread OpenMP's teams are turned off (max-active-levels 0: a parallel
// region runs on the thread that meets it), so that a single-threaded run or a scan's rank starts no more threads.
// More threads: OpenMP's own setting, as the process started with it.
void openmp_for(int threads) {
    static const int initial = omp_get_max_active_levels();
    omp_set_max_active_levels(threads == 1 ? 0 : initial);
}
}  // namespace

bool in_parallel_section() { return parallel_section; }

ParallelSection::ParallelSection() : outer_(parallel_section) { parallel_section = true; }
ParallelSection::~ParallelSection() { parallel_section = outer_; }

void set_thread_count(int n) {
    if (n < 0) throw std::invalid_argument("set_thread_count: n = " + std::to_string(n) + " must be >= 0");
    override_count = n;
    openmp_for(n > 0 ? n : thread_count_default());
}

int thread_count() {
    if (const int o = override_count.load()) return o;
    return thread_count_default();
}

int thread_count_default() {
    static const int n = [] {
        if (const char* s = std::getenv("FIBERNET_THREADS")) {
            char* end = nullptr;
            const long v = std::strtol(s, &end, 10);
            if (end == s || *end != '\0' || v < 1 || v > 1024)
                throw InputError("FIBERNET_THREADS = '" + std::string(s) + "': expected an integer in [1, 1024]");
            return static_cast<int>(v);
        }
        const unsigned h = std::thread::hardware_concurrency();
        return h == 0 ? 1 : static_cast<int>(h);
    }();
    static const bool applied = [] {
        if (!override_count.load()) openmp_for(n);
        return true;
    }();
    (void)applied;
    return n;
}

}  // namespace fibernet
