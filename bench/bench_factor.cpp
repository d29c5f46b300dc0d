// CHOLMOD on wet Hessians (issue 6): cost of the symbolic analysis (done again whenever the bridge set, and so the
// Hessian pattern, changes) against one numeric factorization, and of a failed (indefinite) factorization, on a
// Mikado network of N fibers wetted at all crossings after a short capillary relaxation.
//   bench_factor [N=1000] [q=10] [reps=5] [seed=1] [wet_rounds=0]
// wet_rounds > 0: the Hessian is instead that of the bridge set and state after an active-set relaxation bounded to
// that many global rounds (bench_wet's settings), a late Hessian whose bridges have added fill. Each run also
// compares CHOLMOD's fill-reducing orderings on the simplicial LDL^T (fill, flops, analysis and factorization time).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/cholmod_ldl.hpp"
#include "fibernet/solve/cholmod_llt.hpp"
#include "fibernet/solve/newton.hpp"
#include "fibernet/wet/wet_energy.hpp"
#include "fibernet/wet/wet_run.hpp"
#include "fibernet/wet/wetting.hpp"

#include <cholmod.h>
#include <memory>
#include <vector>

using namespace fibernet;

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

int main(int argc, char** argv) {
    const int N = argc > 1 ? std::atoi(argv[1]) : 1000;
    const double density = argc > 2 ? std::atof(argv[2]) : 10;
    const int reps = argc > 3 ? std::atoi(argv[3]) : 5;
    const unsigned seed = argc > 4 ? static_cast<unsigned>(std::atoi(argv[4])) : 1u;
    const int wet_rounds = argc > 5 ? std::atoi(argv[5]) : 0;
    MikadoParams mp;
    mp.q = density, mp.pl = 0.5, mp.seed = seed;
    mp.L = std::sqrt(N / density);
    const Network net = generate_mikado(mp);
    DiscretizationParams dp;
    const Model m = discretize(net, dp);
    NetworkEnergy dry(m);
    const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
    Eigen::VectorXd q = dry.dofs(m.x);
    WetParams p;
    p.beta = 0.01;
    std::unique_ptr<WetEnergy> Wp;
    // NESDIS ordering of the first wet Hessian's pattern, to see how well a stale ordering serves a late pattern.
    std::vector<int> early_perm;
    auto view = [](const Eigen::SparseMatrix<double>& M) {
        cholmod_sparse A{};
        A.nrow = A.ncol = static_cast<size_t>(M.rows());
        A.nzmax = static_cast<size_t>(M.nonZeros());
        A.p = const_cast<int*>(M.outerIndexPtr()), A.i = const_cast<int*>(M.innerIndexPtr());
        A.x = const_cast<double*>(M.valuePtr());
        A.stype = 1, A.itype = CHOLMOD_INT, A.xtype = CHOLMOD_REAL, A.dtype = CHOLMOD_DOUBLE, A.sorted = 1, A.packed = 1;
        return A;
    };
    if (wet_rounds > 0) {
        WetEnergy W0(dry, I, wet_crossings(net, m, dry.positions(q, I), m.box.B0(), WettingRule{}), p);
        const Eigen::SparseMatrix<double> H0 = W0.hessian_pattern();
        cholmod_common c;
        cholmod_start(&c);
        c.supernodal = CHOLMOD_SIMPLICIAL, c.nmethods = 1, c.method[0].ordering = CHOLMOD_NESDIS, c.print = 0;
        cholmod_sparse A = view(H0);
        cholmod_factor* L = cholmod_analyze(&A, &c);
        early_perm.assign(static_cast<int*>(L->Perm), static_cast<int*>(L->Perm) + L->n);
        cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
    }
    if (wet_rounds > 0) {
        WetRunOptions opt;
        opt.params = p;
        opt.moduli = false;
        opt.active_set.max_rounds = wet_rounds;
        opt.solver_options.tol = 1e-8;
        const WetRun run = run_wet(net, m, I, opt);
        q = run.wet.q;
        Wp = std::make_unique<WetEnergy>(dry, I, run.active.bridges, p);
        std::fprintf(stderr, "after %d rounds (%d local): %zu bridges (%zu at the start)\n", run.active.rounds,
                     run.active.local_rounds, run.active.bridges.size(), run.initial_bridges.size());
    } else {
        Wp = std::make_unique<WetEnergy>(dry, I, wet_crossings(net, m, dry.positions(q, I), m.box.B0(), WettingRule{}), p);
        SolverOptions so;
        so.max_iter = 10;
        NewtonSolver(so).minimize(*Wp, q);  // a state under capillary load (indefinite Hessian)
    }
    WetEnergy& W = *Wp;
    auto tp = Clock::now();
    Eigen::SparseMatrix<double> H = W.hessian_pattern();  // the union pattern and the value slots, once per bridge set
    const double t_pattern = seconds_since(tp);
    Eigen::VectorXd g;
    W.hessian(q, g, H, false);
    double dm = 0;
    for (int j = 0; j < H.cols(); ++j) dm += std::abs(H.coeff(j, j));
    dm /= H.cols();
    double t_an = 1e300, t_ok = 1e300, t_fail = 1e300;
    bool fail_ok = false;
    for (int r = 0; r < reps; ++r) {
        CholmodLLT llt;
        auto t0 = Clock::now();
        llt.analyze(H);
        t_an = std::min(t_an, seconds_since(t0));
        t0 = Clock::now();
        fail_ok = !llt.factorize(H, 1e-8 * dm);
        t_fail = std::min(t_fail, seconds_since(t0));
        t0 = Clock::now();
        const bool ok = llt.factorize(H, 0.2 * dm);
        t_ok = std::min(t_ok, seconds_since(t0));
        if (!ok) std::fprintf(stderr, "warning: H + 0.2 mean diag did not factor\n");
    }
    // The simplicial LDL^T of the indefinite H + 1e-8 mean diag (Newton's first rung) and its modified solve: in
    // CholmodLDL's two-thread order (the default for large matrices), and with CHOLMOD's own order on one thread
    // (split_min above the size: the wrapper before 2026-11-25).
    struct LdlTimes {
        double analysis = 1e300, factorization = 1e300, solve = 1e300;  // min over the repetitions
        int negative = 0, split_a = 0, split_b = 0;
    };
    auto time_ldl = [&](int split_min) {
        LdlTimes t;
        for (int r = 0; r < reps; ++r) {
            CholmodLDL ldl(split_min);
            auto t0 = Clock::now();
            ldl.analyze(H);
            t.analysis = std::min(t.analysis, seconds_since(t0));
            t0 = Clock::now();
            if (!ldl.factorize(H, 1e-8 * dm)) std::fprintf(stderr, "warning: LDL^T of H + 1e-8 mean diag failed\n");
            t.factorization = std::min(t.factorization, seconds_since(t0));
            t.negative = ldl.negative_pivots();
            t.split_a = ldl.split_a(), t.split_b = ldl.split_b();
            t0 = Clock::now();
            const Eigen::VectorXd d = ldl.solve_modified(g, 1e-8 * dm);
            t.solve = std::min(t.solve, seconds_since(t0));
        }
        return t;
    };
    const LdlTimes one = time_ldl(1 << 30), two = time_ldl(CholmodLDL::kSplitMin);
    // Orderings for the simplicial LDL^T, by CHOLMOD directly on H with the order of its own (so "default" is CHOLMOD
    // as the wrapper called it before it pre-permuted: compare its factorization_s with ldl_factorization_s).
    // early_nesdis: the NESDIS order of the first wet Hessian (wet_rounds > 0 only), node_nesdis: NESDIS of the node
    // graph expanded to coordinates.
    constexpr int kEarly = -2, kNode = -3;
    struct Ord {
        const char* name;
        int ordering;  // CHOLMOD_* or -1 (CHOLMOD's default methods), kEarly, kNode
    };
    const Ord ords[] = {{"default", -1},         {"amd", CHOLMOD_AMD},       {"metis", CHOLMOD_METIS},
                        {"nesdis", CHOLMOD_NESDIS}, {"colamd", CHOLMOD_COLAMD}, {"early_nesdis", kEarly},
                        {"node_nesdis", kNode}};
    // Nested dissection of the node graph (a node's two coordinates eliminated together): a quarter of the entries
    // to order. Its time counts the node pattern, the ordering and the expansion to coordinates.
    std::vector<int> node_perm;
    double t_node = 0;
    {
        auto t0 = Clock::now();
        std::vector<int> node_of(H.rows(), -1);
        int nn = 0;
        for (int i = 0; i < m.num_nodes(); ++i) {
            bool any = false;
            for (int c = 0; c < 2; ++c)
                if (dry.dof(i, c) >= 0) node_of[dry.dof(i, c)] = nn, any = true;
            nn += any;
        }
        std::vector<Eigen::Triplet<double>> t;
        t.reserve(H.nonZeros() / 3);
        for (int j = 0; j < H.cols(); ++j)
            for (int k = H.outerIndexPtr()[j]; k < H.outerIndexPtr()[j + 1]; ++k) {
                const int a = node_of[H.innerIndexPtr()[k]], b = node_of[j];
                if (a <= b) t.emplace_back(a, b, 1.0);
            }
        Eigen::SparseMatrix<double> Hn(nn, nn);
        Hn.setFromTriplets(t.begin(), t.end());
        Hn.makeCompressed();
        cholmod_common c;
        cholmod_start(&c);
        c.supernodal = CHOLMOD_SIMPLICIAL, c.nmethods = 1, c.method[0].ordering = CHOLMOD_NESDIS, c.print = 0;
        cholmod_sparse A = view(Hn);
        cholmod_factor* L = cholmod_analyze(&A, &c);
        std::vector<std::vector<int>> dofs_of(nn);
        for (int k = 0; k < H.rows(); ++k) dofs_of[node_of[k]].push_back(k);
        for (size_t k = 0; k < L->n; ++k)
            for (int d : dofs_of[static_cast<int*>(L->Perm)[k]]) node_perm.push_back(d);
        cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
        t_node = seconds_since(t0);
    }
    std::string ord_json;
    for (const Ord& o : ords) {
        if (o.ordering == kEarly && early_perm.empty()) continue;
        const int* given = o.ordering == kEarly ? early_perm.data() : o.ordering == kNode ? node_perm.data() : nullptr;
        cholmod_common c;
        cholmod_start(&c);
        c.supernodal = CHOLMOD_SIMPLICIAL, c.final_ll = 0, c.print = 0, c.error_handler = nullptr;
        if (o.ordering != -1) c.nmethods = 1, c.method[0].ordering = given ? CHOLMOD_GIVEN : o.ordering;
        cholmod_sparse A = view(H);
        auto t0 = Clock::now();
        cholmod_factor* L = given ? cholmod_analyze_p(&A, const_cast<int*>(given), nullptr, 0, &c) : cholmod_analyze(&A, &c);
        const double t_a = seconds_since(t0) + (o.ordering == kNode ? t_node : 0.0);
        if (!L) {
            std::fprintf(stderr, "ordering %s: analysis failed (status %d)\n", o.name, c.status);
            cholmod_finish(&c);
            continue;
        }
        const double lnz = c.lnz, fl = c.fl;
        double t_f = 1e300;
        double beta[2] = {1e-8 * dm, 0};
        for (int r = 0; r < reps; ++r) {
            t0 = Clock::now();
            cholmod_factorize_p(&A, beta, nullptr, 0, L, &c);
            t_f = std::min(t_f, seconds_since(t0));
        }
        const int chosen = c.method[c.selected].ordering;
        char buf[256];
        std::snprintf(buf, sizeof buf, "%s\"%s\": {\"ordering\": %d, \"lnz\": %.4g, \"flops\": %.4g, \"analysis_s\": %.4f, "
                      "\"factorization_s\": %.4f}", ord_json.empty() ? "" : ", ", o.name, chosen, lnz, fl, t_a, t_f);
        ord_json += buf;
        cholmod_free_factor(&L, &c);
        cholmod_finish(&c);
    }
    std::printf("{\"fibers\": %zu, \"dofs\": %ld, \"nnz_upper\": %ld, \"pattern_s\": %.4f, \"analysis_s\": %.4f, \"factorization_s\": %.4f, "
                "\"indefinite\": %s, \"failed_factorization_s\": %.4f, \"ldl_analysis_s\": %.4f, \"ldl_factorization_s\": %.4f, "
                "\"ldl_solve_s\": %.4f, \"ldl_negative_pivots\": %d, \"ldl_parts\": [%d, %d, %d], "
                "\"ldl_one_thread_amd\": {\"analysis_s\": %.4f, \"factorization_s\": %.4f}, \"orderings\": {%s}}\n",
                net.fibers.size(), static_cast<long>(H.rows()), static_cast<long>(H.nonZeros()), t_pattern, t_an, t_ok,
                fail_ok ? "true" : "false", t_fail, two.analysis, two.factorization, two.solve, two.negative, two.split_a,
                two.split_b - two.split_a, static_cast<int>(H.rows()) - two.split_b, one.analysis, one.factorization,
                ord_json.c_str());
}
