#include "fibernet/wet/smooth_wet_energy.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/parallel.hpp"

namespace fibernet {

namespace {

constexpr size_t kParallelMin = 4096;
constexpr size_t kChunk = 16384;

}  // namespace

SmoothWetEnergy::SmoothWetEnergy(const NetworkEnergy& dry, const Eigen::Matrix2d& F, SmoothWetParams params,
                                 FiberPairs dry_crossings, const Eigen::VectorXd& q)
    : dry_(dry),
      F_(F),
      params_(std::move(params)),
      dry_crossings_(std::move(dry_crossings)),
      list_(dry.model(), [p = params_.pair](double length) { return p.support_distance(length); }, params_.skin) {
    params_.pair.check("wet");
    support_crossing_ = params_.pair.support_distance(0);
    support_contact_ = params_.pair.overlap_width + 1.5 * params_.pair.contact;
    support_slope_ = std::sin(params_.pair.angle_hi_deg * M_PI / 360);
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

void SmoothWetEnergy::index_list() const {
    const std::vector<SegmentPair>& P = list_.pairs();
    patterned_.assign(P.size(), -1);
    wet_.resize(P.size());
    for (size_t k = 0; k < P.size(); ++k) {
        const auto it = pattern_index_.find(key(P[k]));
        if (it != pattern_index_.end()) patterned_[k] = it->second;
        wet_[k] = wet_crossing(P[k]);
    }
}

bool SmoothWetEnergy::beyond_support(const Vector8d& X) const {
    const double ax0 = std::min(X[0], X[2]), ax1 = std::max(X[0], X[2]), ay0 = std::min(X[1], X[3]),
                 ay1 = std::max(X[1], X[3]);
    const double bx0 = std::min(X[4], X[6]), bx1 = std::max(X[4], X[6]), by0 = std::min(X[5], X[7]),
                 by1 = std::max(X[5], X[7]);
    const double gx = std::max({0.0, bx0 - ax1, ax0 - bx1}), gy = std::max({0.0, by0 - ay1, ay0 - by1});
    const double L = std::sqrt(std::max((X.segment<2>(2) - X.segment<2>(0)).squaredNorm(),
                                        (X.segment<2>(6) - X.segment<2>(4)).squaredNorm()));
    const double support = std::max(support_crossing_, support_contact_ + support_slope_ * L);
    return gx * gx + gy * gy > support * support;
}

void SmoothWetEnergy::ensure_list(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    if (list_.valid(x, B)) return;
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
    list_.build(x, B);
    build_pattern(x, B);
    stale_ = false;
    pattern_list_ = list_.builds();
    ++pattern_builds_;
}

std::vector<int> SmoothWetEnergy::nonzero_pairs(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const {
    const std::vector<SegmentPair>& P = list_.pairs();
    std::vector<char> on(P.size(), 0);
    parallel_ranges(P.size(), P.size() >= kParallelMin ? thread_count() : 1, [&](size_t lo, size_t hi) {
        for (size_t k = lo; k < hi; ++k) {
            const Vector8d X = list_.coordinates(P[k], x, B);
            on[k] = !beyond_support(X) && !capillary_pair_vanishes(X, wet_[k], params_.pair);
        }
    });
    std::vector<int> out;
    for (size_t k = 0; k < P.size(); ++k)
        if (on[k]) out.push_back(static_cast<int>(k));
    return out;
}

void SmoothWetEnergy::build_pattern(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    const std::vector<SegmentPair>& P = list_.pairs();
    wet_.resize(P.size());
    for (size_t k = 0; k < P.size(); ++k) wet_[k] = wet_crossing(P[k]);
    std::vector<char> take(P.size(), 0);
    for (int k : nonzero_pairs(x, B)) take[k] = 1;
    const double dp = params_.pattern_distance;
    for (size_t k = 0; k < P.size(); ++k) {
        if (take[k]) continue;
        const Vector8d X = list_.coordinates(P[k], x, B);
        take[k] = segment_distance(X.segment<2>(0), X.segment<2>(2), X.segment<2>(4), X.segment<2>(6)) < dp;
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
    const Eigen::SparseMatrix<double>& D = dry_.hessian_pattern();
    PatternBuilder builder(dry_.num_dofs());
    builder.add_pattern(D);
    builder.add_elements(idx, 8);
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
    if (H && H->nonZeros() != pattern_.nonZeros())
        throw std::logic_error("SmoothWetEnergy: the Hessian lacks the energy's pattern");
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    ensure_list(x, B);
    const std::vector<SegmentPair>& P = list_.pairs();
    const std::vector<int> on = nonzero_pairs(x, B);
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
    if (n == 0) dry_terms();
    for (size_t c0 = 0; c0 < n; c0 += chunk) {
        const size_t c1 = std::min(n, c0 + chunk);
        parallel_blocks(c1 - c0, threads, 64, [&] { if (c0 == 0) dry_terms(); }, [&](size_t lo, size_t hi) {
            for (size_t i = lo; i < hi; ++i) {
                const SegmentPair& p = P[on[c0 + i]];
                const Model& m = dry_.model();
                cE[i] = capillary_pair_energy(list_.coordinates(p, x, B), m.segments[p.a].l0, m.segments[p.b].l0,
                                              wet_[on[c0 + i]], params_.pair, g || H ? &cg[i] : nullptr,
                                              H ? &cH[i] : nullptr, psd);
            }
        });
        for (size_t i = 0; i < c1 - c0; ++i) {
            const int k = on[c0 + i];
            E += cE[i];
            if (!g && !H) continue;
            int idx[8];
            local_dofs(P[k], idx);
            const int pk = patterned_[k];
            if (H && pk < 0) stale_ = true;
            scatter_element(idx, H && pk >= 0 ? &slots_[64 * static_cast<size_t>(pk)] : nullptr, 8, cg[i].data(),
                            H ? cH[i].data() : nullptr, g, H && pk >= 0 ? hv : nullptr);
        }
    }
    return E;
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
    const Model& m = dry_.model();
    Vector8d g;
    Matrix8d He;
    for_each_nonzero(q, [&](const SegmentPair& p, const Vector8d& X) {
        capillary_pair_energy(X, m.segments[p.a].l0, m.segments[p.b].l0, wet_crossing(p), params_.pair, &g, &He);
        int node[4];
        Eigen::Vector2i shift[4];
        list_.nodes(p, node, shift);
        add_strain_terms<4>(dry_, F_, dF, comoving, node, shift, X, g, He, out);
    });
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
