#pragma once
// Bundles (issue 6): groups of fibers joined by nearly aligned bridges (locked bundle bridges, or a home pair within
// `angle_deg` of parallel), found by union-find over fibers.
#include <Eigen/Core>
#include <map>
#include <vector>

#include "fibernet/model/model.hpp"
#include "fibernet/wet/bridge.hpp"

namespace fibernet {

struct BundleStats {
    std::vector<int> bundle_of_fiber;   // label per fiber (every fiber has one; a lone fiber is its own label)
    std::vector<int> sizes;             // fibers per bundle of 2 or more, largest first
    std::map<int, int> histogram;       // size -> number of bundles (sizes >= 2)
    int bundled_fibers = 0;             // fibers in bundles of 2 or more
    int aligned_bridges = 0;
};

BundleStats bundles(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B, const std::vector<Bridge>& bridges,
                    double angle_deg = 10);

}  // namespace fibernet
