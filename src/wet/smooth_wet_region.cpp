#include "fibernet/wet/smooth_wet_region.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/wet/bundle_saturation.hpp"
#include "fibernet/wet/smooth_wet_energy.hpp"

namespace fibernet {

SmoothWetRegion::SmoothWetRegion(SmoothWetEnergy& W, const NodeElements& inc, const Eigen::VectorXd& q,
                                 const std::vector<int>& coords)
    : W_(W), coords_(coords), dry_(W.dry_, W.F_, inc, q, coords) {
    const Model& m = W.dry_.model();
    x_ = W.dry_.positions(q, W.F_);
    B_ = W.F_ * m.box.B0();
    W.ensure_list(x_, B_);  // valid at the held nodes from here on: they do not move
    xref_.resize(size());
    for (int k = 0; k < size(); ++k) {
        const int xi = inc.dof_node[coords_[k]];
        coord_x_.push_back(xi);
        xref_[k] = m.x[xi];
        nodes_.push_back(xi / 2);
    }
    std::sort(nodes_.begin(), nodes_.end());
    nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
    in_region_.assign(m.segments.size(), 0);
    segs_ = elements_at(inc.seg_start, inc.seg, nodes_);
    for (int s : segs_) in_region_[s] = 1;
    take_pairs();

    // The pattern, as the whole energy's (smooth_wet_energy.hpp): the dry region's, the block of every moving pair
    // that is non-zero or closer than the pattern distance here, and with the cap the blocks between the aligned such
    // pairs of each segment near the saturation blend (within 1/2 of it). A pair that becomes non-zero outside them
    // later leaves its block out (pattern_stale()).
    const std::vector<SegmentPair>& P = W_.list_.pairs();
    const CapillaryPairParams& pp = W_.params_.pair;
    const double reach = std::sin((pp.angle_hi_deg + 15) * M_PI / 180);
    std::vector<int> el, sat, near;  // near: indices into pairs_
    for (size_t i = 0; i < pairs_.size(); ++i) {
        if (!moving_[i]) continue;
        const Vector8d X = W_.list_.coordinates(P[pairs_[i]], x_, B_);
        const bool on = !W_.beyond_support(X) && !capillary_pair_vanishes(X, W_.wet_[pairs_[i]], pp);
        if (!on && segment_distance(X.segment<2>(0), X.segment<2>(2), X.segment<2>(4), X.segment<2>(6)) >=
                       W_.params_.pattern_distance)
            continue;
        near.push_back(static_cast<int>(i));
        el.insert(el.end(), &idx_[8 * i], &idx_[8 * i] + 8);
    }
    if (W_.capped()) {
        std::vector<int> on;
        for (int k : pairs_) on.push_back(k);
        const std::vector<double> n = W_.partner_cap(x_, B_, on).n;
        const double N = W_.params_.bundle_partners, h = kSaturationHalfWidth + 0.5;
        std::vector<std::pair<int, int>> of_segment;  // (segment, index into pairs_)
        for (int i : near) {
            const Vector8d X = W_.list_.coordinates(P[pairs_[i]], x_, B_);
            const Eigen::Vector2d d1 = X.segment<2>(2) - X.segment<2>(0), d2 = X.segment<2>(6) - X.segment<2>(4);
            const double cr = d1.x() * d2.y() - d1.y() * d2.x();
            if (cr * cr > reach * reach * d1.squaredNorm() * d2.squaredNorm()) continue;
            for (const int s : {P[pairs_[i]].a, P[pairs_[i]].b})
                if (std::abs(n[s] - N) < h) of_segment.emplace_back(s, i);
        }
        std::sort(of_segment.begin(), of_segment.end());
        for (size_t u0 = 0; u0 < of_segment.size();) {
            size_t u1 = u0;
            while (u1 < of_segment.size() && of_segment[u1].first == of_segment[u0].first) ++u1;
            for (size_t u = u0; u < u1; ++u)
                for (size_t v = u + 1; v < u1; ++v) {
                    const int a = of_segment[u].second, b = of_segment[v].second;
                    sat.insert(sat.end(), &idx_[8 * a], &idx_[8 * a] + 8);
                    sat.insert(sat.end(), &idx_[8 * b], &idx_[8 * b] + 8);
                }
            u0 = u1;
        }
    }
    PatternBuilder builder(size());
    builder.add_pattern(dry_.hessian_pattern());
    builder.add_elements(el, 8);
    builder.add_elements(sat, 16);
    pattern_ = builder.build();
    dry_H_ = dry_.hessian_pattern();
    dry_slot_ = subpattern_slots(pattern_, dry_H_);
}

void SmoothWetRegion::take_pairs() {
    W_.index_segment_pairs();
    const std::vector<SegmentPair>& P = W_.list_.pairs();
    const std::vector<int>& start = W_.seg_pair_start_;
    const std::vector<int>& list = W_.seg_pair_;
    // The segments whose pairs are taken: the region's, and with the cap every segment that a moving pair holds.
    std::vector<int> segs = segs_;
    if (W_.capped()) {
        const size_t own = segs.size();
        for (size_t r = 0; r < own; ++r)
            for (int p = start[segs[r]]; p < start[segs[r] + 1]; ++p)
                segs.push_back(P[list[p]].a == segs[r] ? P[list[p]].b : P[list[p]].a);
        std::sort(segs.begin(), segs.end());
        segs.erase(std::unique(segs.begin(), segs.end()), segs.end());
    }
    pairs_.clear();
    for (int s : segs) pairs_.insert(pairs_.end(), list.begin() + start[s], list.begin() + start[s + 1]);
    std::sort(pairs_.begin(), pairs_.end());
    pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
    // Region index of coordinate c of node v, or -1 when it is held (or fixed).
    auto local = [&](int v, int c) -> int {
        const int d = W_.dry_.dof(v, c);
        if (d < 0) return -1;
        const auto it = std::lower_bound(coords_.begin(), coords_.end(), d);
        return it != coords_.end() && *it == d ? static_cast<int>(it - coords_.begin()) : -1;
    };
    moving_.assign(pairs_.size(), 0);
    idx_.assign(8 * pairs_.size(), -1);
    for (size_t i = 0; i < pairs_.size(); ++i) {
        const SegmentPair& p = P[pairs_[i]];
        moving_[i] = in_region_[p.a] || in_region_[p.b];
        int node[4];
        Eigen::Vector2i shift[4];
        W_.list_.nodes(p, node, shift);
        for (int a = 0; a < 8; ++a) idx_[8 * i + a] = local(node[a / 2], a % 2);
    }
    list_build_ = W_.list_.builds();
}

double SmoothWetRegion::capped_energy(const SmoothWetEnergy::PartnerCap& pc, const std::vector<int>& on_i,
                                      const std::vector<int>& on) const {
    // The whole capped energy less a constant that does not depend on which pairs were taken: the crossing terms of
    // the moving pairs; -(beta / 2) l_a S(n_a) of the region's segments; and for any other segment b that a moving
    // pair holds, -(beta / 2) l_b [S(n_b) - S(n_b fixed)], n_b fixed from its pairs with held segments alone (its term
    // less its value with the region's pairs at zero, which is that constant).
    const std::vector<SegmentPair>& P = W_.list_.pairs();
    const Model& m = W_.dry_.model();
    const double beta = W_.params_.pair.beta;
    const int N = W_.params_.bundle_partners;
    double E = 0;
    std::unordered_map<int, double> fixed;  // segment b outside the region held by a moving pair -> C_b fixed
    for (size_t j = 0; j < on.size(); ++j)
        if (moving_[on_i[j]]) {
            E += pc.pair_crossing[j];
            for (const int s : {P[on[j]].a, P[on[j]].b})
                if (!in_region_[s]) fixed.emplace(s, 0.0);
        }
    for (size_t j = 0; j < on.size(); ++j) {
        if (moving_[on_i[j]]) continue;
        for (const int s : {P[on[j]].a, P[on[j]].b}) {
            const auto it = fixed.find(s);
            if (it != fixed.end()) it->second += pc.pair_contact[j];
        }
    }
    for (int a : segs_) E += -0.5 * beta * m.segments[a].l0 * bundle_saturation(pc.n[a], N).S;
    std::vector<std::pair<int, double>> sorted(fixed.begin(), fixed.end());  // a fixed order of the sum
    std::sort(sorted.begin(), sorted.end());
    for (const auto& [b, C] : sorted) {
        const double l = m.segments[b].l0;
        E += -0.5 * beta * l * (bundle_saturation(pc.n[b], N).S - bundle_saturation(-C / (beta * l), N).S);
    }
    return E;
}

void SmoothWetRegion::place(const Eigen::VectorXd& qa) {
    if (qa.size() != size()) throw std::logic_error("SmoothWetRegion: coordinates of the wrong size");
    for (int k = 0; k < size(); ++k) x_[coord_x_[k]] = xref_[k] + qa[k];
}

double SmoothWetRegion::eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) {
    place(qa);
    if (!W_.list_.valid_at(nodes_, x_, B_)) {  // the region left the list: W's list anew at this state
        W_.list_.build(x_, B_);
        W_.index_list();
    }
    if (list_build_ != W_.list_.builds()) take_pairs();
    double E = 0;
    double* hv = nullptr;
    if (H) {
        if (H->nonZeros() != pattern_.nonZeros()) throw std::logic_error("SmoothWetRegion: Hessian lacks the region's pattern");
        E = dry_.hessian(qa, *g, dry_H_, psd);
        hv = assign_subpattern(dry_H_, dry_slot_, *H);
    } else if (g) {
        E = dry_.gradient(qa, *g);
    } else {
        E = dry_.value(qa);
    }
    if (!W_.active()) return E;
    const std::vector<SegmentPair>& P = W_.list_.pairs();
    const Model& m = W_.dry_.model();
    const CapillaryPairParams& pp = W_.params_.pair;
    // The non-zero pairs taken (indices into pairs_ and into W's list).
    std::vector<int> on_i, on;
    for (size_t i = 0; i < pairs_.size(); ++i) {
        const Vector8d X = W_.list_.coordinates(P[pairs_[i]], x_, B_);
        if (!W_.beyond_support(X) && !capillary_pair_vanishes(X, W_.wet_[pairs_[i]], pp))
            on_i.push_back(static_cast<int>(i)), on.push_back(pairs_[i]);
    }
    const bool capped = W_.capped();
    SmoothWetEnergy::PartnerCap pc;
    if (capped) {
        pc = W_.partner_cap(x_, B_, on);
        E += capped_energy(pc, on_i, on);
        if (!g && !H) return E;
    }
    const bool saturation = H && !pc.saturating.empty();
    std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>> cg(saturation ? on.size() : 0);
    Vector8d ge;
    Matrix8d he;
    int slot[64];
    for (size_t j = 0; j < on.size(); ++j) {
        const int i = on_i[j];
        if (!moving_[i]) continue;
        const SegmentPair& p = P[on[j]];
        const double e = capillary_pair_energy(W_.list_.coordinates(p, x_, B_), m.segments[p.a].l0, m.segments[p.b].l0,
                                               W_.wet_[on[j]], pp, g || H ? &ge : nullptr, H ? &he : nullptr, psd,
                                               nullptr, capped ? pc.scale[j] : 1.0, saturation ? &cg[j] : nullptr);
        if (!capped) E += e;
        if (!g && !H) continue;
        const int* idx = &idx_[8 * i];
        if (H)
            for (int a = 0; a < 8; ++a)
                for (int b = 0; b < 8; ++b) {
                    slot[8 * a + b] = -1;
                    if (idx[a] < 0 || idx[b] < 0 || idx[a] > idx[b]) continue;
                    slot[8 * a + b] = find_slot(pattern_, idx[a], idx[b]);
                    if (slot[8 * a + b] < 0) stale_ = true;
                }
        scatter_element(idx, H ? slot : nullptr, 8, ge.data(), H ? he.data() : nullptr, g, hv);
    }
    if (!saturation) return E;
    // The cap's coupling kappa_a G_a G_a^T, G_a the gradient of a's contact energy over its moving pairs.
    std::unordered_map<int, int> which;
    for (size_t s = 0; s < pc.saturating.size(); ++s) which[pc.saturating[s]] = static_cast<int>(s);
    std::vector<std::vector<std::pair<int, double>>> G(pc.saturating.size());
    for (size_t j = 0; j < on.size(); ++j) {
        const int i = on_i[j];
        if (!moving_[i] || !pc.touching[j]) continue;
        for (const int s : {P[on[j]].a, P[on[j]].b}) {
            const auto it = which.find(s);
            if (it == which.end()) continue;
            for (int a = 0; a < 8; ++a)
                if (idx_[8 * i + a] >= 0) G[it->second].emplace_back(idx_[8 * i + a], cg[j][a]);
        }
    }
    for (size_t s = 0; s < G.size(); ++s)
        if (!add_outer_product(pattern_, G[s], pc.kappa[s], hv)) stale_ = true;
    return E;
}

}  // namespace fibernet
