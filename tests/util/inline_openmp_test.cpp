// InlineOpenMP (util/inline_openmp.hpp): under a guard an OpenMP parallel region runs its body once, on the calling
// thread, as a team of one; outside a guard it gets OpenMP's team; CHOLMOD's supernodal factorization (CholmodLLT)
// runs its regions that way at any thread count and gives the solution of CHOLMOD with its own threads bit for bit.
#include <catch2/catch.hpp>
#include <cholmod.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <thread>
#include <vector>

#include <Eigen/SparseCore>

#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/util/blas_threads.hpp"
#include "fibernet/util/inline_openmp.hpp"
#include "fibernet/util/parallel.hpp"

// GCC's entry point of `#pragma omp parallel` (these tests are not compiled with OpenMP, so they call it directly).
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags);

using namespace fibernet;

namespace {

struct Region {
    std::atomic<int> bodies{0};
    std::atomic<int> width{0};
    std::atomic<bool> on_caller{false};
    std::thread::id caller = std::this_thread::get_id();
};

void body(void* p) {
    auto& r = *static_cast<Region*>(p);
    ++r.bodies;
    r.width = omp_get_num_threads();
    if (omp_get_thread_num() == 0 && std::this_thread::get_id() == r.caller) r.on_caller = true;
}

int threads_of_this_process() {
    int n = 0;
    for ([[maybe_unused]] const auto& t : std::filesystem::directory_iterator("/proc/self/task")) ++n;
    return n;
}

// The 5-point Laplacian of a 40 x 40 grid, shifted: positive definite, with more than 128 rows and supernodes of more
// than 1024 entries (so CHOLMOD's regions open), and few enough operations that OpenBLAS runs on one thread in both
// factorizations compared (blas_threads.hpp; its threaded kernels round differently).
Eigen::SparseMatrix<double> laplacian() {
    const int m = 40, n = m * m;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            const int k = i * m + j;
            t.emplace_back(k, k, 4.1);
            if (j + 1 < m) t.emplace_back(k, k + 1, -1.0);
            if (i + 1 < m) t.emplace_back(k, k + m, -1.0);
        }
    Eigen::SparseMatrix<double> H(n, n);
    H.setFromTriplets(t.begin(), t.end());
    return H;
}

// CHOLMOD called directly, with no InlineOpenMP: its regions get libgomp's teams of CHOLMOD_OMP_NUM_THREADS threads.
// OpenBLAS's threads as CholmodLLT sets them (blas_threads.hpp), so that OpenMP is the one difference.
Eigen::VectorXd solve_with_cholmod_threads(const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& b) {
    Eigen::SparseMatrix<double> U = H.triangularView<Eigen::Upper>();
    U.makeCompressed();
    cholmod_common c;
    cholmod_start(&c);
    c.supernodal = CHOLMOD_SUPERNODAL;
    cholmod_sparse A{};
    A.nrow = A.ncol = static_cast<size_t>(U.rows());
    A.nzmax = static_cast<size_t>(U.nonZeros());
    A.p = U.outerIndexPtr(), A.i = U.innerIndexPtr(), A.x = U.valuePtr();
    A.stype = 1, A.itype = CHOLMOD_INT, A.xtype = CHOLMOD_REAL, A.dtype = CHOLMOD_DOUBLE, A.sorted = 1, A.packed = 1;
    cholmod_factor* L = cholmod_analyze(&A, &c);
    REQUIRE(L);
    const BlasThreads blas(c.fl);
    REQUIRE(cholmod_factorize(&A, L, &c));
    Eigen::VectorXd rhs = b;
    cholmod_dense B{};
    B.nrow = B.d = B.nzmax = static_cast<size_t>(rhs.size());
    B.ncol = 1, B.x = rhs.data(), B.xtype = CHOLMOD_REAL, B.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* X = cholmod_solve(CHOLMOD_A, L, &B, &c);
    REQUIRE(X);
    Eigen::VectorXd x = Eigen::Map<Eigen::VectorXd>(static_cast<double*>(X->x), rhs.size());
    cholmod_free_dense(&X, &c);
    cholmod_free_factor(&L, &c);
    cholmod_finish(&c);
    return x;
}

}  // namespace

TEST_CASE("InlineOpenMP: under a guard a parallel region runs once, on the calling thread", "[util][openmp]") {
    set_thread_count(2);  // OpenMP's teams as the process started with them (parallel.cpp turns them off on one)
    Region outside;
    GOMP_parallel(body, &outside, 2, 0);
    CHECK(outside.bodies == 2);  // a team of two: the entry point reached libgomp
    CHECK(outside.width == 2);
    Region inside;
    const long before = InlineOpenMP::regions_inlined();
    {
        const InlineOpenMP guard;
        {
            const InlineOpenMP nested;  // guards nest
        }
        GOMP_parallel(body, &inside, 4, 0);
    }
    CHECK(inside.bodies == 1);
    CHECK(inside.width == 1);
    CHECK(inside.on_caller);
    CHECK(InlineOpenMP::regions_inlined() == before + 1);
    Region after;
    GOMP_parallel(body, &after, 2, 0);
    CHECK(after.bodies == 2);  // the guard is gone with its scope
    set_thread_count(0);
}

namespace {
struct Nested {
    std::atomic<int> inner_bodies{0};
    std::atomic<int> widest{0};
};
void inner(void* p) {
    auto& n = *static_cast<Nested*>(p);
    ++n.inner_bodies;
    n.widest = std::max(n.widest.load(), omp_get_num_threads());
}
void outer(void* p) {
    const InlineOpenMP guard;  // fibernet called from each thread of a program's own parallel region
    GOMP_parallel(inner, p, 4, 0);
}
}  // namespace

TEST_CASE("InlineOpenMP: a region under a guard on a thread of a larger team goes to OpenMP", "[util][openmp]") {
    // Run inline there, the body would see the outer team's size and do only its share of a static loop.
    set_thread_count(2);
    Nested n;
    GOMP_parallel(outer, &n, 2, 0);
    // Each of the 2 outer threads gets a nested team (of one while nesting is off, OpenMP's default; of 4 with it on)
    // whose bodies each see that team's size; inline, a body would see 2 and run once per outer thread.
    CHECK(n.inner_bodies == 2 * n.widest);
    set_thread_count(0);
}

TEST_CASE("InlineOpenMP: CholmodLLT runs CHOLMOD's regions inline at any thread count, the same solution bit for bit",
          "[util][openmp]") {
    const Eigen::SparseMatrix<double> H = laplacian();
    Eigen::VectorXd b(H.rows());
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = std::sin(0.37 * static_cast<double>(i)) + 0.5;
    for (int threads : {1, 2}) {
        set_thread_count(threads);
        // libgomp's teams first, so that their threads exist before the count below.
        const Eigen::VectorXd reference = solve_with_cholmod_threads(H, b);
        const int tasks = threads_of_this_process();
        const long before = InlineOpenMP::regions_inlined();
        CholmodLLT llt;
        llt.analyze(H);
        REQUIRE(llt.factorize(H));
        const Eigen::VectorXd x = llt.solve(b);
        CHECK(InlineOpenMP::regions_inlined() > before);  // the loader bound CHOLMOD's calls to fibernet's entry point
        CHECK(threads_of_this_process() == tasks);
        CHECK((x.array() == reference.array()).all());
    }
    set_thread_count(0);
}
