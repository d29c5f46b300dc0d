// NetworkRegion (energy/network_region.hpp) and SubsetObjective (solve/subset_objective.hpp): the energy restricted to
// a set of coordinates is the full energy less a constant, and its gradient and Hessian are the full ones' entries
// (regimes: periodic images and a sheared box, from a perturbed state, with and without the PSD projection).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "fibernet/energy/network_energy.hpp"
#include "fibernet/energy/network_region.hpp"
#include "fibernet/model/discretize.hpp"
#include "fibernet/network/mikado.hpp"
#include "fibernet/solve/subset_objective.hpp"
#include "fibernet/util/random.hpp"

using namespace fibernet;

namespace {
double entry(const Eigen::SparseMatrix<double>& H, int i, int j) { return H.coeff(std::min(i, j), std::max(i, j)); }
}  // namespace

TEST_CASE("a restricted energy is the full one less a constant, with the full derivatives' entries", "[energy][region]") {
    MikadoParams mp;
    mp.L = 3, mp.q = 8, mp.pl = 1, mp.seed = 5;
    DiscretizationParams dp;
    dp.scheme = Scheme::Even, dp.aspect_ratio = 10;
    const Model m = discretize(generate_mikado(mp), dp);
    const NetworkEnergy e(m);
    Eigen::Matrix2d F = Eigen::Matrix2d::Identity();
    F(0, 1) = 0.2, F(1, 1) = 0.95;  // sheared and compressed: some segments buckle, the projection matters
    StrainedEnergy full(e, F);
    const int n = e.num_dofs();
    Rng rng(11);
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = 0.05 * (2 * rng.uniform() - 1);
    // Every third node's coordinates, and the nodes near the box's left edge (their segments cross periodic images).
    std::vector<int> coords;
    for (int v = 0; v < m.num_nodes(); ++v)
        if (v % 3 == 0 || m.x[2 * v] < 2)
            for (int c = 0; c < 2; ++c)
                if (e.dof(v, c) >= 0) coords.push_back(e.dof(v, c));
    std::sort(coords.begin(), coords.end());
    REQUIRE(coords.size() > 20);
    REQUIRE(static_cast<int>(coords.size()) < n);

    Eigen::VectorXd gf, ga;
    Eigen::SparseMatrix<double> Hf = full.hessian_pattern();
    for (int kind = 0; kind < 2; ++kind) {
        std::unique_ptr<Objective> sub;
        if (kind == 0) sub = full.restriction(q, coords);
        else sub = std::make_unique<SubsetObjective>(full, q, coords);
        CAPTURE(kind);
        REQUIRE(sub->size() == static_cast<int>(coords.size()));
        Eigen::VectorXd qa(coords.size());
        for (size_t k = 0; k < coords.size(); ++k) qa[k] = q[coords[k]];
        Eigen::SparseMatrix<double> Ha = sub->hessian_pattern();
        const double c0 = full.value(q) - sub->value(qa);
        // Move the region's coordinates: the difference stays the same constant.
        Eigen::VectorXd q2 = q, qa2 = qa;
        for (size_t k = 0; k < coords.size(); ++k) q2[coords[k]] = qa2[k] = qa[k] + 0.03 * (2 * rng.uniform() - 1);
        const double E2 = full.value(q2);
        CHECK(E2 - sub->value(qa2) == Approx(c0).margin(1e-12 * std::abs(E2)));
        for (bool psd : {false, true}) {
            CAPTURE(psd);
            full.hessian(q2, gf, Hf, psd);
            sub->hessian(qa2, ga, Ha, psd);
            double gscale = gf.lpNorm<Eigen::Infinity>(), hscale = 0;
            for (int k = 0; k < Hf.nonZeros(); ++k) hscale = std::max(hscale, std::abs(Hf.valuePtr()[k]));
            // Sums of the same element terms in another order: equal to rounding (1e-12 of the largest entry).
            for (size_t a = 0; a < coords.size(); ++a) {
                CHECK(std::abs(ga[a] - gf[coords[a]]) <= 1e-12 * gscale);
                for (size_t b = a; b < coords.size(); ++b)
                    CHECK(std::abs(entry(Ha, a, b) - entry(Hf, coords[a], coords[b])) <= 1e-12 * hscale);
            }
        }
    }
}
