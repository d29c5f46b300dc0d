#include "fibernet/wet/active_set.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iterator>
#include <map>
#include <memory>
#include <limits>
#include <mutex>
#include <numeric>
#include <unordered_map>
#include <set>
#include <utility>

#include "fibernet/util/hash.hpp"
#include "fibernet/util/parallel.hpp"
#include "fibernet/util/stopwatch.hpp"
#include "fibernet/wet/wet_region.hpp"
#include "fibernet/wet/wetting.hpp"

namespace fibernet {

namespace {
std::string format_g(double g) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2e", g);
    return buf;
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Moves side s of b one segment in direction dir (+1 / -1), keeping fiber 2's image consistent with the frame,
// which is anchored at fiber 1's home start node (bridge.hpp).
void move(const Model& m, Bridge& b, int s, int dir) {
    const FiberChain& ch = m.chains[s == 0 ? b.f1 : b.f2];
    int& k = s == 0 ? b.k1 : b.k2;
    const Eigen::Vector2i sh = m.segments[ch.segments[dir > 0 ? k : k - 1]].shift;
    // Side 0 re-anchors the frame at its new start node; side 1 carries its own image along its chain.
    if (s == 0) b.image += dir > 0 ? Eigen::Vector2i(-sh) : sh;
    else b.image += dir > 0 ? sh : Eigen::Vector2i(-sh);
    k += dir;
}

// Side s of b: its home segment's index on the fiber and the fiber's number of segments.
std::pair<int, int> home_on_fiber(const Model& m, const Bridge& b, int s) {
    return {s == 0 ? b.k1 : b.k2, static_cast<int>(m.chains[s == 0 ? b.f1 : b.f2].segments.size())};
}

using Key = std::array<int, 6>;  // a segment pair
Key key(const Bridge& b) { return {b.f1, b.f2, b.k1, b.k2, b.image.x(), b.image.y()}; }
std::array<int, 7> full_key(const Bridge& b) { return {b.f1, b.f2, b.k1, b.k2, b.image.x(), b.image.y(), b.locked}; }
}  // namespace

namespace {
struct SegGeom {
    std::vector<int> fiber, pos;
    std::vector<Eigen::Vector2d> P, D;
};

SegGeom seg_geom(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    const int ns = static_cast<int>(m.segments.size());
    SegGeom g;
    g.fiber.resize(ns), g.pos.resize(ns), g.P.resize(ns), g.D.resize(ns);
    for (size_t f = 0; f < m.chains.size(); ++f)
        for (size_t k = 0; k < m.chains[f].segments.size(); ++k)
            g.fiber[m.chains[f].segments[k]] = static_cast<int>(f), g.pos[m.chains[f].segments[k]] = static_cast<int>(k);
    for (int e = 0; e < ns; ++e) {
        const Segment& s = m.segments[e];
        g.P[e] = x.segment<2>(2 * s.i);
        g.D[e] = x.segment<2>(2 * s.j) - g.P[e] + B * s.shift.cast<double>();
    }
    return g;
}

// Calls visit(a, b, Pb) for every pair of segments of different fibers sharing no node whose midpoints are within
// (la + lb) / 2 + extra, with Pb the start of b at its image nearest to a. Cell list in reduced coordinates.
// only (one flag per segment, may be null): pairs with at least one flagged segment.
template <class Visit>
void near_pairs(const Model& m, const SegGeom& g, const Eigen::Matrix2d& B, double extra, const std::vector<char>* only,
                Visit visit) {
    const int ns = static_cast<int>(m.segments.size());
    const Eigen::Matrix2d Bi = B.inverse();
    std::vector<Eigen::Vector2d> U(ns);
    double lmax = 0;
    for (int e = 0; e < ns; ++e) {
        lmax = std::max(lmax, g.D[e].norm());
        U[e] = Bi * (g.P[e] + 0.5 * g.D[e]);
        if (m.box.periodic) U[e] = U[e].array() - U[e].array().floor();
    }
    Eigen::JacobiSVD<Eigen::Matrix2d> svd(Bi);
    const double reach = svd.singularValues()(0) * (lmax + extra);
    Eigen::Vector2d lo(0, 0), hi(1, 1);
    if (!m.box.periodic && ns > 0) {
        lo = hi = U[0];
        for (const auto& u : U) lo = lo.cwiseMin(u), hi = hi.cwiseMax(u);
    }
    const Eigen::Vector2d span = (hi - lo).cwiseMax(1e-300);
    // At most ~4 cells per segment (and 4096 a side): a sparse network in a large box would otherwise allocate up to
    // 4096^2 cells on every search (170 MB at L = 2000 with 2000 fibers). Fewer, larger cells stay correct.
    const int most = std::max(1, static_cast<int>(std::floor(std::sqrt(4.0 * ns))));
    int nc[2];
    for (int c = 0; c < 2; ++c)
        nc[c] = std::max(1, std::min({4096, most, static_cast<int>(std::floor(span[c] / std::max(reach, 1e-300)))}));
    if (m.box.periodic && (nc[0] < 3 || nc[1] < 3)) nc[0] = nc[1] = 1;  // small box: all pairs
    auto cell_of = [&](const Eigen::Vector2d& u, int c) {
        return std::min(nc[c] - 1, std::max(0, static_cast<int>((u[c] - lo[c]) / span[c] * nc[c])));
    };
    // Cells as one bucketed array (segments in increasing order within a cell): up to ~1e5 cells at 1e4 fibers, which
    // as separate vectors cost an allocation each on every search.
    const size_t ncell = static_cast<size_t>(nc[0]) * nc[1];
    std::vector<int> cell_start(ncell + 1, 0), cell_items(ns), home(ns);
    for (int e = 0; e < ns; ++e) ++cell_start[(home[e] = cell_of(U[e], 0) + nc[0] * cell_of(U[e], 1)) + 1];
    for (size_t c = 0; c < ncell; ++c) cell_start[c + 1] += cell_start[c];
    {
        std::vector<int> next(cell_start.begin(), cell_start.end() - 1);
        for (int e = 0; e < ns; ++e) cell_items[next[home[e]]++] = e;
    }
    auto test = [&](int a, int b) {
        if (g.fiber[a] == g.fiber[b]) return;
        const Segment &sa = m.segments[a], &sb = m.segments[b];
        if (sa.i == sb.i || sa.i == sb.j || sa.j == sb.i || sa.j == sb.j) return;  // meet at a shared node
        Eigen::Vector2d Pb = g.P[b];
        if (m.box.periodic) {
            const Eigen::Vector2d w = Bi * (g.P[b] + 0.5 * g.D[b] - g.P[a] - 0.5 * g.D[a]);
            Pb -= B * w.array().round().matrix();
        }
        visit(a, b, Pb);
    };
    const bool all = nc[0] == 1 && nc[1] == 1;
    // Calls f(b) for every segment b in the cells around cell (cx, cy) (wrapped in a periodic box).
    auto around = [&](int cx, int cy, auto f) {
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                if (all && (dx || dy)) continue;
                int X = cx + dx, Y = cy + dy;
                if (m.box.periodic) X = (X + nc[0]) % nc[0], Y = (Y + nc[1]) % nc[1];
                else if (X < 0 || Y < 0 || X >= nc[0] || Y >= nc[1]) continue;
                const int c = X + nc[0] * Y;
                for (int k = cell_start[c]; k < cell_start[c + 1]; ++k) f(cell_items[k]);
            }
    };
    if (only) {  // from the flagged segments alone, each pair once (a flagged pair from its lower index)
        for (int a = 0; a < ns; ++a)
            if ((*only)[a])
                around(cell_of(U[a], 0), cell_of(U[a], 1), [&](int b) {
                    if (b != a && !((*only)[b] && b < a)) test(std::min(a, b), std::max(a, b));
                });
        return;
    }
    for (int cy = 0; cy < nc[1]; ++cy)
        for (int cx = 0; cx < nc[0]; ++cx)
            for (int k = cell_start[cx + nc[0] * cy]; k < cell_start[cx + nc[0] * cy + 1]; ++k) {
                const int a = cell_items[k];
                around(cx, cy, [&](int b) {
                    if (b > a) test(a, b);
                });
            }
}

bool intersects(const Eigen::Vector2d& Pa, const Eigen::Vector2d& Da, const Eigen::Vector2d& Pb, const Eigen::Vector2d& Db) {
    const double den = cross2(Da, Db);
    if (den == 0) return false;
    const double t = cross2(Pb - Pa, Db) / den, u = cross2(Pb - Pa, Da) / den;
    return t >= 0 && t < 1 && u >= 0 && u < 1;
}

double point_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& P, const Eigen::Vector2d& D) {
    const double t = std::min(1.0, std::max(0.0, (p - P).dot(D) / D.squaredNorm()));
    return (P + t * D - p).norm();
}

struct Contact {
    double sin_angle, distance, overlap;  // overlap: length of b's projection onto a inside a
};
Contact contact(const Eigen::Vector2d& Pa, const Eigen::Vector2d& Da, const Eigen::Vector2d& Pb, const Eigen::Vector2d& Db) {
    Contact c;
    c.sin_angle = std::abs(cross2(Da, Db)) / (Da.norm() * Db.norm());
    c.distance = intersects(Pa, Da, Pb, Db) ? 0.0
                 : std::min({point_segment(Pa, Pb, Db), point_segment(Pa + Da, Pb, Db), point_segment(Pb, Pa, Da),
                             point_segment(Pb + Db, Pa, Da)});
    const double la = Da.norm();
    const Eigen::Vector2d u = Da / la;
    const double t0 = (Pb - Pa).dot(u), t1 = (Pb + Db - Pa).dot(u);
    c.overlap = std::max(0.0, std::min(la, std::max(t0, t1)) - std::max(0.0, std::min(t0, t1)));
    return c;
}
}  // namespace

namespace {
// The searches below on a segment geometry computed once (update_bridges runs both at the same state).
std::vector<Bridge> crossings_of(const Model& m, const SegGeom& g, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                 const std::vector<char>* only) {
    std::vector<Bridge> out;
    near_pairs(m, g, B, 0.0, only, [&](int a, int b, const Eigen::Vector2d& Pb) {
        if (intersects(g.P[a], g.D[a], Pb, g.D[b]))
            out.push_back(make_bridge(m, x, B, g.fiber[a], g.pos[a], g.fiber[b], g.pos[b]));
    });
    return out;
}

std::vector<Bridge> contacts_of(const Model& m, const SegGeom& g, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                double distance, double angle_deg, const std::vector<char>* only) {
    const double smax = std::sin(angle_deg * M_PI / 180);
    std::vector<Bridge> out;
    near_pairs(m, g, B, distance, only, [&](int a, int b, const Eigen::Vector2d& Pb) {
        // The angle first: it rejects most pairs before the four point-segment distances.
        if (std::abs(cross2(g.D[a], g.D[b])) / (g.D[a].norm() * g.D[b].norm()) > smax) return;
        const Contact c = contact(g.P[a], g.D[a], Pb, g.D[b]);
        const double lmin = std::min(g.D[a].norm(), g.D[b].norm());
        if (c.sin_angle <= smax && c.distance <= distance && c.overlap >= 0.5 * lmin) {
            Bridge br = make_bridge(m, x, B, g.fiber[a], g.pos[a], g.fiber[b], g.pos[b]);
            br.locked = true;
            out.push_back(br);
        }
    });
    return out;
}
}  // namespace

std::vector<Bridge> segment_crossings(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                      const std::vector<char>* only) {
    return crossings_of(m, seg_geom(m, x, B), x, B, only);
}

std::vector<Bridge> segment_contacts(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, double distance,
                                     double angle_deg, const std::vector<char>* only) {
    return contacts_of(m, seg_geom(m, x, B), x, B, distance, angle_deg, only);
}

namespace {
// Excluded volume (ActiveSetOptions::bundle_partners): the other fibers each candidate segment already lies along (its
// aligned bridges), so that a new aligned bridge can be refused where a segment has its share. Only the candidates'
// segments are indexed.
class PartnerCap {
public:
    PartnerCap(const Model& m, const SegGeom& geom, double sin_c, int cap) : m_(m), geom_(geom), sin_c_(sin_c), cap_(cap) {}

    void index(const std::vector<Bridge>& bridges, const std::vector<Bridge>& crossings,
               const std::vector<Bridge>& contacts) {
        if (cap_ <= 0) return;
        std::vector<int> cand;
        for (const auto* list : {&crossings, &contacts})
            for (const Bridge& c : *list) cand.push_back(seg_of(c.f1, c.k1)), cand.push_back(seg_of(c.f2, c.k2));
        std::sort(cand.begin(), cand.end());
        cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
        auto is_cand = [&](int s) { return std::binary_search(cand.begin(), cand.end(), s); };
        for (const Bridge& b : bridges) {
            const int s1 = seg_of(b.f1, b.k1), s2 = seg_of(b.f2, b.k2);
            const bool c1 = is_cand(s1), c2 = is_cand(s2);
            if ((!c1 && !c2) || (!b.locked && !aligned(s1, s2))) continue;
            if (c1) add_partner(s1, b.f2);
            if (c2) add_partner(s2, b.f1);
        }
    }

    // True if the new bridge c may form; an aligned one is then counted on both its segments. Refused segment pairs
    // are counted once each (a pair can be both a crossing and a contact).
    bool admit(const Bridge& c, bool contact) {
        const int s1 = seg_of(c.f1, c.k1), s2 = seg_of(c.f2, c.k2);
        if (cap_ <= 0 || (!contact && !aligned(s1, s2))) return true;
        if (full(s1, c.f2) || full(s2, c.f1)) {
            refused_.insert({std::min(s1, s2), std::max(s1, s2)});
            return false;
        }
        add_partner(s1, c.f2), add_partner(s2, c.f1);
        return true;
    }

    int refused() const { return static_cast<int>(refused_.size()); }

private:
    int seg_of(int f, int k) const { return m_.chains[f].segments[k]; }
    bool aligned(int s1, int s2) const {
        return std::abs(cross2(geom_.D[s1], geom_.D[s2])) <= sin_c_ * geom_.D[s1].norm() * geom_.D[s2].norm();
    }
    void add_partner(int s, int f) {
        std::vector<int>& v = along_[s];
        if (std::find(v.begin(), v.end(), f) == v.end()) v.push_back(f);
    }
    bool full(int s, int other) const {
        const auto it = along_.find(s);
        if (it == along_.end()) return false;
        return static_cast<int>(it->second.size() - std::count(it->second.begin(), it->second.end(), other)) >= cap_;
    }

    const Model& m_;
    const SegGeom& geom_;
    const double sin_c_;
    const int cap_;
    std::unordered_map<int, std::vector<int>> along_;  // segment -> fibers it holds aligned bridges with
    std::set<std::pair<int, int>> refused_;
};

// One update of the bridge set at q (update_bridges): the existing bridges follow their crossings, lock or rupture,
// repeated ones merge, and new crossings and contacts form.
class BridgeUpdate {
public:
    BridgeUpdate(const NetworkEnergy& dry, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                 const ActiveSetOptions& opt, const FiberPairs* frozen, const std::vector<char>* moved)
        : m_(dry.model()), x_(dry.positions(q, F)), B_(F * m_.box.B0()), opt_(opt), frozen_(frozen), moved_(moved),
          rc_(opt.contact_distance > 0 ? opt.contact_distance : 2.0 / m_.aspect_ratio),
          sin_c_(std::sin(opt.contact_angle_deg * M_PI / 180)) {}

    // The existing bridges after the fibers moved; `settled`: q is an equilibrium (update_bridges).
    void follow(std::vector<Bridge>& bridges, bool settled, WetEvents& ev) const {
        std::vector<Bridge> kept;
        kept.reserve(bridges.size());
        std::vector<char> was_moved;  // per kept bridge: did it move in this update
        was_moved.reserve(bridges.size());
        int nodes8[8];
        for (Bridge b : bridges) {
            if (is_frozen(b.f1, b.f2) || (moved_ && (bridge_nodes(m_, b, nodes8), !any_moved(nodes8, 8)))) {
                // kept as it is: frozen (relax_wet, after cycling), or none of its nodes moved since the last update
                kept.push_back(b), was_moved.push_back(0);
                continue;
            }
            if (b.locked) {
                if (locked_holds(b)) kept.push_back(b), was_moved.push_back(0);
                else ++ev.ruptures;
                continue;
            }
            const int moves_before = ev.moves;
            CrossingPosition cp;
            if (!slide(b, cp, ev) || !lock_or_keep(b, cp, settled, ev)) {
                ++ev.ruptures;
                continue;
            }
            kept.push_back(b), was_moved.push_back(ev.moves != moves_before);
        }
        drop_repeated(kept, was_moved, bridges, ev);
    }

    // New crossings and contacts (ActiveSetOptions::form_new).
    void form(std::vector<Bridge>& bridges, WetEvents& ev) const {
        // Only segments with a node that moved can cross or touch anything new.
        std::vector<char> seg_moved;
        if (moved_) {
            seg_moved.resize(m_.segments.size());
            for (size_t e = 0; e < m_.segments.size(); ++e) {
                const int n[2] = {m_.segments[e].i, m_.segments[e].j};
                seg_moved[e] = any_moved(n, 2);
            }
        }
        const std::vector<char>* only = moved_ ? &seg_moved : nullptr;
        const SegGeom geom = seg_geom(m_, x_, B_);
        const std::vector<Bridge> crossings = crossings_of(m_, geom, x_, B_, only);
        const std::vector<Bridge> contacts = contacts_of(m_, geom, x_, B_, rc_, opt_.contact_angle_deg, only);
        Neighbours near(crossings, contacts, bridges);
        PartnerCap cap(m_, geom, sin_c_, opt_.bundle_partners);
        cap.index(bridges, crossings, contacts);
        for (const Bridge& c : crossings) {
            if (near.known_crossing(c) || is_frozen(c.f1, c.f2) || dry_pair(c.f1, c.f2) || near_fiber_end(c)) continue;
            if (!cap.admit(c, false)) continue;
            near.note(c);
            bridges.push_back(c);
            ++ev.formed;
        }
        for (const Bridge& c : contacts) {
            if (near.partnered(c) || is_frozen(c.f1, c.f2)) continue;
            if (!cap.admit(c, true)) continue;
            near.note(c);
            bridges.push_back(c);
            ++ev.formed;
        }
        ev.capped = cap.refused();
    }

private:
    // Existing bridges by fiber pair and image: a crossing on or next to a bridged pair is that bridge's (a crossing
    // at a node is found on either side of it); a contact needs both its segments free towards the other fiber. Only
    // the fiber pairs of the candidates are looked up, so only their bridges are indexed (a local round's candidates
    // are few, the bridges of a 1e4-fiber network ~4e4).
    class Neighbours {
    public:
        Neighbours(const std::vector<Bridge>& crossings, const std::vector<Bridge>& contacts,
                   const std::vector<Bridge>& bridges) {
            std::vector<std::pair<int, int>> pairs;
            for (const auto* list : {&crossings, &contacts})
                for (const Bridge& c : *list) pairs.push_back({std::min(c.f1, c.f2), std::max(c.f1, c.f2)});
            std::sort(pairs.begin(), pairs.end());
            pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
            for (const Bridge& b : bridges)
                if (std::binary_search(pairs.begin(), pairs.end(),
                                       std::make_pair(std::min(b.f1, b.f2), std::max(b.f1, b.f2))))
                    note(b);
        }
        void note(const Bridge& b) {
            near_[{b.f1, b.f2, b.image.x(), b.image.y()}].push_back({b.k1, b.k2});
            partnered_.insert({b.f1, b.k1, b.f2}), partnered_.insert({b.f2, b.k2, b.f1});
        }
        bool known_crossing(const Bridge& c) {
            auto& v = near_[{c.f1, c.f2, c.image.x(), c.image.y()}];
            return std::any_of(v.begin(), v.end(), [&](const std::pair<int, int>& h) {
                return std::abs(h.first - c.k1) <= 1 && std::abs(h.second - c.k2) <= 1;
            });
        }
        bool partnered(const Bridge& c) const {
            return partnered_.count({c.f1, c.k1, c.f2}) || partnered_.count({c.f2, c.k2, c.f1});
        }

    private:
        std::map<std::array<int, 4>, std::vector<std::pair<int, int>>> near_;
        std::set<std::array<int, 3>> partnered_;  // (fiber, segment, other fiber) holding a bridge
    };

    bool is_frozen(int f1, int f2) const { return frozen_ && frozen_->count({std::min(f1, f2), std::max(f1, f2)}); }
    // A pair whose network crossing the wetting rule left dry gets no crossing bridge (contacts of aligned segments
    // form as for any pair: zipping fibers wet each other).
    bool dry_pair(int f1, int f2) const {
        return opt_.dry_pairs && opt_.dry_pairs->count({std::min(f1, f2), std::max(f1, f2)});
    }
    bool any_moved(const int* nodes, int k) const {
        for (int a = 0; a < k; ++a)
            if (nodes[a] >= 0 && (*moved_)[nodes[a]]) return true;
        return false;
    }
    // The home pair's segment vectors in the bridge frame.
    Contact pair_contact(const Bridge& b) const {
        const BridgeElement el = resolve(m_, b);
        const Vector16d X = element_coordinates(el, x_, B_);
        return contact(X.segment<2>(2), X.segment<2>(4) - X.segment<2>(2), X.segment<2>(10),
                       X.segment<2>(12) - X.segment<2>(10));
    }
    // A locked bridge holds while its pair stays aligned, in contact and overlapping (with a hysteresis of 2x).
    bool locked_holds(const Bridge& b) const {
        const Contact c = pair_contact(b);
        return c.sin_angle <= std::min(1.0, 2 * sin_c_) && c.distance <= 2 * rc_ && c.overlap > 0;
    }

    // Moves b's home pair to the segments that hold its crossing, one node at a time; false if the crossing slid off
    // a fiber end (rupture). cp: the crossing's position on the last home pair.
    bool slide(Bridge& b, CrossingPosition& cp, WetEvents& ev) const {
        const int limit = 4 + 2 * static_cast<int>(m_.chains[b.f1].segments.size() + m_.chains[b.f2].segments.size());
        bool alive = true;
        for (int it = 0; it < limit && alive; ++it) {
            const BridgeElement el = resolve(m_, b);
            cp = crossing_position(el, element_coordinates(el, x_, B_));
            if (!cp.defined) break;
            bool stepped = false;
            for (int s = 0; s < 2 && !stepped && alive; ++s) {
                const auto [k, nseg] = home_on_fiber(m_, b, s);
                // A move needs the crossing a margin past the node (hysteresis): the element of the new home measures
                // the other fiber's blend against a different segment line, so where both fibers' blend zones overlap
                // the move is not exactly energy neutral, and a bridge moved at z = 0+ could slide back and forth
                // across the node on every round (cycling; seen on 1 of 6 100-fiber benchmark networks). Within
                // the margin the home element still covers the crossing (its blend extends delta past each node).
                if (cp.z[s][0] < 0 && k == 0) {
                    if (cp.z[s][0] <= -cp.delta[s][0]) alive = false;  // off the fiber's start, weight zero
                } else if (cp.z[s][0] < -opt_.move_margin * cp.delta[s][0]) {
                    move(m_, b, s, -1), stepped = true;
                } else if (cp.z[s][1] > 0 && k + 1 == nseg) {
                    if (cp.z[s][1] >= cp.delta[s][1]) alive = false;  // off the fiber's end
                } else if (cp.z[s][1] > opt_.move_margin * cp.delta[s][1]) {
                    move(m_, b, s, +1), stepped = true;
                }
            }
            if (!stepped) break;
            ++ev.moves;
        }
        return alive;
    }

    // Lock an aligned bridge whose weight sits wholly on its home pair (no energy change). A nearly parallel pair
    // (crossing undefined, home-only weights) is locked if in contact, and ruptures (false) once the fibers separate.
    bool lock_or_keep(Bridge& b, const CrossingPosition& cp, bool settled, WetEvents& ev) const {
        const Contact c = pair_contact(b);
        const bool home_only = !cp.defined || (cp.z[0][0] >= cp.delta[0][0] && cp.z[0][1] <= -cp.delta[0][1] &&
                                               cp.z[1][0] >= cp.delta[1][0] && cp.z[1][1] <= -cp.delta[1][1]);
        if (home_only && c.sin_angle <= sin_c_ && c.distance <= rc_ && c.overlap > 0) {
            b.locked = true, ++ev.locked;
        } else if (settled && !cp.defined && (c.distance > 2 * rc_ || c.overlap == 0)) {
            // Only at an equilibrium: mid-solve (a cut round) two fibers being pulled parallel are often not yet in
            // contact, and rupturing them there made them cross, re-form and rupture again for hundreds of rounds.
            return false;
        }
        return true;
    }

    // Two bridges on one pair: keep the first. Found by sorting (key, position) pairs: a set of 4e4 keys (1e4 fibers)
    // cost more in allocations every round. After a local round (moved given) the set it starts from has no two
    // (relax_wet's first round is global, and every update leaves none), so only keys of bridges that moved can
    // repeat: only the bridges with such a key are sorted.
    void drop_repeated(const std::vector<Bridge>& kept, const std::vector<char>& was_moved,
                       std::vector<Bridge>& bridges, WetEvents& ev) const {
        std::vector<Key> moved_keys;
        if (moved_)
            for (size_t k = 0; k < kept.size(); ++k)
                if (was_moved[k]) moved_keys.push_back(key(kept[k]));
        std::sort(moved_keys.begin(), moved_keys.end());
        std::vector<std::pair<Key, int>> order;
        order.reserve(moved_ ? 2 * moved_keys.size() : kept.size());
        for (size_t k = 0; k < kept.size(); ++k) {
            const Key kk = key(kept[k]);
            if (!moved_ || std::binary_search(moved_keys.begin(), moved_keys.end(), kk))
                order.push_back({kk, static_cast<int>(k)});
        }
        std::sort(order.begin(), order.end());
        std::vector<char> duplicate(kept.size(), 0);
        for (size_t k = 1; k < order.size(); ++k)
            if (order[k].first == order[k - 1].first) duplicate[order[k].second] = 1;  // a later one of equal keys
        bridges.clear();
        for (size_t k = 0; k < kept.size(); ++k) {
            if (!duplicate[k]) bridges.push_back(kept[k]);
            else ++ev.merged;
        }
    }

    // The move margin at fiber ends too: a crossing within it of an end forms no bridge. Such a bridge has under half
    // its weight, its crossing can slide off the end (rupture) and back in (form) on alternate rounds (cycling; seen
    // on a 100-fiber benchmark network).
    bool near_fiber_end(const Bridge& c) const {
        const BridgeElement el = resolve(m_, c);
        const CrossingPosition cp = crossing_position(el, element_coordinates(el, x_, B_));
        bool near_end = false;
        for (int s = 0; s < 2 && cp.defined; ++s) {
            const auto [k, nseg] = home_on_fiber(m_, c, s);
            near_end = near_end || (k == 0 && cp.z[s][0] < opt_.move_margin * cp.delta[s][0]) ||
                       (k + 1 == nseg && cp.z[s][1] > -opt_.move_margin * cp.delta[s][1]);
        }
        return near_end;
    }

    const Model& m_;
    const Eigen::VectorXd x_;
    const Eigen::Matrix2d B_;
    const ActiveSetOptions& opt_;
    const FiberPairs* frozen_;
    const std::vector<char>* moved_;
    const double rc_, sin_c_;
};
}  // namespace

WetEvents update_bridges(const NetworkEnergy& dry, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
                         std::vector<Bridge>& bridges, const ActiveSetOptions& opt, const FiberPairs* frozen,
                         bool settled, const std::vector<char>* moved) {
    const BridgeUpdate update(dry, q, F, opt, frozen, moved);
    WetEvents ev;
    update.follow(bridges, settled, ev);
    if (opt.form_new) update.form(bridges, ev);
    return ev;
}

namespace {
using Signature = std::vector<std::array<int, 7>>;  // a bridge set, sorted

Signature signature(const std::vector<Bridge>& bs) {
    Signature v;
    for (const Bridge& b : bs) v.push_back(full_key(b));
    std::sort(v.begin(), v.end());
    return v;
}

std::uint64_t hash_of(const Signature& sg) {
    std::uint64_t h = kFnvOffset;
    for (const auto& a : sg)
        for (int v : a) h = fnv1a(h, static_cast<std::uint32_t>(v));
    return h;
}

// The set after each round (0: start), as a hash, and in full for the last kKeep rounds only: with short rounds a
// large network runs hundreds of rounds of ~1e4-1e5 bridges each. Repeats are found by hash (64 bits); the toggling
// bridges are named from this round's change (the previous set is always kept).
struct SetHistory {
    static constexpr size_t kKeep = 16;
    std::vector<Signature> sets;
    std::vector<std::uint64_t> hashes;
    std::vector<int> round_of;  // the round after which each entry was recorded

    explicit SetHistory(Signature first) { restart(std::move(first), 0); }
    void restart(Signature sg, int round) {
        const std::uint64_t h = hash_of(sg);
        sets.assign(1, std::move(sg)), hashes.assign(1, h), round_of.assign(1, round);
    }
    void remember(Signature sg, std::uint64_t h, int round) {
        hashes.push_back(h);
        sets.push_back(std::move(sg));
        round_of.push_back(round);
        if (sets.size() > kKeep) Signature().swap(sets[sets.size() - kKeep - 1]);
    }
    bool kept(size_t i) const { return i + kKeep >= sets.size(); }
    const Signature& last() const { return sets.back(); }
};

// The active-set loop of relax_wet (active_set.hpp): rounds of solves on the current bridge set, each followed by an
// update of the set, until the set is stable at an equilibrium, cycles, or the rounds run out.
class ActiveSetLoop {
public:
    ActiveSetLoop(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const WetParams& params,
                  std::vector<Bridge> bridges, Solver& solver, Eigen::VectorXd& q, const ActiveSetOptions& opt)
        : dry_(dry), F_(F), params_(params), bridges_(std::move(bridges)), solver_(solver), q_(q), opt_(opt),
          history_(signature(bridges_)), so_(solver.options()), budget_(so_.max_iter), restore_{so_, so_},
          // With beta = 0 the bridges carry no energy: one uncapped solve is the dry one, bit for bit (issue 6).
          cap_(opt.round_iterations > 0 && opt.round_iterations < budget_ && params.beta > 0), capped_(cap_),
          // Local rounds were designed and measured with Newton (docs/wet.md, "Local rounds").
          use_local_(opt.local_fraction > 0 && params.beta > 0 && solver.capabilities().newton_steps) {}

    ActiveSetResult run() {
        // max_rounds bounds the global rounds; local ones are cheap and many (1253 of 1341 at 1e4 fibers), bounded by
        // 10 x max_rounds in all.
        for (int round = 1; global_rounds_ < opt_.max_rounds && round <= 10 * opt_.max_rounds; ++round)
            if (!round_done(round)) break;
        if (!r_.stable && !r_.cycling && r_.message.empty())  // every round used, the last one possibly breaking a cycle
            r_.message = "no stable bridge set after " + std::to_string(r_.rounds) + " rounds (" +
                         std::to_string(r_.rounds - r_.local_rounds) + " global; last solve: " +
                         to_string(r_.last.status) + ")";
        r_.bridges = std::move(bridges_);
        r_.frozen = std::move(frozen_);
        return std::move(r_);
    }

private:
    // One round: the solve, the update of the set, the test for an equilibrium, the next round's kind. False: the
    // loop ends (stable, cycling, or a failure), r_.message says why.
    bool round_done(int round) {
        r_.rounds = round;
        // The energy of this round's set: the one the last round's gradient was taken with, if there was one.
        std::unique_ptr<WetEnergy> Wp = next_ ? std::move(next_) : std::make_unique<WetEnergy>(dry_, F_, bridges_, params_);
        double t0 = wall_seconds();
        so_.max_iter = capped_ ? opt_.round_iterations : budget_;
        so_.warm_start = (resume_ && opt_.warm_start) || restore_.saved.warm_start;  // Newton: keep its adapted shift
        so_.ldl = (opt_.newton_ldl && params_.beta > 0) || restore_.saved.ldl;      // beta = 0: the dry solve, bit for bit
        const bool local = !region_.empty();
        RegionCounts rc;
        std::vector<char> moved_nodes;  // a local round: the nodes it moved, where alone the set can change
        if (local) {
            r_.last = solve_region(*Wp, rc, t0);
            moved_nodes.swap(region_);
            ++r_.local_rounds;
            r_.local_iterations += r_.last.iterations;
            r_.timings_local += r_.last.timings;
            r_.seconds_local += wall_seconds() - t0;
        } else {
            r_.last = solver_.minimize(*Wp, q_);
            ++global_rounds_;
        }
        r_.seconds_solve += wall_seconds() - t0;
        r_.solver_iterations += r_.last.iterations;
        r_.factorizations += r_.last.factorizations;
        r_.timings += r_.last.timings;
        // An iteration limit is not final: large motions (a fiber zipping onto another) make the set stale long before
        // the solve ends, so the set is updated and the solve continues with it. Other failures end the loop, but a
        // local round's only hands the next round to the whole network (its state is no worse than where it began).
        const bool limit = r_.last.status == SolveStatus::IterationLimit;
        resume_ = capped_ && limit;
        if (!r_.last.converged() && !limit && !local) {
            r_.message = "round " + std::to_string(round) + ": solver " + to_string(r_.last.status) + " (" +
                         r_.last.message + ")";
            return false;
        }
        const bool failed_local = local && !r_.last.converged() && !limit;
        t0 = wall_seconds();
        const WetEvents ev = update_bridges(dry_, q_, F_, bridges_, opt_, &frozen_, r_.last.converged(),
                                            local ? &moved_nodes : nullptr);
        r_.per_round.push_back(ev);
        Signature sig = signature(bridges_);
        r_.seconds_update += wall_seconds() - t0;
        r_.events.moves += ev.moves, r_.events.ruptures += ev.ruptures;
        r_.events.formed += ev.formed, r_.events.merged += ev.merged, r_.events.locked += ev.locked;
        r_.events.capped = ev.capped;  // a state count (the same candidates are refused every round), not a sum
        double gmax = 0;
        bool equilibrium = false;
        if (r_.last.converged() || use_local_) equilibrium = settled(local, failed_local, moved_nodes, sig, gmax);
        else g_valid_ = false;
        r_.seconds_events += wall_seconds() - t0;
        if (opt_.verbose) log_round(round, local, rc, gmax, ev);
        return decide(round, local, limit, equilibrium, std::move(sig));
    }

    struct RegionCounts {
        int size = 0, parts = 0;
    };

    // A local round: each part of the region on its own (wet_region.hpp), with its own line search and convergence.
    // The round's result: iterations summed, the worst status (a failure, else an iteration limit), the largest max|g|.
    SolveResult solve_region(WetEnergy& W, RegionCounts& rc, double t0) {
        incidence_for(W, inc_);  // usually already W's: built after the last round, when the region was chosen
        RegionState state(W, q_);
        const auto parts = region_parts(W, inc_, region_);
        r_.seconds_local_setup += wall_seconds() - t0;
        so_.warm_start = restore_.saved.warm_start;  // each part adapts its own shift
        // The parts on FIBERNET_THREADS threads, largest first: they share no element and each writes only its own
        // nodes (of q and of the shared state), so no part's solve depends on another's. The last part (in the parts'
        // order) is solved by the caller's solver, the others by solvers of the threads: a global round that resumes
        // a cut one warm-starts from the caller's solver's last shift, which must stay that of the last part, as when
        // the parts were solved one after another (solved by solvers of their own, a 1000-fiber run did not settle in
        // 1000 global rounds; docs/benchmarks.md). So the round is the same bit for bit on any number of threads.
        // Results are gathered in the parts' order. (One thread with Newton's verbose lines, which would interleave.)
        const int threads = so_.verbose ? 1 : std::max(1, std::min(thread_count(), static_cast<int>(parts.size())));
        while (static_cast<int>(part_solvers_.size()) < threads) part_solvers_.push_back(solver_.clone());
        std::vector<Solver*> pool;
        for (int k = 0; k < threads; ++k) part_solvers_[k]->options() = so_, pool.push_back(part_solvers_[k].get());
        std::mutex pool_mutex;
        std::vector<size_t> by_size(parts.size());
        std::iota(by_size.begin(), by_size.end(), size_t{0});
        std::stable_sort(by_size.begin(), by_size.end(),
                         [&](size_t x, size_t y) { return parts[x].size() > parts[y].size(); });
        std::vector<SolveResult> results(parts.size());
        std::vector<int> sizes(parts.size(), 0);
        std::vector<double> setup(parts.size(), 0.0);
        parallel_blocks(parts.size(), threads, 1, [] {}, [&](size_t lo, size_t hi) {
            Solver* mine = nullptr;
            {
                std::lock_guard<std::mutex> lock(pool_mutex);
                mine = pool.back();
                pool.pop_back();
            }
            for (size_t k = lo; k < hi; ++k) {
                const size_t i = by_size[k];
                const double ts = wall_seconds();
                WetRegion R(W, state, parts[i], inc_);
                setup[i] = wall_seconds() - ts;
                sizes[i] = R.size();
                if (R.size() == 0) continue;
                Eigen::VectorXd qa = R.restrict(q_);
                results[i] = (i + 1 == parts.size() ? static_cast<Solver&>(solver_) : *mine).minimize(R, qa);
                R.embed(qa, q_);
            }
            std::lock_guard<std::mutex> lock(pool_mutex);
            pool.push_back(mine);
        });
        SolveResult all;
        all.status = SolveStatus::Converged, all.solver = solver_.name();
        for (size_t i = 0; i < parts.size(); ++i) {
            r_.seconds_local_setup += setup[i];
            if (sizes[i] == 0) continue;
            rc.size += sizes[i], ++rc.parts;
            const SolveResult& p = results[i];
            all.iterations += p.iterations, all.factorizations += p.factorizations;
            all.ldl_retries += p.ldl_retries, all.evaluations += p.evaluations;
            all.timings += p.timings;
            all.grad_max = std::max(all.grad_max, p.grad_max);
            if (!p.converged() && (all.converged() || all.status == SolveStatus::IterationLimit))
                all.status = p.status, all.message = p.message;
        }
        if (all.converged()) all.message = "every part of the region converged";
        return all;
    }

    // The nodes of the bridges in `changed`, flagged in `flags`.
    void flag_nodes(const Signature& changed, std::vector<char>& flags) const {
        int nodes[8];
        for (const auto& k : changed) {
            Bridge b;
            b.f1 = k[0], b.f2 = k[1], b.k1 = k[2], b.k2 = k[3];
            bridge_nodes(dry_.model(), b, nodes);
            for (int node : nodes)
                if (node >= 0) flags[node] = 1;
        }
    }

    // Moves, locks and fade-out ruptures leave the energy unchanged near q: if the updated set's gradient at q is no
    // larger than the one the solver accepted, q is already an equilibrium of it (and beta = 0 stays bit for bit the
    // dry result). After a local round this is the whole network's gradient against the region's accepted one, so
    // stable still means an equilibrium of every coordinate. Also chooses the next round's region (region_).
    bool settled(bool local, bool failed_local, const std::vector<char>& moved_nodes, const Signature& sig,
                 double& gmax) {
        const double tg = wall_seconds();
        Signature changed;  // the bridges this round changed (both sets' entries)
        std::set_symmetric_difference(history_.last().begin(), history_.last().end(), sig.begin(), sig.end(),
                                      std::back_inserter(changed));
        next_ = std::make_unique<WetEnergy>(dry_, F_, bridges_, params_);
        WetEnergy& Wn = *next_;
        if (local && g_valid_) {
            // Only the region's nodes moved and only the changed bridges differ (update_bridges keeps the others in
            // order), so only the rows near them are recomputed: bit for bit the whole gradient, at the region's
            // cost, not the network's (the whole gradient was 96 of 962 s at 1e4 fibers).
            std::vector<char> touched(moved_nodes.size(), 0);
            flag_nodes(changed, touched);
            incidence_for(Wn, inc_);
            update_gradient(Wn, inc_, q_, moved_nodes, touched, g_);
        } else {
            Wn.gradient(q_, g_);
        }
        g_valid_ = true;
        gmax = g_.size() ? g_.cwiseAbs().maxCoeff() : 0.0;
        r_.seconds_gradient += wall_seconds() - tg;
        bool equilibrium = r_.last.converged() && gmax <= r_.last.grad_max * (1 + 1e-9);
        // A bridge formed without a torque at q (fibers crossing nearly parallel) leaves q an equilibrium but changes
        // the energy: the result's energy is the final set's.
        if (equilibrium && !changed.empty()) r_.last.energy = Wn.value(q_);
        // After a local round the set was updated only where nodes moved, but a rule that depends on the state being
        // an equilibrium (the rupture of nearly parallel pairs out of contact) applies everywhere: a global round (no
        // Newton step at an equilibrium, then a full update) decides.
        const bool confirm = local && equilibrium;
        if (confirm) equilibrium = false;
        // The next round: local on the part of the network that needs it, if that part is small enough, else global.
        // That part: the nodes with |g| above local_threshold x max|g| (and tol), and those of the bridges this round
        // changed (their torques are new), grown by local_hops elements.
        region_.clear();
        if (use_local_ && !equilibrium && !confirm && !failed_local && g_.size() > 0) {
            std::vector<char> hot = nodes_above(dry_, g_, std::max(restore_.saved.tol, opt_.local_threshold * gmax));
            flag_nodes(changed, hot);
            incidence_for(Wn, inc_);
            grow_region(Wn, inc_, hot, opt_.local_hops);
            int n_hot = 0;
            for (int i = 0; i < dry_.model().num_nodes(); ++i)
                n_hot += hot[i] ? (dry_.dof(i, 0) >= 0) + (dry_.dof(i, 1) >= 0) : 0;
            if (n_hot > 0 && n_hot <= opt_.local_fraction * static_cast<double>(g_.size())) region_.swap(hot);
        }
        return equilibrium;
    }

    void log_round(int round, bool local, const RegionCounts& rc, double gmax, const WetEvents& ev) const {
        std::fprintf(stderr,
                     "wet round %2d: %s%s in %d iterations (max|g| %.2e%s), %zu bridges after moves %d, ruptures %d, "
                     "formed %d, merged %d, locked %d%s\n",
                     round,
                     local ? ("local (" + std::to_string(rc.size) + " coordinates in " + std::to_string(rc.parts) +
                              " pieces) ").c_str()
                           : "",
                     to_string(r_.last.status).c_str(), r_.last.iterations, r_.last.grad_max,
                     // where the solver stopped (a local round: its region's), then the whole network's with the
                     // updated set, which decides the next round
                     g_valid_ ? ("; whole network with the updated set " + format_g(gmax)).c_str() : "",
                     bridges_.size(), ev.moves, ev.ruptures, ev.formed, ev.merged, ev.locked,
                     opt_.bundle_partners > 0 ? (", capped " + std::to_string(ev.capped)).c_str() : "");
    }

    // After the update: stop (stable, stalled, cycling: false) or go on, and whether the next round is cut.
    bool decide(int round, bool local, bool limit, bool equilibrium, Signature sig) {
        // Solves that use their whole budget (not cut by the round cap) and leave the set as it was continue the same
        // solve round after round; while max|g| halves from one such round to the next that is progress, but a solver
        // that stalls would repeat towards max_rounds (an L-BFGS run on a 90-fiber network ran 239 rounds of 500
        // iterations, max|g| stuck at 0.06-0.17). Two such rounds in a row without max|g| halving end the run
        // unconverged.
        const bool unchanged_limit = limit && !capped_ && !local && sig == history_.last();
        if (unchanged_limit && stalled_g_ < std::numeric_limits<double>::infinity() &&
            !(r_.last.grad_max <= 0.5 * stalled_g_)) {
            r_.message = "round " + std::to_string(round) + ": the solver stopped at its limit again (" +
                         r_.last.message + ", max|g| " + format_g(r_.last.grad_max) + " after " + format_g(stalled_g_) +
                         ") and the bridge set did not change: no progress towards an equilibrium";
            return false;
        }
        stalled_g_ = unchanged_limit ? r_.last.grad_max : std::numeric_limits<double>::infinity();
        if (equilibrium) {
            r_.stable = true;
            r_.message = "stable after " + std::to_string(round) + " round(s)" +
                         (r_.frozen_pairs ? " (" + std::to_string(r_.frozen_pairs) + " fiber pair(s) frozen after " +
                                                std::to_string(r_.cycles_broken) + " cycle(s))"
                                          : std::string());
            return false;
        }
        // A local round that left the set as it was is no repeat: the rest of the network has not been solved yet. The
        // next round is global: with no events left to chase, regions with held boundaries pass the residual from one
        // to the next (at 3000 fibers max|g| fell from 1.6e-2 to 1e-2 over 150 such rounds) where one global solve ends it.
        // That global round keeps the cap decided when the set last changed (below): uncapped if that change returned
        // to a set seen before, so that a toggle is judged after a finished solve. Resetting the cap here hid a cycle
        // (a bridge ruptured and re-formed by alternate cut global rounds, a quiet local round between each: 1000 fibers,
        // pl = 0.8, seed 4, beta = 0.1 ran 1300 rounds until the round limit; docs/wet.md, "Breaking a cycle").
        if (local && sig == history_.last()) {
            region_.clear();
            return true;
        }
        // The next round is capped only if this one changed the set to one not seen before: once it has settled, or
        // toggles (a bridge moving back and forth while the rest still moves), the solve finishes, and a repeat
        // after a finished solve is a cycle (below). Without this a 3000-fiber run toggled 3 bridges for 250 rounds.
        const std::uint64_t hs = hash_of(sig);
        const auto again_h = std::find(history_.hashes.rbegin(), history_.hashes.rend(), hs);  // the most recent
        capped_ = cap_ && again_h == history_.hashes.rend();
        if (!limit && again_h != history_.hashes.rend())
            return break_cycle(round, sig, static_cast<size_t>(history_.hashes.rend() - again_h) - 1);
        history_.remember(std::move(sig), hs, round);
        return true;
    }

    // The set after this round repeats the one after round j's entry: a cycle. Broken by freezing the toggling fiber
    // pairs (true: the rounds go on) while the budget lasts, else reported (false).
    bool break_cycle(int round, const Signature& sig, size_t j) {
        // Name what toggles: the bridges this round changed (it came back to the set after round j); if it changed
        // nothing, those in which the set after round j and the next different kept one differ.
        std::vector<std::array<int, 7>> diff;  // empty if the set did not change at all (a solver that wanders)
        std::set_symmetric_difference(history_.last().begin(), history_.last().end(), sig.begin(), sig.end(),
                                      std::back_inserter(diff));
        for (size_t k = j + 1; diff.empty() && history_.kept(j) && k < history_.sets.size(); ++k)
            std::set_symmetric_difference(history_.sets[j].begin(), history_.sets[j].end(), history_.sets[k].begin(),
                                          history_.sets[k].end(), std::back_inserter(diff));
        std::string which;
        for (size_t k = 0; k < diff.size() && k < 4; ++k)
            which += (k ? ", " : "") + std::string("fibers ") + std::to_string(diff[k][0]) + "/" +
                     std::to_string(diff[k][1]) + " segments " + std::to_string(diff[k][2]) + "/" +
                     std::to_string(diff[k][3]);
        const std::string what = "the bridge set after round " + std::to_string(round) + " repeats " +
                                 (history_.round_of[j] == 0 ? std::string("the initial one")
                                                            : "that after round " + std::to_string(history_.round_of[j])) +
                                 "; " + std::to_string(diff.size()) + " bridge entries toggle (" + which +
                                 (diff.size() > 4 ? ", ..." : "") + ")";
        // Break the cycle: the fiber pairs of the toggling bridges keep their current bridges from here on (no moves,
        // ruptures or new bridges between them), and the rounds go on. What follows is an equilibrium of the energy
        // with that set; the pairs are reported (frozen_pairs).
        const size_t before = frozen_.size();
        for (const auto& d : diff) frozen_.insert({std::min(d[0], d[1]), std::max(d[0], d[1])});
        // The budget grows with the set: at 1e4 fibers (44000 bridges) cycles turn up in several places of one run (4
        // and 6 in two runs of the benchmark network; docs/wet.md, "Breaking a cycle").
        const int budget_freezes = opt_.max_freezes + static_cast<int>(bridges_.size() /
                                                                      static_cast<size_t>(std::max(1, opt_.bridges_per_freeze)));
        if (r_.cycles_broken < budget_freezes && frozen_.size() > before) {
            ++r_.cycles_broken;
            r_.frozen_pairs = static_cast<int>(frozen_.size());
            // The frozen set starts a new history, and its rounds are cut again while it changes: left uncapped (as
            // after any repeat), the next global round of a 1e4-fiber run ran 500 iterations and moved 1263 bridges,
            // and the run took 913 s against 759 s.
            capped_ = cap_;
            if (opt_.verbose) std::fprintf(stderr, "wet round %2d: cycling (%s): fiber pairs frozen\n", round, what.c_str());
            history_.restart(sig, round);
            return true;
        }
        r_.cycling = true;
        r_.message = "cycling: " + what;
        return false;
    }

    const NetworkEnergy& dry_;
    const Eigen::Matrix2d F_;
    const WetParams& params_;
    std::vector<Bridge> bridges_;
    Solver& solver_;
    Eigen::VectorXd& q_;
    const ActiveSetOptions& opt_;
    ActiveSetResult r_;
    SetHistory history_;
    double stalled_g_ = std::numeric_limits<double>::infinity();  // max|g| of the last limit round that changed nothing
    FiberPairs frozen_;
    // The solver's options, restored on return; rounds are capped below its budget while the set keeps changing.
    SolverOptions& so_;
    const int budget_;
    struct Restore {
        SolverOptions& so;
        SolverOptions saved;
        ~Restore() { so = saved; }
    } restore_;
    const bool cap_;
    bool capped_;
    bool resume_ = false;  // the last round was cut at round_iterations: the next one resumes its solve
    const bool use_local_;
    std::vector<char> region_;  // non-empty: the next round is local, on these nodes
    ElementIncidence inc_;      // of the energy the next local round solves (segment and hinge rows built once)
    std::unique_ptr<WetEnergy> next_;
    std::vector<std::unique_ptr<Solver>> part_solvers_;  // local rounds: a solver per thread solving parts
    Eigen::VectorXd g_;     // the gradient at q of the next round's energy, if g_valid_ (taken after each round)
    bool g_valid_ = false;
    int global_rounds_ = 0;
};
}  // namespace

ActiveSetResult relax_wet(const NetworkEnergy& dry, const Eigen::Matrix2d& F, const WetParams& params,
                          std::vector<Bridge> bridges, Solver& solver, Eigen::VectorXd& q, const ActiveSetOptions& opt) {
    ActiveSetLoop loop(dry, F, params, std::move(bridges), solver, q, opt);
    return loop.run();
}

}  // namespace fibernet
