#include "fibernet/wet/bundles.hpp"
#include "fibernet/util/union_find.hpp"

#include <algorithm>
#include <cmath>

namespace fibernet {

BundleStats bundles(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<Bridge>& bridges,
                    double angle_deg) {
    const int nf = static_cast<int>(m.chains.size());
    UnionFind fibers(nf);
    BundleStats s;
    const double smax = std::sin(angle_deg * M_PI / 180);
    for (const Bridge& b : bridges) {
        const BridgeElement e = resolve(m, b);
        const Vector16d X = element_coordinates(e, x, B);
        const Eigen::Vector2d d1 = X.segment<2>(4) - X.segment<2>(2), d2 = X.segment<2>(12) - X.segment<2>(10);
        const double sin_a = std::abs(d1.x() * d2.y() - d1.y() * d2.x()) / (d1.norm() * d2.norm());
        if (!b.locked && sin_a > smax) continue;
        ++s.aligned_bridges;
        fibers.unite(b.f1, b.f2);
    }
    std::vector<int> count(nf, 0);
    s.bundle_of_fiber.resize(nf);
    for (int f = 0; f < nf; ++f) ++count[s.bundle_of_fiber[f] = fibers.find(f)];
    for (int f = 0; f < nf; ++f)
        if (count[f] >= 2) s.sizes.push_back(count[f]), ++s.histogram[count[f]], s.bundled_fibers += count[f];
    std::sort(s.sizes.rbegin(), s.sizes.rend());
    return s;
}

}  // namespace fibernet
