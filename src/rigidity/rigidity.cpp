#include "fibernet/rigidity/rigidity.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

#include "fibernet/rigidity/pebble_game.hpp"

namespace fibernet {

namespace {
std::vector<int> relabel(std::vector<int> root) {
    std::vector<int> label(root.size(), -1), of_root(root.size(), -1);
    int k = 0;
    for (size_t i = 0; i < root.size(); ++i) {
        int& l = of_root[root[i]];
        if (l < 0) l = k++;
        label[i] = l;
    }
    return label;
}
}  // namespace

std::vector<int> pin_components(const BodyPinFramework& fw) {
    std::vector<int> p(fw.bodies);
    std::iota(p.begin(), p.end(), 0);
    auto find = [&](int i) {
        while (p[i] != i) i = p[i] = p[p[i]];
        return i;
    };
    for (int k = 0; k < fw.num_pins(); ++k)
        for (int i = fw.pin_offset[k] + 1; i < fw.pin_offset[k + 1]; ++i) {
            const int a = find(fw.pin_body[fw.pin_offset[k]]), b = find(fw.pin_body[i]);
            if (a != b) p[std::max(a, b)] = std::min(a, b);
        }
    std::vector<int> root(fw.bodies);
    for (int i = 0; i < fw.bodies; ++i) root[i] = find(i);
    return relabel(root);
}

RigidityResult analyze_rigidity(const BodyPinFramework& fw) {
    RigidityResult r;
    r.fibers = fw.fibers, r.bodies = fw.bodies, r.pins = fw.num_pins(), r.bars = fw.num_bars();
    r.clamped = fw.clamped;
    // Speed only (the counts do not depend on the order): play the pins in the order of unit cells along rows
    // and number the bodies in the order their first pin is met, so that searches touch nearby memory.
    std::vector<int> pin_order(fw.num_pins());
    {
        std::vector<std::int64_t> key(fw.num_pins());
        for (int k = 0; k < fw.num_pins(); ++k) {
            const auto& p = fw.pin_point[k];
            key[k] = static_cast<std::int64_t>(std::floor(p.y())) * (1LL << 31) + static_cast<std::int64_t>(std::floor(p.x()));
        }
        std::iota(pin_order.begin(), pin_order.end(), 0);
        std::stable_sort(pin_order.begin(), pin_order.end(), [&](int a, int b) { return key[a] < key[b]; });
    }
    std::vector<int> id(fw.bodies, -1);  // game id of each body
    int next_id = 0;
    for (int k : pin_order)
        for (int i = fw.pin_offset[k]; i < fw.pin_offset[k + 1]; ++i)
            if (id[fw.pin_body[i]] < 0) id[fw.pin_body[i]] = next_id++;
    for (int b = 0; b < fw.bodies; ++b)
        if (id[b] < 0) id[b] = next_id++;
    PebbleGame game(fw.bodies);
    // A pin joining bodies b0, b1, ..., bm is 2m bars in a star from b0 (in 2D a pin removes 2 relative
    // degrees of freedom per extra body).
    for (int k : pin_order) {
        const int b0 = id[fw.pin_body[fw.pin_offset[k]]];
        for (int i = fw.pin_offset[k] + 1; i < fw.pin_offset[k + 1]; ++i) {
            game.add_bar(b0, id[fw.pin_body[i]]);
            game.add_bar(b0, id[fw.pin_body[i]]);
        }
    }
    r.independent = game.independent();
    r.redundant = game.redundant();
    r.floppy_modes = game.free_pebbles();
    if (fw.clamped) {
        r.d = game.gatherable_on_pair(id[fw.bottom()], id[fw.top()]) - 3;
        r.rigid_spanning = r.d == 0;
        r.carries_shear = r.d < 3;
        r.floppy_grounded = r.floppy_modes - 3;
        r.floppy_both_grounded = r.floppy_modes - 3 - r.d;
        const auto comp = pin_components(fw);
        r.connected_spanning = comp[fw.bottom()] == comp[fw.top()];
    }
    // Rigid clusters: a rigid cluster is connected through its pins, so testing every pair of bodies that share
    // a pin (would one more bar between them be redundant? a rank question, so it does not depend on which
    // star of bars stands for a shared pin) and condensing what each test finds rigid leaves one condensed
    // body per cluster.
    for (int k : pin_order)
        for (int i = fw.pin_offset[k]; i < fw.pin_offset[k + 1]; ++i)
            for (int j = i + 1; j < fw.pin_offset[k + 1]; ++j) {
                const int a = id[fw.pin_body[i]], b = id[fw.pin_body[j]];
                if (game.root(a) != game.root(b)) game.rigidly_connected(a, b);
            }
    std::vector<int> root(fw.bodies);
    for (int i = 0; i < fw.bodies; ++i) root[i] = game.root(id[i]);
    r.cluster = relabel(root);
    std::vector<int> size;
    for (int i = 0; i < fw.fibers; ++i) {
        if (r.cluster[i] >= static_cast<int>(size.size())) size.resize(r.cluster[i] + 1, 0);
        ++size[r.cluster[i]];
    }
    r.clusters = fw.bodies == 0 ? 0 : *std::max_element(r.cluster.begin(), r.cluster.end()) + 1;
    r.largest_cluster = size.empty() ? 0 : *std::max_element(size.begin(), size.end());
    return r;
}

}  // namespace fibernet
