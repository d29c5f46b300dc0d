#pragma once
// The (3,3) pebble game for 2D body-and-bar frameworks (Lee & Streinu 2008; Jacobs & Thorpe 1995 for the
// idea). Each body carries 3 pebbles (its degrees of freedom); a bar between two bodies is independent iff
// 4 pebbles can be gathered on its two ends, and then it takes one of them. In 2D a pin between two bodies
// is two bars (DESIGN.md §2), so a body-and-pin framework is played as a body-and-bar one.
//
// Speed: every pebble search that fails visits a set R that holds exactly 3 free pebbles and has no out-edge
// leaving it, so R spans 3|R| - 3 bars: R is rigid. A rigid set of bodies moves as one body, so R is
// condensed into one body with 3 free pebbles (union-find). Each body is condensed at most once, so failed
// searches cost O(n) in total, and later bars inside a condensed body are rejected without a search.
// For l = k = 3 the rigid components are vertex-disjoint (Lee & Streinu 2008, Thm. 5), so "the rigid cluster
// of a body" is well defined.
#include <vector>

namespace fibernet {

class PebbleGame {
public:
    explicit PebbleGame(int bodies = 0);

    int add_body();
    int num_bodies() const { return static_cast<int>(parent_.size()); }

    // Plays one bar between bodies a != b; true if it is independent (it then covers one pebble).
    bool add_bar(int a, int b);

    int independent() const { return independent_; }
    int redundant() const { return redundant_; }
    // Free pebbles = degrees of freedom left = 3 * bodies - independent bars (trivial motions included).
    long free_pebbles() const { return 3L * num_bodies() - independent_; }

    // True if a further bar between a and b would be redundant, i.e. a and b lie in one rigid cluster.
    // Condenses the rigid region it finds; the bar itself is not added.
    bool rigidly_connected(int a, int b);

    // Most pebbles that can be gathered on {a, b} (3..6); 3 + the number of independent bars that could
    // still be added between them, i.e. the relative degrees of freedom of b with a held fixed is this - 3.
    int gatherable_on_pair(int a, int b);

    // Representative of the condensed body that holds b (same value <=> known to be mutually rigid).
    int root(int b);

private:
    int pebbles(int r) const { return 3 - outdeg_[r]; }
    // Searches from root r for a free pebble on a root other than the blocked ones; moves it to r.
    bool search(int r);
    // Gathers 4 free pebbles on roots ra != rb; false (after condensing the failed search's region into one rigid
    // body) when it cannot: then ra and rb are rigidly connected.
    bool gather_four(int ra, int rb);
    void condense_visited();

    std::vector<int> parent_;
    std::vector<int> out_;       // 3 slots per body: heads of the bars its pebbles cover (body ids)
    std::vector<unsigned char> outdeg_;
    std::vector<unsigned> mark_;  // visit stamp per body
    unsigned stamp_ = 0;
    std::vector<int> pred_, pred_slot_, stack_, visited_;
    int independent_ = 0, redundant_ = 0;
};

}  // namespace fibernet
