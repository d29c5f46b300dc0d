#include "fibernet/wet/smooth_wet_energy.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/parallel.hpp"
#include "fibernet/util/stopwatch.hpp"
#include "fibernet/wet/bundle_saturation.hpp"
#include "fibernet/wet/smooth_wet_region.hpp"

namespace fibernet {

namespace {

constexpr size_t kParallelMin = 4096;
constexpr size_t kChunk = 16384;

// The squared distance between the bounding boxes of a pair's two segments (X: their nodes): a lower bound of the
// segments' distance.
double box_gap_squared(const Vector8d& X) {
    const double ax0 = std::min(X[0], X[2]), ax1 = std::max(X[0], X[2]), ay0 = std::min(X[1], X[3]),
                 ay1 = std::max(X[1], X[3]);
    const double bx0 = std::min(X[4], X[6]), bx1 = std::max(X[4], X[6]), by0 = std::min(X[5], X[7]),
                 by1 = std::max(X[5], X[7]);
    const double gx = std::max({0.0, bx0 - ax1, ax0 - bx1}), gy = std::max({0.0, by0 - ay1, ay0 - by1});
    return gx * gx + gy * gy;
}

}  // namespace

SmoothWetEnergy::SmoothWetEnergy(const NetworkEnergy& dry, const Eigen::Matrix2d& F, SmoothWetParams params,
                                 FiberPairs dry_crossings, const Eigen::VectorXd& q)
    : dry_(dry),
      F_(F),
      params_(std::move(params)),
      dry_crossings_(std::move(dry_crossings)),
      list_(dry.model(), PairSupport(params_.pair), params_.skin),
      support_(params_.pair) {
    params_.pair.check("wet");
    if (params_.pattern_distance <= 0)
        params_.pattern_distance = 1.5 * params_.pair.contact + params_.pair.overlap_width + params_.pair.crossing_width;
    const Model& m = dry.model();
    seg_fiber_.assign(m.segments.size(), -1), seg_index_.assign(m.segments.size(), -1);
    for (size_t f = 0; f < m.chains.size(); ++f)
        for (size_t k = 0; k < m.chains[f].segments.size(); ++k) {
            seg_fiber_[m.chains[f].segments[k]] = static_cast<int>(f);
            seg_index_[m.chains[f].segments[k]] = static_cast<int>(k);
        }
    rebuild(q);
}

bool SmoothWetEnergy::wet_crossing(const SegmentPair& p) const {
    int f1 = seg_fiber_[p.a], f2 = seg_fiber_[p.b];
    if (f1 > f2) std::swap(f1, f2);
    return dry_crossings_.find({f1, f2}) == dry_crossings_.end();
}

void SmoothWetEnergy::local_dofs(const SegmentPair& p, int idx[8]) const {
    int node[4];
    Eigen::Vector2i shift[4];
    list_.nodes(p, node, shift);
    for (int a = 0; a < 8; ++a) idx[a] = dry_.dof(node[a / 2], a % 2);
}

std::uint64_t SmoothWetEnergy::key(const SegmentPair& p) {
    // 24 bits per segment, 8 per image component (images are within +-2 of a pair's first node).
    return (static_cast<std::uint64_t>(p.a) << 40) | (static_cast<std::uint64_t>(p.b) << 16) |
           (static_cast<std::uint64_t>(p.image.x() + 128) << 8) | static_cast<std::uint64_t>(p.image.y() + 128);
}

void SmoothWetEnergy::index_wet() const {
    const std::vector<SegmentPair>& P = list_.pairs();
    wet_.resize(P.size());
    for (size_t k = 0; k < P.size(); ++k) wet_[k] = wet_crossing(P[k]);
}

void SmoothWetEnergy::index_list() const {
    const std::vector<SegmentPair>& P = list_.pairs();
    auto patterned = [&](const SegmentPair& p) {
        const auto it = pattern_index_.find(key(p));
        return it != pattern_index_.end() ? it->second : -1;
    };
    const std::vector<int>& from = list_.origin();
    if (list_.origin_build() >= 0 && list_.origin_build() == indexed_build_ && from.size() == P.size()) {
        // An update of the list indexed last (a region's local solve): the kept pairs carry their indices over, only
        // the pairs found anew are looked up. A hash lookup per listed pair made this O(list) per local solve.
        std::vector<int>& pat = patterned_next_;
        std::vector<char>& wet = wet_next_;
        pat.resize(P.size()), wet.resize(P.size());
        for (size_t k = 0; k < P.size(); ++k) {
            const int o = from[k];
            pat[k] = o >= 0 ? patterned_[o] : patterned(P[k]);
            wet[k] = o >= 0 ? wet_[o] : static_cast<char>(wet_crossing(P[k]));
        }
        patterned_.swap(pat), wet_.swap(wet);
    } else {
        patterned_.resize(P.size());
        for (size_t k = 0; k < P.size(); ++k) patterned_[k] = patterned(P[k]);
        index_wet();
    }
    indexed_build_ = list_.builds();
}

double SmoothWetEnergy::support_distance(double L) const {
    return support_(L);
}

bool SmoothWetEnergy::beyond_support(const Vector8d& X) const {
    const double L = std::sqrt(std::max((X.segment<2>(2) - X.segment<2>(0)).squaredNorm(),
                                        (X.segment<2>(6) - X.segment<2>(4)).squaredNorm()));
    const double support = support_distance(L);
    return box_gap_squared(X) > support * support;
}

void SmoothWetEnergy::ensure_list(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    if (list_.valid(x, B)) return;
    ScopedSeconds timed(seconds_lists_);
    // A line search's trial left the list: rebuilt at the same place with a skin that reaches the trial, so that the
    // backtracking trials between the two stay covered (rebuilt at each of them, a 100-fiber run spent 85% of its
    // time building lists); a far trial (beyond 4 skins) gets a list of its own.
    const double d = list_.max_displacement(x, B);
    if (d <= 2 * list_.skin()) {
        const Eigen::VectorXd at = list_.built_at();
        list_.build(at, B, 2.05 * d);
    } else {
        list_.build(x, B);
    }
    index_list();
}

void SmoothWetEnergy::rebuild(const Eigen::VectorXd& q) {
    if (!active()) {
        pattern_ = dry_.hessian_pattern();
        return;
    }
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    {
        ScopedSeconds timed(seconds_lists_);
        list_.build(x, B);
    }
    index_wet();
    PartnerCap pc;
    const std::vector<int> on = nonzero_pairs(x, B, capped() ? &pc : nullptr);
    new_pattern(x, B, on, pc.n);
    indexed_build_ = list_.builds();  // wet_ and patterned_ index this build
}

void SmoothWetEnergy::new_pattern(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& on,
                                  const std::vector<double>& n) {
    ScopedSeconds timed(seconds_patterns_);
    build_pattern(x, B, on, n);
    stale_ = false;
    pattern_list_ = list_.builds();
    ++pattern_builds_;
}

void SmoothWetEnergy::cover(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& on,
                            const std::vector<double>& n, Eigen::SparseMatrix<double>& H) {
    bool covered = !stale_;
    for (size_t i = 0; i < on.size() && covered; ++i) covered = patterned_[on[i]] >= 0;
    if (!covered) new_pattern(x, B, on, n);
    if (!same_pattern(H, pattern_)) H = pattern_;
}

SmoothWetEnergy::SegmentBox SmoothWetEnergy::segment_box(int s, const Eigen::VectorXd& x,
                                                        const Eigen::Matrix2d& B) const {
    const Segment& a = dry_.model().segments[s];
    const Eigen::Vector2d p0 = x.segment<2>(2 * a.i), p1 = x.segment<2>(2 * a.j) + B * a.shift.cast<double>();
    return {std::min(p0.x(), p1.x()), std::max(p0.x(), p1.x()), std::min(p0.y(), p1.y()), std::max(p0.y(), p1.y()),
            (p1 - p0).norm()};
}

bool SmoothWetEnergy::apart(const SegmentBox& a, const SegmentBox& b, const Eigen::Vector2d& t) const {
    const double gx = std::max({0.0, b.x0 + t.x() - a.x1, a.x0 - b.x1 - t.x()});
    const double gy = std::max({0.0, b.y0 + t.y() - a.y1, a.y0 - b.y1 - t.y()});
    const double support = support_distance(std::max(a.length, b.length));
    return gx * gx + gy * gy > support * support;
}

std::vector<int> SmoothWetEnergy::nonzero_pairs(const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                                                PartnerCap* pc) const {
    const std::vector<SegmentPair>& P = list_.pairs();
    const Model& m = dry_.model();
    // Each segment's box once: most listed pairs (far from their support at any one state) are set aside by two boxes.
    std::vector<SegmentBox> box(m.segments.size());
    for (size_t s = 0; s < box.size(); ++s) box[s] = segment_box(static_cast<int>(s), x, B);
    // With the cap, each remaining pair's values at once (they tell whether it acts), so that none is evaluated twice.
    std::vector<char> act(P.size(), 0);
    std::vector<double> ex(pc ? P.size() : 0), ec(pc ? P.size() : 0);
    parallel_ranges(P.size(), P.size() >= kParallelMin ? thread_count() : 1, [&](size_t lo, size_t hi) {
        for (size_t k = lo; k < hi; ++k) {
            if (apart(box[P[k].a], box[P[k].b], B * P[k].image.cast<double>())) continue;
            const Vector8d X = list_.coordinates(P[k], x, B);
            if (!pc) {
                act[k] = !capillary_pair_vanishes(X, wet_[k], params_.pair);
                continue;
            }
            CapillaryPairParts parts;
            capillary_pair_energy(X, m.segments[P[k].a].l0, m.segments[P[k].b].l0, wet_[k], params_.pair, nullptr,
                                  nullptr, false, &parts);
            act[k] = parts.nonzero, ex[k] = parts.crossing_energy, ec[k] = parts.contact_energy;
        }
    });
    std::vector<int> on;
    std::vector<double> Ex, Ec;
    for (size_t k = 0; k < P.size(); ++k) {
        if (!act[k]) continue;
        on.push_back(static_cast<int>(k));
        if (pc) Ex.push_back(ex[k]), Ec.push_back(ec[k]);
    }
    if (pc) *pc = partner_cap(on, Ex, Ec);
    return on;
}

void SmoothWetEnergy::build_pattern(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& on,
                                    const std::vector<double>& n) {
    const std::vector<SegmentPair>& P = list_.pairs();
    std::vector<char> take(P.size(), 0);
    for (int k : on) take[k] = 1;
    const double dp = params_.pattern_distance;
    for (size_t k = 0; k < P.size(); ++k) {
        if (take[k]) continue;
        const Vector8d X = list_.coordinates(P[k], x, B);
        take[k] = box_gap_squared(X) < dp * dp &&
                  segment_distance(X.segment<2>(0), X.segment<2>(2), X.segment<2>(4), X.segment<2>(6)) < dp;
    }
    patterned_.assign(P.size(), -1);
    pattern_index_.clear();
    std::vector<int> idx;
    n_patterned_ = 0;
    for (size_t k = 0; k < P.size(); ++k) {
        if (!take[k]) continue;
        pattern_index_[key(P[k])] = static_cast<int>(n_patterned_);
        patterned_[k] = static_cast<int>(n_patterned_++);
        int e[8];
        local_dofs(P[k], e);
        idx.insert(idx.end(), e, e + 8);
    }
    std::vector<int> partner_idx;
    if (capped()) add_partner_blocks(take, x, B, n, partner_idx);
    const Eigen::SparseMatrix<double>& D = dry_.hessian_pattern();
    PatternBuilder builder(dry_.num_dofs());
    builder.add_pattern(D);
    builder.add_elements(idx, 8);
    builder.add_elements(partner_idx, 8);
    pattern_ = builder.build();
    dry_slot_ = subpattern_slots(pattern_, D);
    element_slots(pattern_, idx, 8, slots_);
    dry_H_ = D;
}

double SmoothWetEnergy::eval(const Eigen::VectorXd& q, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) {
    const unsigned want = (g ? kGradient : 0u) | (H ? kHessian : 0u) | (psd ? kProjectPSD : 0u);
    if (!active()) {
        dry_.evaluate(q, F_, Eigen::Matrix2d::Zero(), want, eval_, H);
        if (g) g->swap(eval_.gradient);
        return eval_.energy;
    }
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    ensure_list(x, B);
    const std::vector<SegmentPair>& P = list_.pairs();
    // The non-zero pairs and, with the partner cap, the energy and each pair's contact weight (a first pass over the
    // pairs' values): kept from the last evaluation at the same positions (Newton's Hessian at its line search's
    // accepted trial).
    if (!(at_.builds == list_.builds() && at_.x.size() == x.size() && (at_.x.array() == x.array()).all())) {
        at_.x = x, at_.builds = list_.builds();
        at_.pc = PartnerCap{};
        at_.on = nonzero_pairs(x, B, capped() ? &at_.pc : nullptr);
    }
    const std::vector<int>& on = at_.on;
    const PartnerCap& pc = at_.pc;
    if (H && follow_) cover(x, B, on, pc.n, *H);
    if (H && H->nonZeros() != pattern_.nonZeros())
        throw std::logic_error("SmoothWetEnergy: the Hessian lacks the energy's pattern");
    const bool pairs_pass = g || H || !capped();
    const bool saturation_hessian = H && !pc.saturating.empty();
    // The non-zero pairs in chunks, each evaluated in parallel into its own slots and added in list order after the
    // dry terms (evaluated beside the first chunk).
    const size_t n = on.size(), chunk = H ? std::min(n, kChunk) : n;
    const int threads = n >= 64 ? thread_count() : 1;
    // Buffers kept between evaluations (a Hessian's chunk holds 8 MB of blocks).
    std::vector<double>& cE = chunk_E_;
    auto& cg = chunk_g_;
    auto& cH = chunk_H_;
    cE.resize(chunk);
    if (g || H) cg.resize(chunk);
    if (H) cH.resize(chunk);
    if (saturation_hessian) contact_grad_.resize(n);
    double E = 0;
    double* hv = nullptr;
    auto dry_terms = [&] {
        dry_.evaluate(q, F_, Eigen::Matrix2d::Zero(), want, eval_, H ? &dry_H_ : nullptr);
        E = eval_.energy;
        if (g) g->swap(eval_.gradient);
        if (H) {
            hv = assign_subpattern(dry_H_, dry_slot_, *H);
        }
    };
    if (n == 0 || !pairs_pass) dry_terms();
    for (size_t c0 = 0; c0 < n && pairs_pass; c0 += chunk) {
        const size_t c1 = std::min(n, c0 + chunk);
        parallel_blocks(c1 - c0, threads, 64, [&] { if (c0 == 0) dry_terms(); }, [&](size_t lo, size_t hi) {
            for (size_t i = lo; i < hi; ++i) {
                const SegmentPair& p = P[on[c0 + i]];
                const Model& m = dry_.model();
                cE[i] = capillary_pair_energy(list_.coordinates(p, x, B), m.segments[p.a].l0, m.segments[p.b].l0,
                                              wet_[on[c0 + i]], params_.pair, g || H ? &cg[i] : nullptr,
                                              H ? &cH[i] : nullptr, psd, nullptr,
                                              capped() ? pc.scale[c0 + i] : 1.0,
                                              saturation_hessian ? &contact_grad_[c0 + i] : nullptr);
            }
        });
        for (size_t i = 0; i < c1 - c0; ++i) {
            const int k = on[c0 + i];
            if (!capped()) E += cE[i];
            if (!g && !H) continue;
            int idx[8];
            local_dofs(P[k], idx);
            const int pk = patterned_[k];
            if (H && pk < 0) stale_ = true;
            scatter_element(idx, H && pk >= 0 ? &slots_[64 * static_cast<size_t>(pk)] : nullptr, 8, cg[i].data(),
                            H ? cH[i].data() : nullptr, g, H && pk >= 0 ? hv : nullptr);
        }
    }
    if (capped()) E += pc.crossing + pc.contact;
    if (saturation_hessian) add_saturation_hessian(pc, on, contact_grad_, hv);
    if (H && follow_ && stale_ && !retrying_) {
        // The cap's coupling met a block outside the pattern: the pattern of this state holds it (add_partner_blocks).
        new_pattern(x, B, on, pc.n);
        retrying_ = true;
        E = eval(q, g, H, psd);
        retrying_ = false;
    }
    return E;
}

SmoothWetEnergy::PartnerCap SmoothWetEnergy::partner_cap(const std::vector<int>& on, const std::vector<double>& Ex,
                                                         const std::vector<double>& Ec) const {
    const std::vector<SegmentPair>& P = list_.pairs();
    const Model& m = dry_.model();
    const size_t n = on.size();
    // C_a, summed in list order (the same for any thread count).
    PartnerCap pc;
    std::vector<double> C(m.segments.size(), 0.0), dS(m.segments.size(), 1.0);
    for (size_t i = 0; i < n; ++i) {
        const SegmentPair& p = P[on[i]];
        pc.crossing += Ex[i];
        C[p.a] += Ec[i], C[p.b] += Ec[i];
    }
    const double beta = params_.pair.beta;
    pc.n.assign(C.size(), 0.0);
    for (size_t a = 0; a < C.size(); ++a) {
        if (C[a] == 0) continue;
        const double l = m.segments[a].l0;
        pc.n[a] = -C[a] / (beta * l);
        const Saturation s = bundle_saturation(pc.n[a], params_.bundle_partners);
        pc.contact += -0.5 * beta * l * s.S;
        dS[a] = s.dS;
        if (s.d2S != 0) pc.saturating.push_back(static_cast<int>(a)), pc.kappa.push_back(-s.d2S / (2 * beta * l));
    }
    pc.scale.resize(n), pc.touching.resize(n);
    for (size_t i = 0; i < n; ++i) pc.scale[i] = 0.5 * (dS[P[on[i]].a] + dS[P[on[i]].b]), pc.touching[i] = Ec[i] != 0;
    return pc;
}

std::vector<std::vector<int>> SmoothWetEnergy::saturating_pairs(const PartnerCap& pc, const std::vector<int>& on) const {
    std::vector<int> which(dry_.model().segments.size(), -1);
    for (size_t j = 0; j < pc.saturating.size(); ++j) which[pc.saturating[j]] = static_cast<int>(j);
    std::vector<std::vector<int>> out(pc.saturating.size());
    const std::vector<SegmentPair>& P = list_.pairs();
    for (size_t i = 0; i < on.size(); ++i) {
        const SegmentPair& p = P[on[i]];
        if (!pc.touching[i]) continue;
        if (which[p.a] >= 0) out[which[p.a]].push_back(static_cast<int>(i));
        if (which[p.b] >= 0) out[which[p.b]].push_back(static_cast<int>(i));
    }
    return out;
}

void SmoothWetEnergy::add_saturation_hessian(const PartnerCap& pc, const std::vector<int>& on,
                                             const std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>>& cgrad,
                                             double* hv) {
    const std::vector<SegmentPair>& P = list_.pairs();
    const std::vector<std::vector<int>> pairs = saturating_pairs(pc, on);
    std::vector<std::pair<int, double>> G;
    for (size_t j = 0; j < pairs.size(); ++j) {
        // G_a = grad C_a
        G.clear();
        for (int i : pairs[j]) {
            int idx[8];
            local_dofs(P[on[i]], idx);
            for (int l = 0; l < 8; ++l)
                if (idx[l] >= 0) G.emplace_back(idx[l], cgrad[i][l]);
        }
        if (!add_outer_product(pattern_, G, pc.kappa[j], hv)) stale_ = true;
    }
}

void SmoothWetEnergy::add_partner_blocks(const std::vector<char>& take, const Eigen::VectorXd& x,
                                         const Eigen::Matrix2d& B, const std::vector<double>& n,
                                         std::vector<int>& idx) const {
    // Aligned: within 15 deg beyond the contact term's reach at the build; near the blend: n_a within 1/2 of it (the
    // coupling is kappa_a G_a G_a^T, non-zero only inside the blend). So the blocks cover the motion until the next
    // rebuild; a segment that saturates outside them marks the pattern stale.
    const double reach = std::sin((params_.pair.angle_hi_deg + 15) * M_PI / 180);
    const double N = params_.bundle_partners, h = kSaturationHalfWidth + 0.5;
    const std::vector<SegmentPair>& P = list_.pairs();
    std::vector<std::vector<int>> partners(dry_.model().segments.size());
    for (size_t k = 0; k < P.size(); ++k) {
        if (!take[k]) continue;
        const Vector8d X = list_.coordinates(P[k], x, B);
        const Eigen::Vector2d d1 = X.segment<2>(2) - X.segment<2>(0), d2 = X.segment<2>(6) - X.segment<2>(4);
        const double cr = d1.x() * d2.y() - d1.y() * d2.x();
        if (cr * cr > reach * reach * d1.squaredNorm() * d2.squaredNorm()) continue;
        for (const int a : {P[k].a, P[k].b})
            if (std::abs(n[a] - N) < h) partners[a].push_back(static_cast<int>(k));
    }
    for (size_t a = 0; a < partners.size(); ++a) {
        const std::vector<int>& L = partners[a];
        for (size_t u = 0; u < L.size(); ++u)
            for (size_t v = u + 1; v < L.size(); ++v) {
                int eu[8], ev[8];
                local_dofs(P[L[u]], eu), local_dofs(P[L[v]], ev);
                const int* ou = P[L[u]].a == static_cast<int>(a) ? eu + 4 : eu;  // the partner's half
                const int* ov = P[L[v]].a == static_cast<int>(a) ? ev + 4 : ev;
                idx.insert(idx.end(), ou, ou + 4);
                idx.insert(idx.end(), ov, ov + 4);
            }
    }
}

void SmoothWetEnergy::index_segment_pairs() const {
    if (seg_pair_list_ == list_.builds()) return;
    const std::vector<SegmentPair>& P = list_.pairs();
    const size_t ns = dry_.model().segments.size();
    seg_pair_start_.assign(ns + 1, 0);
    for (const SegmentPair& p : P) ++seg_pair_start_[p.a + 1], ++seg_pair_start_[p.b + 1];
    for (size_t s = 0; s < ns; ++s) seg_pair_start_[s + 1] += seg_pair_start_[s];
    seg_pair_.resize(seg_pair_start_[ns]);
    std::vector<int> fill(seg_pair_start_.begin(), seg_pair_start_.end() - 1);
    for (size_t k = 0; k < P.size(); ++k) {
        seg_pair_[fill[P[k].a]++] = static_cast<int>(k);
        seg_pair_[fill[P[k].b]++] = static_cast<int>(k);
    }
    seg_pair_list_ = list_.builds();
}

std::unique_ptr<Objective> SmoothWetEnergy::restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) {
    if (!incidence_) incidence_ = std::make_shared<const NodeElements>(node_elements(dry_));
    if (!active()) return std::make_unique<NetworkRegion>(dry_, F_, *incidence_, q, coords);
    return std::make_unique<SmoothWetRegion>(*this, *incidence_, q, coords);
}

double SmoothWetEnergy::value(const Eigen::VectorXd& q) { return eval(q, nullptr, nullptr, false); }
double SmoothWetEnergy::gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) { return eval(q, &g, nullptr, false); }
double SmoothWetEnergy::hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H,
                                bool psd) {
    return eval(q, &g, &H, psd);
}

void SmoothWetEnergy::for_each_nonzero(const Eigen::VectorXd& q,
                                       const std::function<void(const SegmentPair&, const Vector8d&)>& f) const {
    if (!active()) return;
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    ensure_list(x, B);
    const std::vector<SegmentPair>& P = list_.pairs();
    for (int k : nonzero_pairs(x, B)) f(P[k], list_.coordinates(P[k], x, B));
}

void SmoothWetEnergy::strain_derivatives(const Eigen::VectorXd& q, const Eigen::Matrix2d& dF, EnergyEval& out,
                                         bool comoving) const {
    dry_.evaluate(q, F_, dF, kStrain | (comoving ? kComoving : 0u), out);
    if (!active()) return;
    const Model& m = dry_.model();
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * m.box.B0();
    ensure_list(x, B);
    const std::vector<SegmentPair>& P = list_.pairs();
    PartnerCap pc;
    const std::vector<int> on = nonzero_pairs(x, B, capped() ? &pc : nullptr);
    const bool saturation = !pc.saturating.empty();
    // With saturating segments, also each pair's contact gradient and rate dC_ab/dt (the cap's kappa_a (dC_a/dt)^2
    // and kappa_a dC_a/dt grad C_a, bundle_saturation.hpp).
    std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>> cg(saturation ? on.size() : 0);
    std::vector<double> rate(saturation ? on.size() : 0);
    Vector8d g;
    Matrix8d He;
    for (size_t i = 0; i < on.size(); ++i) {
        const SegmentPair& p = P[on[i]];
        const Vector8d X = list_.coordinates(p, x, B);
        capillary_pair_energy(X, m.segments[p.a].l0, m.segments[p.b].l0, wet_[on[i]], params_.pair, &g, &He, false,
                              nullptr, capped() ? pc.scale[i] : 1.0, saturation ? &cg[i] : nullptr);
        int node[4];
        Eigen::Vector2i shift[4];
        list_.nodes(p, node, shift);
        add_strain_terms<4>(dry_, F_, dF, comoving, node, shift, X, g, He, out);
        if (saturation) rate[i] = cg[i].dot(strain_rate<4>(dry_, F_, dF, comoving, node, shift, X));
    }
    const std::vector<std::vector<int>> pairs = saturation ? saturating_pairs(pc, on) : std::vector<std::vector<int>>{};
    for (size_t j = 0; j < pairs.size(); ++j) {
        double Cdot = 0;
        for (int i : pairs[j]) Cdot += rate[i];
        const double tt = pc.kappa[j] * Cdot * Cdot;
        out.d2E_dt2 += tt, out.d2E_dt2_size += std::abs(tt);
        for (int i : pairs[j]) {
            int idx[8];
            local_dofs(P[on[i]], idx);
            for (int l = 0; l < 8; ++l)
                if (idx[l] >= 0) out.d2E_dqdt[idx[l]] += pc.kappa[j] * Cdot * cg[i][l];
        }
    }
}

void SmoothWetEnergy::for_each_part(const Eigen::VectorXd& q,
                                    const std::function<void(const SegmentPair&, const CapillaryPairParts&)>& f) const {
    const Model& m = dry_.model();
    for_each_nonzero(q, [&](const SegmentPair& p, const Vector8d& X) {
        CapillaryPairParts parts;
        capillary_pair_energy(X, m.segments[p.a].l0, m.segments[p.b].l0, wet_crossing(p), params_.pair, nullptr,
                              nullptr, false, &parts);
        f(p, parts);
    });
}

SmoothWetSplit SmoothWetEnergy::split(const Eigen::VectorXd& q) const {
    EnergyEval ev;
    dry_.evaluate(q, F_, Eigen::Matrix2d::Zero(), kValue, ev);
    SmoothWetSplit s;
    s.stretch = ev.stretch, s.bend = ev.bend;
    if (capped() && active()) {
        const Eigen::VectorXd x = dry_.positions(q, F_);
        const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
        ensure_list(x, B);
        PartnerCap pc;
        nonzero_pairs(x, B, &pc);
        s.crossing = pc.crossing, s.contact = pc.contact;
        return s;
    }
    for_each_part(q, [&](const SegmentPair&, const CapillaryPairParts& parts) {
        s.crossing += parts.crossing_energy, s.contact += parts.contact_energy;
    });
    return s;
}

std::vector<Bridge> SmoothWetEnergy::bridges(const Eigen::VectorXd& q, double* crossing_weight) const {
    std::vector<Bridge> out;
    if (crossing_weight) *crossing_weight = 0;
    for_each_part(q, [&](const SegmentPair& p, const CapillaryPairParts& parts) {
        Bridge b;
        b.f1 = seg_fiber_[p.a], b.f2 = seg_fiber_[p.b];
        b.k1 = seg_index_[p.a], b.k2 = seg_index_[p.b];
        b.image = p.image;
        b.locked = parts.crossing_weight == 0;
        if (crossing_weight) *crossing_weight += parts.crossing_weight;
        out.push_back(b);
    });
    return out;
}

}  // namespace fibernet
