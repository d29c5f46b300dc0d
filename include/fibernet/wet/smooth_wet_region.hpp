#pragma once
// The smooth wet energy (smooth_wet_energy.hpp) restricted to a set of coordinates, every other one held
// (Objective::restriction; issue 23, nonlinear elimination, solve/nonlinear_elimination.hpp). Evaluated at the cost of
// the set's elements: the dry segments and hinges at its nodes (NetworkRegion) and the segment pairs of the energy's
// neighbour list that hold a segment with a node in the set ("moving" pairs). Up to a constant (the held elements) its
// value, gradient and Hessian are the whole energy's restricted to the set.
//
// Partner cap (bundle_saturation.hpp): E_contact = sum_a -(beta / 2) l_a S(n_a) couples a segment's pairs through n_a.
// A moving pair's segment b outside the region (a partner) keeps its pairs with held segments, whose contact energy is
// summed once when the pairs are taken; the region's energy then holds b's term less its value with the region's pairs
// at zero, a constant that does not depend on which pairs were taken. The saturation coupling kappa_a G_a G_a^T (G_a
// over the moving pairs of a) gets pattern blocks between the moving pairs of each segment near the blend.
//
// The neighbour list is the energy's: valid while the set's nodes stay within half the skin of the list's build (the
// held nodes do not move). An evaluation beyond that finds the region's pairs anew (NeighbourList::find, at the cost of
// the region; a rebuild never changes the energy) and keeps them; W's list gets them when the region is destroyed, so
// that a local solve passes over the whole list once, not at every update (W evaluated meanwhile finds its list not
// valid and rebuilds it, NeighbourList::pending; the region's pairs are then void). A Hessian that meets a non-zero pair outside the region's pattern (built with the first list)
// leaves that block out, as the whole energy does (pattern_stale()).
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "fibernet/energy/network_region.hpp"
#include "fibernet/energy/objective.hpp"
#include "fibernet/wet/smooth_wet_energy.hpp"

namespace fibernet {

class SmoothWetEnergy;

class SmoothWetRegion : public EvaluatedObjective {
public:
    // W's energy over the coordinates `coords` of q (sorted, distinct). Keeps a reference to W.
    SmoothWetRegion(SmoothWetEnergy& W, const NodeElements& inc, const Eigen::VectorXd& q, const std::vector<int>& coords);
    // Puts the pairs the region found while it moved into W's list (one pass over the list per region, not per update).
    ~SmoothWetRegion() override;
    SmoothWetRegion(const SmoothWetRegion&) = delete;
    SmoothWetRegion& operator=(const SmoothWetRegion&) = delete;

    int size() const override { return static_cast<int>(coords_.size()); }
    const Eigen::SparseMatrix<double>& hessian_pattern() const override { return pattern_; }
    bool pattern_stale() const { return stale_; }

private:
    double eval(const Eigen::VectorXd& qa, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) override;
    // The moving pairs from W's list as it is now (take_pairs), or as the region found them (eval), then their
    // coordinates' region indices and segments, and with the cap the held pairs' contact energies (index_pairs,
    // take_cap_segments).
    void take_pairs();
    void index_pairs();
    void take_cap_segments();
    void slot_pairs();  // slots_ and unpatterned_ for the pairs taken
    void place(const Eigen::VectorXd& qa);  // the region's coordinates into x_
    // The moving pairs whose segments' boxes lie within the support at x_ (indices into pairs_): a superset of the
    // non-zero ones, which the pair term itself then tells (CapillaryPairParts::nonzero).
    std::vector<int> candidates() const;
    // The partner cap over the cap's segments (seg_) at x_, from the moving pairs `cand` (candidates()): `on` gets the
    // non-zero ones and `contact` (if asked) each one's contact energy; per segment n, S'(n) and the coupling
    // kappa = -S''(n) / (2 beta l); E (if asked) gets the capped capillary energy of the region up to a constant.
    struct CapState {
        std::vector<double> n, dS, kappa;
    };
    CapState cap_state(const std::vector<int>& cand, std::vector<int>& on, double* E, std::vector<double>* contact) const;

    SmoothWetEnergy& W_;
    std::vector<int> coords_, coord_x_;  // region coordinate -> coordinate of q, and its entry of x_
    std::vector<int> nodes_;             // the region's nodes
    std::vector<int> segs_;              // segments with a node in the region
    std::vector<char> in_region_;        // per segment: it has a node in the region
    Eigen::VectorXd x_;                  // node positions of the whole network (the held ones as at construction)
    Eigen::VectorXd xref_;               // per region coordinate: its node's reference coordinate
    Eigen::Matrix2d B_;
    NetworkRegion dry_;
    // The moving pairs (the pairs of W's list that hold a segment of the region, in list order), whether each is a wet
    // crossing, and the region index of their 8 local coordinates (-1: held). Once the region has left W's list
    // (own_pairs_), it finds them itself (NeighbourList::find) and W's list holds stale ones until the destructor.
    std::vector<SegmentPair> pairs_;
    std::vector<char> wet_;
    bool own_pairs_ = false;
    std::vector<int> idx_;      // 8 per pair
    std::vector<int> slots_;    // 64 per pair: value slots of its block in pattern_ (-1: none)
    std::vector<char> unpatterned_;  // per pair: the pattern lacks part of its block
    // The region's segments and their partners (ascending), per pair its two segments' places there; the partner
    // cap's contact energy per such segment of its pairs with held segments (0 for the region's own).
    std::vector<int> seg_, pair_seg_;
    std::vector<int> local_x_;    // per entry of x_: its region coordinate, -1 if held or fixed
    std::vector<int> seg_place_;  // per segment of the model: its place in seg_, -1 if none
    std::vector<double> fixed_C_;
    mutable std::vector<SmoothWetEnergy::SegmentBox> box_;  // per entry of seg_, at x_ (candidates())
    int list_build_ = -1;
    Eigen::SparseMatrix<double> pattern_, dry_H_;
    std::vector<int> dry_slot_;
    bool stale_ = false;
};

}  // namespace fibernet
