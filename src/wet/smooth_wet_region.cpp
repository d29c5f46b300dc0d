#include "fibernet/wet/smooth_wet_region.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/stopwatch.hpp"
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
    local_x_.assign(x_.size(), -1);
    seg_place_.assign(m.segments.size(), -1);
    for (int k = 0; k < size(); ++k) {
        const int xi = inc.dof_node[coords_[k]];
        coord_x_.push_back(xi);
        local_x_[xi] = k;
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
    const CapillaryPairParams& pp = W_.params_.pair;
    const double reach = std::sin((pp.angle_hi_deg + 15) * M_PI / 180);
    std::vector<int> el, sat, near;  // near: indices into pairs_
    for (size_t i = 0; i < pairs_.size(); ++i) {
        const Vector8d X = W_.list_.coordinates(pairs_[i], x_, B_);
        const bool on = !W_.beyond_support(X) && !capillary_pair_vanishes(X, wet_[i], pp);
        if (!on && segment_distance(X.segment<2>(0), X.segment<2>(2), X.segment<2>(4), X.segment<2>(6)) >=
                       W_.params_.pattern_distance)
            continue;
        near.push_back(static_cast<int>(i));
        el.insert(el.end(), &idx_[8 * i], &idx_[8 * i] + 8);
    }
    if (W_.capped()) {
        std::vector<int> on;
        const CapState cs = cap_state(candidates(), on, nullptr, nullptr);
        const double N = W_.params_.bundle_partners, h = kSaturationHalfWidth + 0.5;
        std::vector<std::pair<int, int>> of_segment;  // (segment's place in seg_, index into pairs_)
        for (int i : near) {
            const Vector8d X = W_.list_.coordinates(pairs_[i], x_, B_);
            const Eigen::Vector2d d1 = X.segment<2>(2) - X.segment<2>(0), d2 = X.segment<2>(6) - X.segment<2>(4);
            const double cr = d1.x() * d2.y() - d1.y() * d2.x();
            if (cr * cr > reach * reach * d1.squaredNorm() * d2.squaredNorm()) continue;
            for (int side = 0; side < 2; ++side)
                if (std::abs(cs.n[pair_seg_[2 * i + side]] - N) < h)
                    of_segment.emplace_back(pair_seg_[2 * i + side], i);
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
    slot_pairs();
}

void SmoothWetRegion::slot_pairs() {
    // Per pair the slots of its upper block in the pattern, -1 where the pattern lacks one (the pair is unpatterned).
    element_slots(pattern_, idx_, 8, slots_, &unpatterned_);
}

SmoothWetRegion::~SmoothWetRegion() {
    // Pairs found by the region's own list updates go into W's list once, now (NeighbourList::find).
    if (!own_pairs_ || !W_.list_.pending()) return;  // nothing found, or W's list was rebuilt since
    ScopedSeconds timed(W_.seconds_lists_);
    W_.list_.replace(segs_, pairs_);
    W_.index_list();
}

void SmoothWetRegion::take_pairs() {
    W_.index_segment_pairs();
    const std::vector<SegmentPair>& P = W_.list_.pairs();
    const std::vector<int>& start = W_.seg_pair_start_;
    const std::vector<int>& list = W_.seg_pair_;
    // The moving pairs: those of the region's segments, in list order.
    std::vector<int> at;
    for (int s : segs_) at.insert(at.end(), list.begin() + start[s], list.begin() + start[s + 1]);
    std::sort(at.begin(), at.end());
    at.erase(std::unique(at.begin(), at.end()), at.end());
    pairs_.resize(at.size()), wet_.resize(at.size());
    for (size_t i = 0; i < at.size(); ++i) pairs_[i] = P[at[i]], wet_[i] = W_.wet_[at[i]];
    own_pairs_ = false;
    list_build_ = W_.list_.builds();
    index_pairs();
}

void SmoothWetRegion::index_pairs() {
    // Per pair the region index of its 8 coordinates, -1 where held (or fixed).
    idx_.assign(8 * pairs_.size(), -1);
    for (size_t i = 0; i < pairs_.size(); ++i) {
        int node[4];
        Eigen::Vector2i shift[4];
        W_.list_.nodes(pairs_[i], node, shift);
        for (int a = 0; a < 8; ++a) idx_[8 * i + a] = local_x_[2 * node[a / 2] + a % 2];
    }
    // The pairs' segments: the region's and their partners (the other segment of a moving pair).
    for (int s : seg_) seg_place_[s] = -1;
    seg_ = segs_;
    for (const SegmentPair& p : pairs_) seg_.push_back(p.a), seg_.push_back(p.b);
    std::sort(seg_.begin(), seg_.end());
    seg_.erase(std::unique(seg_.begin(), seg_.end()), seg_.end());
    for (size_t j = 0; j < seg_.size(); ++j) seg_place_[seg_[j]] = static_cast<int>(j);
    pair_seg_.resize(2 * pairs_.size());
    for (size_t i = 0; i < pairs_.size(); ++i)
        pair_seg_[2 * i] = seg_place_[pairs_[i].a], pair_seg_[2 * i + 1] = seg_place_[pairs_[i].b];
    if (W_.capped()) take_cap_segments();
}

void SmoothWetRegion::take_cap_segments() {
    // The segments whose n enters are seg_. A partner's pairs with held segments do not change while the region moves:
    // their contact energy is summed once here.
    const std::vector<SegmentPair>& P = W_.list_.pairs();
    const Model& m = W_.dry_.model();
    const CapillaryPairParams& pp = W_.params_.pair;
    fixed_C_.assign(seg_.size(), 0.0);
    const std::vector<int>& start = W_.seg_pair_start_;
    const std::vector<int>& list = W_.seg_pair_;
    for (size_t j = 0; j < seg_.size(); ++j) {
        const int b = seg_[j];
        if (in_region_[b]) continue;
        for (int p = start[b]; p < start[b + 1]; ++p) {
            const SegmentPair& pr = P[list[p]];
            if (in_region_[pr.a] || in_region_[pr.b]) continue;  // a moving pair
            const Vector8d X = W_.list_.coordinates(pr, x_, B_);
            if (W_.beyond_support(X) || capillary_pair_vanishes(X, W_.wet_[list[p]], pp)) continue;
            CapillaryPairParts parts;
            capillary_pair_energy(X, m.segments[pr.a].l0, m.segments[pr.b].l0, W_.wet_[list[p]], pp, nullptr, nullptr,
                                  false, &parts);
            fixed_C_[j] += parts.contact_energy;
        }
    }
}

std::vector<int> SmoothWetRegion::candidates() const {
    box_.resize(seg_.size());
    for (size_t j = 0; j < seg_.size(); ++j) box_[j] = W_.segment_box(seg_[j], x_, B_);
    std::vector<int> out;
    for (size_t i = 0; i < pairs_.size(); ++i)
        if (!W_.apart(box_[pair_seg_[2 * i]], box_[pair_seg_[2 * i + 1]], B_ * pairs_[i].image.cast<double>()))
            out.push_back(static_cast<int>(i));
    return out;
}

SmoothWetRegion::CapState SmoothWetRegion::cap_state(const std::vector<int>& cand, std::vector<int>& on, double* E,
                                                     std::vector<double>* contact) const {
    // n_s = -C_s / (beta l_s) over the cap's segments, C_s summed in list order; the energy is the whole capped
    // energy less a constant that does not depend on which pairs were taken: the crossing terms of the moving pairs,
    // -(beta / 2) l_a S(n_a) of the region's segments, and -(beta / 2) l_b [S(n_b) - S(n_b fixed)] of a partner b,
    // n_b fixed from its pairs with held segments alone (b's term less its value with the region's pairs at zero).
    const Model& m = W_.dry_.model();
    const CapillaryPairParams& pp = W_.params_.pair;
    const double beta = pp.beta;
    const int N = W_.params_.bundle_partners;
    std::vector<double> C = fixed_C_;
    double crossing = 0;
    on.clear();
    if (contact) contact->clear();
    for (const int i : cand) {
        const SegmentPair& pr = pairs_[i];
        CapillaryPairParts parts;
        capillary_pair_energy(W_.list_.coordinates(pr, x_, B_), m.segments[pr.a].l0, m.segments[pr.b].l0, wet_[i], pp,
                              nullptr, nullptr, false, &parts);
        if (!parts.nonzero) continue;
        on.push_back(i);
        crossing += parts.crossing_energy;
        C[pair_seg_[2 * i]] += parts.contact_energy, C[pair_seg_[2 * i + 1]] += parts.contact_energy;
        if (contact) contact->push_back(parts.contact_energy);
    }
    CapState cs;
    cs.n.resize(seg_.size()), cs.dS.resize(seg_.size()), cs.kappa.assign(seg_.size(), 0.0);
    double e = crossing;
    for (size_t j = 0; j < seg_.size(); ++j) {
        const double l = m.segments[seg_[j]].l0;
        cs.n[j] = -C[j] / (beta * l);
        const Saturation st = bundle_saturation(cs.n[j], N);
        cs.dS[j] = st.dS, cs.kappa[j] = -st.d2S / (2 * beta * l);
        double share = -0.5 * beta * l * st.S;
        if (!in_region_[seg_[j]]) share -= -0.5 * beta * l * bundle_saturation(-fixed_C_[j] / (beta * l), N).S;
        e += share;
    }
    if (E) *E = e;
    return cs;
}

void SmoothWetRegion::place(const Eigen::VectorXd& qa) {
    if (qa.size() != size()) throw std::logic_error("SmoothWetRegion: coordinates of the wrong size");
    for (int k = 0; k < size(); ++k) x_[coord_x_[k]] = xref_[k] + qa[k];
}

double SmoothWetRegion::eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) {
    place(qa);
    if (!W_.list_.valid_at(nodes_, x_, B_)) {  // the region left the list: its pairs anew (W's list gets them at the end)
        ScopedSeconds timed(W_.seconds_lists_);
        if (W_.list_.find(x_, B_, segs_, nodes_, pairs_)) {
            wet_.resize(pairs_.size());
            for (size_t i = 0; i < pairs_.size(); ++i) wet_[i] = static_cast<char>(W_.wet_crossing(pairs_[i]));
            own_pairs_ = true;
            list_build_ = W_.list_.builds();  // they are the pairs of W's list as it stands, with this region's anew
            index_pairs(), slot_pairs();
        } else {  // a full build instead: W's list is whole again
            own_pairs_ = false;
            W_.index_list();
        }
    }
    if (list_build_ != W_.list_.builds()) take_pairs(), slot_pairs();
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
    const Model& m = W_.dry_.model();
    const CapillaryPairParams& pp = W_.params_.pair;
    // The non-zero pairs (indices into pairs_); with the cap, its state over them.
    const std::vector<int> cand = candidates();
    const bool capped = W_.capped();
    std::vector<int> on;
    CapState cs;
    std::vector<double> contact;
    if (capped) {
        double Ecap = 0;
        cs = cap_state(cand, on, &Ecap, &contact);
        E += Ecap;
        if (!g && !H) return E;
    } else {
        for (const int i : cand)
            if (!capillary_pair_vanishes(W_.list_.coordinates(pairs_[i], x_, B_), wet_[i], pp))
                on.push_back(i);
    }
    bool saturation = false;
    for (double k : cs.kappa) saturation = saturation || (H && k != 0);
    std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>> cg(saturation ? on.size() : 0);
    Vector8d ge;
    Matrix8d he;
    for (size_t j = 0; j < on.size(); ++j) {
        const int i = on[j];
        const SegmentPair& p = pairs_[i];
        const double scale = capped ? 0.5 * (cs.dS[pair_seg_[2 * i]] + cs.dS[pair_seg_[2 * i + 1]]) : 1.0;
        const double e = capillary_pair_energy(W_.list_.coordinates(p, x_, B_), m.segments[p.a].l0, m.segments[p.b].l0,
                                               wet_[i], pp, g || H ? &ge : nullptr, H ? &he : nullptr, psd,
                                               nullptr, scale, saturation ? &cg[j] : nullptr);
        if (!capped) E += e;
        if (!g && !H) continue;
        if (H && unpatterned_[i]) stale_ = true;
        scatter_element(&idx_[8 * i], H ? &slots_[64 * i] : nullptr, 8, ge.data(), H ? he.data() : nullptr, g, hv);
    }
    if (!saturation) return E;
    // The cap's coupling kappa_s G_s G_s^T, G_s the gradient of s's contact energy over its moving pairs.
    std::vector<std::vector<std::pair<int, double>>> G(seg_.size());
    for (size_t j = 0; j < on.size(); ++j) {
        const int i = on[j];
        if (contact[j] == 0) continue;
        for (int side = 0; side < 2; ++side) {
            const int s = pair_seg_[2 * i + side];
            if (cs.kappa[s] == 0) continue;
            for (int a = 0; a < 8; ++a)
                if (idx_[8 * i + a] >= 0) G[s].emplace_back(idx_[8 * i + a], cg[j][a]);
        }
    }
    for (size_t s = 0; s < G.size(); ++s)
        if (cs.kappa[s] != 0 && !add_outer_product(pattern_, G[s], cs.kappa[s], hv)) stale_ = true;
    return E;
}

}  // namespace fibernet
