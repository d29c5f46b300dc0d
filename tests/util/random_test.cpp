#include <catch2/catch.hpp>

#include "fibernet/util/random.hpp"

using namespace fibernet;

TEST_CASE("Rng: equal seeds give equal streams, uniform() is uniform on [0, 1)", "[random]") {
    // (The values themselves are pinned in tests/network/mikado_test.cpp.)
    Rng a(1), b(1), c(2);
    const auto a0 = a.next();
    REQUIRE(a0 == b.next());
    REQUIRE(a0 != c.next());
    Rng r(42);
    double sum = 0;
    for (int i = 0; i < 100000; ++i) {
        double u = r.uniform();
        REQUIRE(u >= 0);
        REQUIRE(u < 1);
        sum += u;
    }
    CHECK(sum / 100000 == Approx(0.5).margin(0.005));  // 5 sigma of sqrt(1/12/1e5) ~ 0.0009
}
