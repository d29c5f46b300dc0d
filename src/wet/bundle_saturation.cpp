#include "fibernet/wet/bundle_saturation.hpp"

namespace fibernet {

Saturation bundle_saturation(double n, int N) {
    const double h = kSaturationHalfWidth;
    if (N <= 0 || n <= N - h) return {n, 1, 0};
    if (n >= N + h) return {static_cast<double>(N), 0, 0};
    // t in (0, 1) across the blend; S' = 1 - (3 t^2 - 2 t^3), integrated from S(N - h) = N - h.
    const double t = (n - (N - h)) / (2 * h), t2 = t * t;
    return {n - 2 * h * (t2 * t - 0.5 * t2 * t2), 1 - (3 * t2 - 2 * t2 * t), -6 * t * (1 - t) / (2 * h)};
}

}  // namespace fibernet
