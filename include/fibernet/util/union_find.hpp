#pragma once
// Disjoint sets with path halving; the smaller root becomes the representative, so a set's representative is its
// smallest member and results do not depend on the order of the unions (crosslink clusters, supernodes, bundles,
// pin merging, the pore graph's contracted vertices and components).
#include <algorithm>
#include <numeric>
#include <vector>

namespace fibernet {

struct UnionFind {
    std::vector<int> parent;
    explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
    int find(int i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    }
    // True if a and b were in different sets.
    bool unite(int a, int b) {
        a = find(a), b = find(b);
        if (a == b) return false;
        parent[std::max(a, b)] = std::min(a, b);
        return true;
    }
};

}  // namespace fibernet
