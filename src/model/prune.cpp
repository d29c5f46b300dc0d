#include "fibernet/model/prune.hpp"

#include <queue>

namespace fibernet {

std::vector<char> wrapping_fibers(const Network& net) {
    const int n = static_cast<int>(net.fibers.size());
    std::vector<char> wraps(n, 0);
    if (!net.periodic) return wraps;
    // Crosslink graph with image offsets: crossing (f1, f2, image) places f2 at offset(f1) + image relative to f1's
    // frame (the point on f1 equals the point on f2 shifted by L * image). A cycle with non-zero net offset wraps.
    std::vector<std::vector<std::pair<int, Eigen::Vector2i>>> adj(n);
    for (const auto& c : net.crossings)
        if (c.crosslink) {
            adj[c.f1].push_back({c.f2, c.image});
            adj[c.f2].push_back({c.f1, -c.image});
        }
    std::vector<char> seen(n, 0);
    std::vector<Eigen::Vector2i> off(n, Eigen::Vector2i::Zero());
    std::vector<int> members;
    for (int s = 0; s < n; ++s) {
        if (seen[s]) continue;
        members.clear();
        bool wrap = false;
        std::queue<int> q;
        q.push(s);
        seen[s] = 1;
        while (!q.empty()) {
            int f = q.front();
            q.pop();
            members.push_back(f);
            for (const auto& [g, img] : adj[f]) {
                const Eigen::Vector2i o = off[f] + img;
                if (!seen[g]) {
                    seen[g] = 1;
                    off[g] = o;
                    q.push(g);
                } else if (o != off[g]) {
                    wrap = true;
                }
            }
        }
        if (wrap)
            for (int f : members) wraps[f] = 1;
    }
    return wraps;
}

Network prune(const Network& net, const PruneOptions& opt, std::vector<int>* kept_out) {
    const int n = static_cast<int>(net.fibers.size());
    std::vector<char> keep(n, 1);
    if (opt.nonspanning && net.periodic) {
        auto w = wrapping_fibers(net);
        for (int f = 0; f < n; ++f) keep[f] = w[f];
    }
    if (opt.dangling) {
        // Peel fibers with < 2 crosslinks to kept fibers until none is left (the 2-core of the crosslink multigraph).
        std::vector<int> degree(n, 0);
        std::vector<std::vector<int>> adj(n);
        for (const auto& c : net.crossings)
            if (c.crosslink && keep[c.f1] && keep[c.f2]) {
                ++degree[c.f1], ++degree[c.f2];
                adj[c.f1].push_back(c.f2);
                adj[c.f2].push_back(c.f1);
            }
        std::queue<int> q;
        for (int f = 0; f < n; ++f)
            if (keep[f] && degree[f] < 2) q.push(f), keep[f] = 0;
        while (!q.empty()) {
            int f = q.front();
            q.pop();
            for (int g : adj[f])
                if (keep[g] && --degree[g] < 2) keep[g] = 0, q.push(g);
        }
    }
    Network out;
    out.L = net.L;
    out.periodic = net.periodic;
    out.seed = net.seed, out.q = net.q, out.pl = net.pl;
    std::vector<int> index(n, -1), kept;
    for (int f = 0; f < n; ++f)
        if (keep[f]) {
            index[f] = static_cast<int>(out.fibers.size());
            out.fibers.push_back(net.fibers[f]);
            kept.push_back(f);
        }
    for (const auto& c : net.crossings) {
        if (keep[c.f1] && keep[c.f2]) {
            Crossing d = c;
            d.f1 = index[c.f1], d.f2 = index[c.f2];
            out.crossings.push_back(d);
        } else if (c.crosslink && keep[c.f1] != keep[c.f2]) {
            // The kept fiber keeps a node where the pruned one was pinned: its discretization stays the same.
            if (keep[c.f1]) out.fibers[index[c.f1]].breakpoints.push_back(c.s1);
            else out.fibers[index[c.f2]].breakpoints.push_back(c.s2);
        }
    }
    if (kept_out) *kept_out = kept;
    return out;
}

}  // namespace fibernet
