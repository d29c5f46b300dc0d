// The partner cap's saturation S(n) (bundle_saturation.hpp): the identity below the cap's blend, the cap above it,
// C2 across the blend's ends, and S', S'' against central differences inside it.
#include <catch2/catch.hpp>
#include <cmath>

#include "fibernet/wet/bundle_saturation.hpp"

using namespace fibernet;

TEST_CASE("bundle saturation: S(n) = n below the blend, N above, C2 with exact derivatives", "[wet][smooth]") {
    const double h = kSaturationHalfWidth;
    for (const int N : {1, 2, 6}) {
        INFO("N = " << N);
        for (const double n : {0.0, 0.3, N - h - 1e-9}) {
            const Saturation s = bundle_saturation(n, N);
            CHECK(s.S == n);
            CHECK(s.dS == 1);
            CHECK(s.d2S == 0);
        }
        for (const double n : {N + h, N + h + 0.7, 40.0}) {
            const Saturation s = bundle_saturation(n, N);
            CHECK(s.S == N);
            CHECK(s.dS == 0);
            CHECK(s.d2S == 0);
        }
        // Continuity of S, S', S'' at both ends of the blend.
        for (const double end : {N - h, N + h}) {
            const Saturation a = bundle_saturation(end - 1e-9, N), b = bundle_saturation(end + 1e-9, N);
            CHECK(std::abs(a.S - b.S) < 1e-8);
            CHECK(std::abs(a.dS - b.dS) < 1e-7);
            CHECK(std::abs(a.d2S - b.d2S) < 1e-7);
        }
        // Inside: derivatives against central differences, S' falling from 1 to 0, S concave.
        for (double n = N - h + 0.01; n < N + h; n += 0.07) {
            const double e = 1e-6;
            const Saturation s = bundle_saturation(n, N), p = bundle_saturation(n + e, N), m = bundle_saturation(n - e, N);
            CHECK(s.dS == Approx((p.S - m.S) / (2 * e)).margin(1e-8));
            CHECK(s.d2S == Approx((p.dS - m.dS) / (2 * e)).margin(1e-7));
            CHECK(s.dS > 0);
            CHECK(s.dS < 1);
            CHECK(s.d2S < 0);
            CHECK(s.S < n);
            CHECK(s.S < N);
        }
    }
    // No cap: the identity everywhere.
    const Saturation s = bundle_saturation(17.5, 0);
    CHECK(s.S == 17.5);
    CHECK(s.dS == 1);
}
