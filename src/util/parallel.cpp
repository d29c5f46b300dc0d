#include "fibernet/util/parallel.hpp"

#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "fibernet/util/error.hpp"

namespace fibernet {

namespace {
std::atomic<int> override_count{0};
}

void set_thread_count(int n) {
    if (n < 0) throw std::invalid_argument("set_thread_count: n = " + std::to_string(n) + " must be >= 0");
    override_count = n;
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
    return n;
}

}  // namespace fibernet
