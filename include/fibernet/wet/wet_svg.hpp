#pragma once
// Pictures for `fibernet wet`: the network dry and wet side by side (bridges as dots, bundles coloured), and a
// histogram chart of pore equivalent diameters for several states. Plain SVG text, no dependencies.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "fibernet/model/model.hpp"
#include "fibernet/wet/bridge.hpp"
#include "fibernet/wet/bundles.hpp"

namespace fibernet {

struct SvgPanel {
    std::string title;
    Eigen::VectorXd x;               // node positions
    Eigen::Matrix2d B;               // box matrix
    std::vector<Bridge> bridges;
    std::vector<int> bundle_of_fiber;  // empty: no colouring
    std::vector<int> bundle_size;      // per label: fibers in it
};

std::string network_svg(const Model& m, const std::vector<SvgPanel>& panels, double pixels = 420);

// Where a bridge is drawn: the crossing point of its two segments' lines (clamped near the first segment), in the box.
Eigen::Vector2d bridge_point(const Model& m, const Bridge& b, const Eigen::VectorXd& x, const Eigen::Matrix2d& B);

// Histograms of `values` per series (same bins), as outlined bars; x label, log-spaced bins if log_bins.
std::string histogram_svg(const std::vector<std::string>& names, const std::vector<std::vector<double>>& values,
                          const std::string& xlabel, int bins = 20);

}  // namespace fibernet
