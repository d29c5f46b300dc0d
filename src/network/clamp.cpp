#include "fibernet/network/clamp.hpp"

#include <algorithm>
#include <cmath>

#include "fibernet/util/error.hpp"

namespace fibernet {

ClampedNetwork clamp_network(const Network& net) {
    if (net.periodic) throw InputError("clamps need an open box (the network is periodic; use --open)");
    ClampedNetwork out;
    out.net.L = net.L;
    out.net.periodic = false;
    out.net.seed = net.seed, out.net.q = net.q, out.net.pl = net.pl;
    const double L = net.L;
    const double tiny = 1e-12;  // fibers shorter than this after trimming (touching an edge) are dropped
    const int nf = static_cast<int>(net.fibers.size());
    std::vector<int> new_index(nf, -1);
    std::vector<double> lo(nf, 0), hi(nf, 0);
    for (int f = 0; f < nf; ++f) {
        const Fiber& fib = net.fibers[f];
        // The part of the fiber with 0 <= y <= L: s in [a, b].
        double a = 0, b = fib.length;
        const double y0 = fib.start.y(), dy = std::sin(fib.theta);
        bool cut_a = false, cut_b = false;
        Clamp clamp_a = Clamp::Bottom, clamp_b = Clamp::Bottom;
        if (std::abs(dy) > 0) {
            const double s_bottom = (0 - y0) / dy, s_top = (L - y0) / dy;
            const double s_in = std::min(s_bottom, s_top), s_out = std::max(s_bottom, s_top);
            const Clamp c_in = s_bottom < s_top ? Clamp::Bottom : Clamp::Top;
            const Clamp c_out = s_bottom < s_top ? Clamp::Top : Clamp::Bottom;
            if (s_in > a) a = s_in, cut_a = true, clamp_a = c_in;
            if (s_out < b) b = s_out, cut_b = true, clamp_b = c_out;
        } else if (y0 < 0 || y0 > L) {
            continue;  // horizontal and outside
        }
        if (b - a <= tiny) continue;
        new_index[f] = static_cast<int>(out.net.fibers.size());
        out.original_fiber.push_back(f);
        lo[f] = a, hi[f] = b;
        Fiber t = fib;
        t.start = fib.point(a);
        t.length = b - a;
        out.net.fibers.push_back(t);
        if (cut_a) out.pins.push_back({new_index[f], 0.0, clamp_a});
        if (cut_b) out.pins.push_back({new_index[f], b - a, clamp_b});
    }
    for (const Crossing& c : net.crossings) {
        const int g1 = new_index[c.f1], g2 = new_index[c.f2];
        if (g1 < 0 || g2 < 0) continue;
        if (c.s1 < lo[c.f1] || c.s1 > hi[c.f1] || c.s2 < lo[c.f2] || c.s2 > hi[c.f2]) continue;
        Crossing k = c;
        k.f1 = g1, k.f2 = g2;
        k.s1 = c.s1 - lo[c.f1], k.s2 = c.s2 - lo[c.f2];
        out.net.crossings.push_back(k);
    }
    return out;
}

}  // namespace fibernet
