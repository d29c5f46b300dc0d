#pragma once
// An SVG picture of a network coloured by rigid cluster (issue 4): fibers of one rigid cluster share a colour,
// fibers that are rigid on their own are thin and grey, the cluster holding both clamps (rigid spanning) is
// drawn thick in a red no other cluster gets; clamps are bars along the bottom and top edges. A title names L, q, pl,
// the cluster count and d; a legend says what each colour means.
#include <string>

#include "fibernet/network/network.hpp"
#include "fibernet/rigidity/rigidity.hpp"

namespace fibernet {

// `net` is the network whose fibers are the framework's first bodies (the clamped network when r.clamped).
std::string rigid_cluster_svg(const Network& net, const RigidityResult& r);

}  // namespace fibernet
