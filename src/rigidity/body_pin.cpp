#include "fibernet/rigidity/body_pin.hpp"

#include <algorithm>
#include <numeric>

#include "fibernet/util/error.hpp"
#include "fibernet/util/union_find.hpp"

namespace fibernet {

namespace {

// Pins from the crosslinks of an open network; crosslinks closer than 1e-12 fiber lengths on one fiber are
// one pin (the same tolerance discretize() uses to merge them into one supernode).
void add_crosslink_pins(const Network& net, BodyPinFramework& fw) {
    if (net.periodic)
        throw InputError("rigidity: the network is periodic; the pebble game here counts open or clamped boxes (use --open)");
    const int nf = static_cast<int>(net.fibers.size());
    const int nc = static_cast<int>(net.crossings.size());
    // Crosslinks per fiber (CSR), sorted by arc position.
    std::vector<int> start(nf + 1, 0);
    for (const auto& c : net.crossings)
        if (c.crosslink) ++start[c.f1 + 1], ++start[c.f2 + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::pair<double, int>> on_fiber(start[nf]);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int k = 0; k < nc; ++k) {
        const auto& c = net.crossings[k];
        if (!c.crosslink) continue;
        on_fiber[fill[c.f1]++] = {c.s1, k};
        on_fiber[fill[c.f2]++] = {c.s2, k};
    }
    UnionFind pins(nc);
    bool any_merged = false;
    for (int f = 0; f < nf; ++f) {
        auto b = on_fiber.begin() + start[f], e = on_fiber.begin() + start[f + 1];
        std::sort(b, e);
        for (auto it = b; it != e && it + 1 != e; ++it)
            if ((it + 1)->first - it->first <= 1e-12) {
                if (pins.unite(it->second, (it + 1)->second)) any_merged = true;
            }
    }
    if (!any_merged) {  // the generic case: one pin per crosslink
        for (const auto& c : net.crossings) {
            if (!c.crosslink) continue;
            fw.pin_point.push_back(net.fibers[c.f1].point(c.s1));
            fw.pin_body.push_back(c.f1);
            fw.pin_body.push_back(c.f2);
            fw.pin_offset.push_back(static_cast<int>(fw.pin_body.size()));
        }
        return;
    }
    std::vector<std::vector<int>> members(nc);
    for (int k = 0; k < nc; ++k)
        if (net.crossings[k].crosslink) members[pins.find(k)].push_back(k);
    for (int r = 0; r < nc; ++r) {
        if (members[r].empty()) continue;
        std::vector<int> bodies;
        for (int k : members[r]) bodies.push_back(net.crossings[k].f1), bodies.push_back(net.crossings[k].f2);
        std::sort(bodies.begin(), bodies.end());
        bodies.erase(std::unique(bodies.begin(), bodies.end()), bodies.end());
        const auto& c = net.crossings[r];
        fw.pin_point.push_back(net.fibers[c.f1].point(c.s1));
        fw.pin_body.insert(fw.pin_body.end(), bodies.begin(), bodies.end());
        fw.pin_offset.push_back(static_cast<int>(fw.pin_body.size()));
    }
}

}  // namespace

BodyPinFramework body_pin_framework(const Network& net) {
    BodyPinFramework fw;
    fw.fibers = fw.bodies = static_cast<int>(net.fibers.size());
    add_crosslink_pins(net, fw);
    return fw;
}

BodyPinFramework body_pin_framework(const ClampedNetwork& cl) {
    BodyPinFramework fw;
    fw.fibers = static_cast<int>(cl.net.fibers.size());
    fw.bodies = fw.fibers + 2;
    fw.clamped = true;
    add_crosslink_pins(cl.net, fw);
    for (const auto& p : cl.pins) {
        fw.pin_point.push_back(cl.net.fibers[p.fiber].point(p.s));
        fw.pin_body.push_back(p.fiber);
        fw.pin_body.push_back(p.clamp == Clamp::Bottom ? fw.bottom() : fw.top());
        fw.pin_offset.push_back(static_cast<int>(fw.pin_body.size()));
    }
    return fw;
}

}  // namespace fibernet
