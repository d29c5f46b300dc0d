// Sparse Hessian patterns (energy/sparse_pattern.hpp): PatternBuilder against a pattern built from column lists here,
// and element_slots and subpattern_slots agreeing with pattern_slot entry by entry.
#include <catch2/catch.hpp>

#include <algorithm>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/random.hpp"

using namespace fibernet;

namespace {
// The reference: the pattern whose column c holds the rows cols[c] (any order, repeats allowed), by Eigen's triplets.
Eigen::SparseMatrix<double> pattern_from_columns(int n, const std::vector<std::vector<int>>& cols) {
    std::vector<Eigen::Triplet<double>> t;
    for (int c = 0; c < n; ++c)
        for (int r : cols[c]) t.emplace_back(r, c, 0.0);
    Eigen::SparseMatrix<double> P(n, n);
    P.setFromTriplets(t.begin(), t.end());
    P.makeCompressed();
    return P;
}
}  // namespace

TEST_CASE("sparse pattern: columns sorted and deduplicated; element_slots equals pattern_slot", "[energy][pattern]") {
    // Random elements of 3 coordinates over 40, with some coordinates absent (-1).
    const int n = 40, M = 3, ne = 60;
    Rng rng(5);
    std::vector<int> idx(M * ne);
    for (int& v : idx) v = rng.uniform() < 0.15 ? -1 : static_cast<int>(rng.uniform() * n);
    std::vector<std::vector<int>> cols(n);
    for (int e = 0; e < ne; ++e)
        for (int a = 0; a < M; ++a)
            for (int b = 0; b < M; ++b) {
                const int r = idx[e * M + a], c = idx[e * M + b];
                if (r >= 0 && c >= 0 && r <= c) cols[c].push_back(r);
            }
    for (int c = 0; c < n; ++c) cols[c].push_back(c);
    PatternBuilder builder(n);
    builder.add_elements(idx, M);
    builder.add_diagonal();
    const Eigen::SparseMatrix<double> P = builder.build();
    const Eigen::SparseMatrix<double> want = pattern_from_columns(n, cols);
    REQUIRE(P.nonZeros() == want.nonZeros());
    CHECK(std::equal(P.innerIndexPtr(), P.innerIndexPtr() + P.nonZeros(), want.innerIndexPtr()));
    for (int c = 0; c < n; ++c)
        for (int k = P.outerIndexPtr()[c] + 1; k < P.outerIndexPtr()[c + 1]; ++k)
            CHECK(P.innerIndexPtr()[k - 1] < P.innerIndexPtr()[k]);
    std::vector<int> slots;
    element_slots(P, idx, M, slots);
    REQUIRE(slots.size() == static_cast<size_t>(M * M * ne));
    int found = 0;
    for (int e = 0; e < ne; ++e)
        for (int a = 0; a < M; ++a)
            for (int b = 0; b < M; ++b) {
                const int r = idx[e * M + a], c = idx[e * M + b];
                const int want = (r >= 0 && c >= 0 && r <= c) ? pattern_slot(P, r, c) : -1;
                CHECK(slots[e * M * M + a * M + b] == want);
                found += want >= 0;
            }
    CHECK(found > ne);
    // The slots of a contained pattern (the diagonal and the first element's entries), in its value order.
    std::vector<std::vector<int>> sub(n);
    for (int c = 0; c < n; ++c) sub[c].push_back(c);
    for (int a = 0; a < M; ++a)
        for (int b = 0; b < M; ++b)
            if (idx[a] >= 0 && idx[b] >= 0 && idx[a] <= idx[b]) sub[idx[b]].push_back(idx[a]);
    const Eigen::SparseMatrix<double> S = pattern_from_columns(n, sub);
    const std::vector<int> in = subpattern_slots(P, S);
    REQUIRE(in.size() == static_cast<size_t>(S.nonZeros()));
    for (int c = 0, k = 0; c < n; ++c)
        for (int j = S.outerIndexPtr()[c]; j < S.outerIndexPtr()[c + 1]; ++j, ++k)
            CHECK(in[k] == pattern_slot(P, S.innerIndexPtr()[j], c));
    // An entry the pattern lacks is an error, as with pattern_slot.
    std::vector<int> bad = {0, n - 1};
    Eigen::SparseMatrix<double> diag(n, n);
    for (int c = 0; c < n; ++c) diag.insert(c, c) = 0;
    diag.makeCompressed();
    CHECK_THROWS_AS(element_slots(diag, bad, 2, slots), std::logic_error);
    // ... unless the caller takes the lacking elements: their missing entries are -1, the others as found.
    std::vector<int> some = {0, n - 1, 1, 1, 2, -1};  // (0, n-1) lacks its off-diagonal entry; the others have theirs
    std::vector<char> lacking;
    element_slots(diag, some, 2, slots, &lacking);
    CHECK(lacking == std::vector<char>{1, 0, 0});
    CHECK(slots == std::vector<int>{0, -1, -1, n - 1, 1, 1, 1, 1, 2, -1, -1, -1});
    CHECK_THROWS_AS(pattern_slot(diag, 0, n - 1), std::logic_error);
    CHECK_THROWS_AS(subpattern_slots(diag, P), std::logic_error);
}

TEST_CASE("sparse pattern: PatternBuilder from patterns, elements of several sizes and the diagonal", "[energy][pattern]") {
    // A base pattern, two element lists of different sizes with absent coordinates, and the diagonal.
    const int n = 50;
    Rng rng(11);
    auto elements = [&](int M, int ne) {
        std::vector<int> idx(M * ne);
        for (int& v : idx) v = rng.uniform() < 0.2 ? -1 : static_cast<int>(rng.uniform() * n);
        return idx;
    };
    const std::vector<int> e3 = elements(3, 40), e5 = elements(5, 25), base_idx = elements(2, 30);
    std::vector<std::vector<int>> base_cols(n), cols(n);
    auto collect = [](std::vector<std::vector<int>>& into, const std::vector<int>& idx, int M) {
        for (size_t e = 0; e < idx.size(); e += M)
            for (int a = 0; a < M; ++a)
                for (int b = 0; b < M; ++b) {
                    const int r = idx[e + a], c = idx[e + b];
                    if (r >= 0 && c >= 0 && r <= c) into[c].push_back(r);
                }
    };
    collect(base_cols, base_idx, 2);
    const Eigen::SparseMatrix<double> base = pattern_from_columns(n, base_cols);
    collect(cols, base_idx, 2), collect(cols, e3, 3), collect(cols, e5, 5);
    for (int c = 0; c < n; ++c) cols[c].push_back(c);
    const Eigen::SparseMatrix<double> want = pattern_from_columns(n, cols);

    PatternBuilder builder(n);
    builder.add_pattern(base);
    builder.add_elements(e3, 3);
    builder.add_elements(e5, 5);
    builder.add_diagonal();
    const Eigen::SparseMatrix<double> got = builder.build();
    REQUIRE(got.nonZeros() == want.nonZeros());
    CHECK(std::equal(got.outerIndexPtr(), got.outerIndexPtr() + n + 1, want.outerIndexPtr()));
    CHECK(std::equal(got.innerIndexPtr(), got.innerIndexPtr() + got.nonZeros(), want.innerIndexPtr()));
    // Without the diagonal, columns with no entry stay empty.
    PatternBuilder sparse(n);
    sparse.add_elements(e3, 3);
    const Eigen::SparseMatrix<double> s3 = sparse.build();
    std::vector<std::vector<int>> c3(n);
    collect(c3, e3, 3);
    const Eigen::SparseMatrix<double> w3 = pattern_from_columns(n, c3);
    REQUIRE(s3.nonZeros() == w3.nonZeros());
    CHECK(std::equal(s3.outerIndexPtr(), s3.outerIndexPtr() + n + 1, w3.outerIndexPtr()));
    CHECK(std::equal(s3.innerIndexPtr(), s3.innerIndexPtr() + s3.nonZeros(), w3.innerIndexPtr()));
}
