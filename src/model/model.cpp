#include "fibernet/model/model.hpp"

#include <algorithm>
#include <limits>

namespace fibernet {

ModelSummary summarize(const Model& m) {
    ModelSummary s;
    s.nodes = m.num_nodes();
    s.dofs = 2 * s.nodes;
    for (char f : m.fixed) s.dofs -= f ? 2 : 0;
    s.segments = static_cast<int>(m.segments.size());
    s.hinges = static_cast<int>(m.hinges.size());
    s.supernodes = static_cast<int>(m.supernodes.size());
    s.fibers = static_cast<int>(m.chains.size());
    if (!m.segments.empty()) {
        s.shortest_segment = std::numeric_limits<double>::infinity();
        double sum = 0;
        for (const auto& seg : m.segments) {
            s.shortest_segment = std::min(s.shortest_segment, seg.l0);
            s.longest_segment = std::max(s.longest_segment, seg.l0);
            sum += seg.l0;
        }
        s.mean_segment = sum / m.segments.size();
    }
    return s;
}

}  // namespace fibernet
