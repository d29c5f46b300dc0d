#pragma once
// The wet network's energy as one smooth function (issue 22; docs/wet.md, "The smooth model"):
//   E(q) = dry stretching + bending (NetworkEnergy, unchanged) + sum over segment pairs of capillary_pair_energy
// over every pair of segments of different fibers. Pairs farther apart than the pair term's support distance have
// exactly zero energy, so only the pairs of a neighbour list (neighbour_list.hpp, built with a skin) are evaluated; the
// list is valid while no node has moved more than half the skin since its build; every evaluation first rebuilds it
// where it is no longer valid, so values and gradients are always those of the whole energy. A rebuild never changes
// the energy, only which pairs are evaluated.
//
// Hessian pattern. Most listed pairs are zero at any one state; the pattern holds the dry pattern and the 4-node block
// of every *patterned* pair: those non-zero at the last rebuild() or closer than `pattern_distance` there. A Hessian
// evaluated where a non-zero pair is not patterned leaves that pair's block out (value and gradient stay exact) and
// sets pattern_stale(); the driver (relax_smooth_wet) then calls rebuild(). The pattern is fixed between rebuild()
// calls, as a solver expects (objective.hpp). With follow_pattern(true), for a solver that follows a changing
// pattern (SolverCapabilities::follows_pattern), a Hessian evaluated where a non-zero pair (or the partner cap's
// coupling) is not patterned first rebuilds the pattern there, from the list in use, and gives H the new pattern;
// it is then never stale, and pattern_version() counts the new patterns. The pattern rebuilt is a function of the
// state alone (the pairs non-zero or within `pattern_distance`, which every valid list holds).
//
// Partner cap (SmoothWetParams::bundle_partners = N > 0, bundle_saturation.hpp): the contact parts of the pairs are
// summed per segment and saturated there, so a pair's contact term enters with the weight (S'_a + S'_b) / 2 and a
// segment inside the saturation blend couples all its partners (a rank-one term, whose blocks the pattern adds for
// segments near the blend); the energy is then a pass over the pairs' values ahead of their derivatives.
//
// With beta = 0 no pair is evaluated and the pattern is the dry one: values, gradients and Hessians are the dry ones
// bit for bit. Sums run in pair order after the dry terms, the same for any thread count.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

#include "fibernet/energy/network_region.hpp"
#include "fibernet/wet/bridge.hpp"
#include "fibernet/wet/capillary_pair.hpp"
#include "fibernet/wet/neighbour_list.hpp"
#include "fibernet/wet/wet_objective.hpp"

namespace fibernet {

struct SmoothWetParams {
    CapillaryPairParams pair;
    double skin = 0.5;              // neighbour-list skin (seed units)
    double pattern_distance = 0;    // 0: 1.5 contact + overlap_width + crossing_width
    int bundle_partners = 0;        // the partner cap N (bundle_saturation.hpp); 0: none
};

struct SmoothWetSplit {
    double stretch = 0, bend = 0, crossing = 0, contact = 0;
    double capillary() const { return crossing + contact; }
    double total() const { return stretch + bend + crossing + contact; }
};

class SmoothWetEnergy : public WetObjective {
public:
    // dry_crossings: fiber pairs (lower first) whose crossings get no crossing term (crosslinked, or left dry by the
    // wetting rule); their contact term stays. Keeps a reference to `dry`. Builds the neighbour list at q.
    SmoothWetEnergy(const NetworkEnergy& dry, const Eigen::Matrix2d& F, SmoothWetParams params,
                    FiberPairs dry_crossings, const Eigen::VectorXd& q);
    SmoothWetEnergy(const NetworkEnergy&& dry, const Eigen::Matrix2d& F, SmoothWetParams params,
                    FiberPairs dry_crossings, const Eigen::VectorXd& q) = delete;

    int size() const override { return dry_.num_dofs(); }
    double value(const Eigen::VectorXd& q) override;
    double gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) override;
    double hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool project_psd) override;
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return pattern_; }
    // 0 while the pattern is fixed; with follow_pattern(true), 1 + the pattern builds so far.
    long pattern_version() const override { return follow_ ? 1 + pattern_builds_ : 0; }
    // Whether a Hessian rebuilds the pattern where it does not cover the state (above), instead of leaving the
    // missing blocks out and setting pattern_stale().
    void follow_pattern(bool on) { follow_ = on; }
    // The energy of the coordinates `coords` alone, at the cost of their elements (Objective::restriction; nonlinear
    // elimination): a SmoothWetRegion (smooth_wet_region.hpp), or the dry NetworkRegion at beta = 0.
    std::unique_ptr<Objective> restriction(const Eigen::VectorXd& q, const std::vector<int>& coords) override;

    // Rebuilds the neighbour list and the Hessian pattern at q.
    void rebuild(const Eigen::VectorXd& q);
    // Whether the pattern was built with the list now in use (false once an evaluation had to rebuild the list).
    bool pattern_current() const { return pattern_list_ == list_.builds(); }
    // A Hessian since the last rebuild() met a non-zero pair outside the pattern.
    bool pattern_stale() const { return stale_; }
    int list_builds() const { return list_.listings(); }
    int pattern_builds() const { return pattern_builds_; }
    // Seconds spent building and updating the list (with the list's indexes) and building patterns, so far (parts of
    // the evaluations' time).
    double seconds_lists() const { return seconds_lists_; }
    double seconds_patterns() const { return seconds_patterns_; }

    void strain_derivatives(const Eigen::VectorXd& q, const Eigen::Matrix2d& dF, EnergyEval& out,
                            bool comoving = false) const override;
    const NetworkEnergy& dry() const override { return dry_; }
    const Eigen::Matrix2d& F() const override { return F_; }
    const SmoothWetParams& params() const { return params_; }
    const FiberPairs& dry_crossings() const { return dry_crossings_; }

    SmoothWetSplit split(const Eigen::VectorXd& q) const;
    // The non-zero pairs at q as bridges, for reports, bundles and SVGs: a pair with a crossing share (b W_A W_B > 0)
    // is a crossing bridge, one with only a contact share a locked (bundle) bridge.
    std::vector<Bridge> bridges(const Eigen::VectorXd& q, double* crossing_weight = nullptr) const;

private:
    friend class SmoothWetRegion;
    double eval(const Eigen::VectorXd& q, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd);
    bool active() const { return params_.pair.beta != 0; }
    bool wet_crossing(const SegmentPair& p) const;
    // The pattern at x from the list in use: `on` its non-zero pairs there, n the partner counts (with the cap).
    void build_pattern(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& on,
                       const std::vector<double>& n);
    // Follow mode: a pattern built at x unless it covers the non-zero pairs `on`, and H in it.
    void cover(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& on,
               const std::vector<double>& n, Eigen::SparseMatrix<double>& H);
    void new_pattern(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<int>& on,
                     const std::vector<double>& n);
    void local_dofs(const SegmentPair& p, int idx[8]) const;
    // f(pair, its local coordinates) for every non-zero pair at q, in list order.
    void for_each_nonzero(const Eigen::VectorXd& q,
                          const std::function<void(const SegmentPair&, const Vector8d&)>& f) const;
    // The partner cap (bundle_saturation.hpp) over the non-zero pairs `on` at some positions.
    struct PartnerCap {
        std::vector<double> scale;    // per entry of `on`: the pair's contact weight (S'(n_a) + S'(n_b)) / 2
        std::vector<char> touching;   // per entry of `on`: its contact term is non-zero
        std::vector<int> saturating;  // segments with S''(n_a) != 0, ascending
        std::vector<double> kappa;    // per saturating segment: d2E / dC_a^2 = -S''(n_a) / (2 beta l_a) >= 0
        std::vector<double> n;        // per segment: n_a
        double crossing = 0, contact = 0;  // the crossing terms' energy and the capped contact energy
    };
    bool capped() const { return params_.bundle_partners > 0; }
    // The partner cap from the non-zero pairs' crossing and contact energies Ex, Ec (per entry of `on`).
    PartnerCap partner_cap(const std::vector<int>& on, const std::vector<double>& Ex, const std::vector<double>& Ec) const;
    // Indices of the listed pairs that are non-zero at x (in list order); pc (if given) gets the partner cap over them,
    // each pair's values computed once.
    std::vector<int> nonzero_pairs(const Eigen::VectorXd& x, const Eigen::Matrix2d& B, PartnerCap* pc = nullptr) const;
    // Per saturating segment: the entries of `on` whose pair holds it and has a contact term.
    std::vector<std::vector<int>> saturating_pairs(const PartnerCap& pc, const std::vector<int>& on) const;
    // Adds the cap's coupling of each saturating segment's partners, kappa_a G_a G_a^T with G_a the gradient of its
    // contact energy C_a (from the pairs' contact gradients cgrad, in `on` order), to the values hv of the pattern.
    void add_saturation_hessian(const PartnerCap& pc, const std::vector<int>& on,
                                const std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>>& cgrad, double* hv);
    // The cap's extra pattern: per segment, the blocks between the segments of its aligned patterned partners.
    void add_partner_blocks(const std::vector<char>& take, const Eigen::VectorXd& x, const Eigen::Matrix2d& B,
                            const std::vector<double>& n, std::vector<int>& idx) const;
    // f(pair, its parts) for every non-zero pair at q, in list order.
    void for_each_part(const Eigen::VectorXd& q,
                       const std::function<void(const SegmentPair&, const CapillaryPairParts&)>& f) const;
    // Rebuilds the list if it is not valid at x (and indexes it: index_list).
    void ensure_list(const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const;
    // Per listed pair: its patterned index and whether its crossing is wet (index_wet: the latter alone).
    void index_list() const;
    void index_wet() const;
    // Beyond this distance a pair of segments whose longer one has length L is exactly zero.
    double support_distance(double L) const;
    // Whether the pair at X is surely zero from its segments' bounding boxes alone (farther apart than the support).
    bool beyond_support(const Vector8d& X) const;
    // A segment's bounding box and length at x, so that a pass over many pairs tests each pair by two boxes and its
    // image offset (apart()) instead of gathering its coordinates.
    struct SegmentBox {
        double x0, x1, y0, y1, length;
    };
    SegmentBox segment_box(int s, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) const;
    // beyond_support() from the boxes of a pair's segments a and b, b at the offset t (B times the pair's image).
    bool apart(const SegmentBox& a, const SegmentBox& b, const Eigen::Vector2d& t) const;
    static std::uint64_t key(const SegmentPair& p);
    // Per segment, the indices of the listed pairs that hold it (compressed rows over the list now in use).
    void index_segment_pairs() const;

    const NetworkEnergy& dry_;
    Eigen::Matrix2d F_;
    SmoothWetParams params_;
    FiberPairs dry_crossings_;
    mutable NeighbourList list_;   // rebuilt where an evaluation finds it invalid (a cache of the geometry)
    PairSupport support_;          // support_distance()
    Eigen::SparseMatrix<double> pattern_, dry_H_;
    std::vector<int> dry_slot_;
    mutable std::vector<int> patterned_;  // per listed pair: its index among the patterned pairs, or -1
    mutable std::vector<char> wet_;       // per listed pair: wet_crossing()
    mutable int indexed_build_ = -1;      // the list build that index_list() gave patterned_ and wet_ for
    mutable std::vector<int> patterned_next_;  // index_list()'s buffers, kept to spare a list-sized allocation each
    mutable std::vector<char> wet_next_;
    std::unordered_map<std::uint64_t, int> pattern_index_;  // patterned pair (key()) -> its index
    int pattern_list_ = 0, pattern_builds_ = 0;
    std::vector<int> slots_;       // 64 per patterned pair (element_slots)
    size_t n_patterned_ = 0;
    bool stale_ = false;
    bool follow_ = false;
    mutable double seconds_lists_ = 0, seconds_patterns_ = 0;
    bool retrying_ = false;  // eval() again in a pattern rebuilt for the cap's coupling
    EnergyEval eval_;
    struct LastState {  // the non-zero pairs and the partner cap at the positions of the last evaluation
        Eigen::VectorXd x;
        int builds = -1;  // the list build they index
        std::vector<int> on;
        PartnerCap pc;
    } at_;
    // Per-chunk pair results (eval), kept between evaluations.
    std::vector<double> chunk_E_;
    std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>> chunk_g_;
    std::vector<Matrix8d, Eigen::aligned_allocator<Matrix8d>> chunk_H_;
    std::vector<Vector8d, Eigen::aligned_allocator<Vector8d>> contact_grad_;  // per non-zero pair (partner cap)
    std::vector<int> seg_fiber_, seg_index_;  // per segment: fiber and index in its chain
    mutable std::vector<int> seg_pair_start_, seg_pair_;  // index_segment_pairs()
    mutable int seg_pair_list_ = -1;                      // the list build they index
    std::shared_ptr<const NodeElements> incidence_;       // built on the first restriction()
};

}  // namespace fibernet
