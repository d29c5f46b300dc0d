#include "fibernet/rigidity/pebble_game.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace fibernet {

PebbleGame::PebbleGame(int bodies) {
    for (int i = 0; i < bodies; ++i) add_body();
}

int PebbleGame::add_body() {
    const int id = num_bodies();
    parent_.push_back(id);
    out_.insert(out_.end(), 3, -1);
    outdeg_.push_back(0);
    mark_.push_back(0);
    pred_.push_back(-1);
    pred_slot_.push_back(-1);
    return id;
}

int PebbleGame::root(int b) {
    int r = b;
    while (parent_[r] != r) r = parent_[r];
    while (parent_[b] != r) {  // path compression
        const int next = parent_[b];
        parent_[b] = r;
        b = next;
    }
    return r;
}

bool PebbleGame::search(int r) {
    // Depth-first over the directed pebble graph (a body points at the bars its pebbles cover) from r, among
    // bodies not yet marked in this stamp; the first root with a free pebble gives it back along the path.
    stack_.clear();
    stack_.push_back(r);
    while (!stack_.empty()) {
        const int x = stack_.back();
        stack_.pop_back();
        for (int s = 0; s < outdeg_[x]; ++s) {
            const int y = root(out_[3 * x + s]);
            if (mark_[y] == stamp_) continue;
            mark_[y] = stamp_;
            visited_.push_back(y);
            pred_[y] = x;
            pred_slot_[y] = s;
            if (outdeg_[y] < 3) {
                // Reverse the path r -> ... -> y: y covers the last bar with its free pebble, each inner body
                // swaps its forward bar for the one behind it, and r's forward bar is released.
                out_[3 * y + outdeg_[y]++] = x;
                int cur = x, slot = s;
                while (cur != r) {
                    const int p = pred_[cur], ps = pred_slot_[cur];
                    out_[3 * cur + slot] = p;
                    cur = p, slot = ps;
                }
                out_[3 * r + slot] = out_[3 * r + outdeg_[r] - 1];
                --outdeg_[r];
                return true;
            }
            stack_.push_back(y);
        }
    }
    return false;
}

void PebbleGame::condense_visited() {
    // The failed searches from both ends visited a closed set holding exactly the 3 free pebbles on the two
    // ends: it spans 3|R| - 3 bars, hence it is rigid and becomes one body with those 3 pebbles.
    int free = 0;
    for (int x : visited_) free += pebbles(x);
    if (free != 3) throw std::logic_error("pebble game: failed region holds " + std::to_string(free) + " pebbles, not 3");
    const int z = visited_.front();
    for (int x : visited_) parent_[x] = z;
    outdeg_[z] = 0;
}

bool PebbleGame::gather_four(int ra, int rb) {
    while (pebbles(ra) + pebbles(rb) < 4) {
        if (++stamp_ == 0) std::fill(mark_.begin(), mark_.end(), 0), stamp_ = 1;
        mark_[ra] = mark_[rb] = stamp_;
        visited_.assign({ra, rb});
        const bool got = (pebbles(ra) < 3 && search(ra)) || (pebbles(rb) < 3 && search(rb));
        if (!got) {
            condense_visited();
            return false;
        }
    }
    return true;
}

bool PebbleGame::add_bar(int a, int b) {
    if (a == b) throw std::invalid_argument("pebble game: a bar needs two different bodies (got " + std::to_string(a) + ")");
    const int ra = root(a), rb = root(b);
    if (ra == rb || !gather_four(ra, rb)) {
        ++redundant_;
        return false;
    }
    const int tail = pebbles(ra) > 0 ? ra : rb;
    out_[3 * tail + outdeg_[tail]++] = tail == ra ? rb : ra;
    ++independent_;
    return true;
}

bool PebbleGame::rigidly_connected(int a, int b) {
    const int ra = root(a), rb = root(b);
    return ra == rb || !gather_four(ra, rb);
}

int PebbleGame::gatherable_on_pair(int a, int b) {
    const int ra = root(a), rb = root(b);
    if (ra == rb) return 3;
    for (int r : {ra, rb}) {
        while (pebbles(r) < 3) {
            if (++stamp_ == 0) std::fill(mark_.begin(), mark_.end(), 0), stamp_ = 1;
            mark_[ra] = mark_[rb] = stamp_;
            visited_.assign({ra, rb});
            if (!search(r)) break;
        }
    }
    return pebbles(ra) + pebbles(rb);
}

}  // namespace fibernet
