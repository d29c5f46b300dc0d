#include "fibernet/wet/wet_energy.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "fibernet/energy/sparse_pattern.hpp"
#include "fibernet/util/parallel.hpp"

namespace fibernet {

namespace {
std::atomic<std::uint64_t> next_id{1};
}

WetEnergy::WetEnergy(const NetworkEnergy& dry, const Eigen::Matrix2d& F, std::vector<Bridge> bridges, WetParams params)
    : dry_(dry), F_(F), bridges_(std::move(bridges)), params_(std::move(params)), id_(next_id++) {
    const Model& m = dry.model();
    // Resolved on the element threads: a new energy per active-set round, and at 1e4 fibers resolving 4e4 bridges
    // (scattered model lookups) took about 5 ms, like the rest of a small local round's bookkeeping.
    elements_.resize(bridges_.size());
    const int threads = bridges_.size() >= kParallelMin ? thread_count() : 1;
    parallel_ranges(bridges_.size(), threads, [&](size_t lo, size_t hi) {
        for (size_t k = lo; k < hi; ++k) elements_[k] = resolve(m, bridges_[k]);
    });
}

// The Hessian pattern and slots on first use: a round that only needs the gradient, or solves a region
// (wet_region.hpp), never builds them.
const Eigen::SparseMatrix<double>& WetEnergy::hessian_pattern() const {
    if (pattern_built_) return pattern_;
    const NetworkEnergy& dry = dry_;
    if (!active()) {
        pattern_ = dry.hessian_pattern();
        pattern_built_ = true;
        return pattern_;
    }
    // Union pattern of the dry one and the bridge elements.
    const Eigen::SparseMatrix<double>& P = dry.hessian_pattern();
    const int n = dry.num_dofs();
    auto local_dof = [&](const BridgeElement& e, int a) { return e.node[a / 2] < 0 ? -1 : dry.dof(e.node[a / 2], a % 2); };
    std::vector<int> idx(16 * elements_.size());
    for (size_t k = 0; k < elements_.size(); ++k)
        for (int a = 0; a < 16; ++a) idx[16 * k + a] = local_dof(elements_[k], a);
    PatternBuilder union_pattern(n);
    union_pattern.add_pattern(P);
    union_pattern.add_elements(idx, 16);
    pattern_ = union_pattern.build();
    dry_slot_ = subpattern_slots(pattern_, P);
    element_slots(pattern_, idx, 16, bridge_slots_);
    dry_H_ = P;
    pattern_built_ = true;  // only now: a build that threw is tried again, not half used
    return pattern_;
}

double WetEnergy::eval(const Eigen::VectorXd& q, Eigen::VectorXd* g, Eigen::SparseMatrix<double>* H, bool psd) {
    const unsigned want = (g ? kGradient : 0u) | (H ? kHessian : 0u) | (psd ? kProjectPSD : 0u);
    if (H) hessian_pattern();
    if (!active()) {  // the dry energy itself: bit for bit
        dry_.evaluate(q, F_, Eigen::Matrix2d::Zero(), want, eval_, H);
        if (g) g->swap(eval_.gradient);
        return eval_.energy;
    }
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    // Elements in chunks: each chunk's elements are evaluated in parallel into their own slots, then added in element
    // order after the dry terms, so the sums (and every solve) are bit for bit the same for any thread count.
    // The dry terms are evaluated on the calling thread beside the first chunk's elements, which the other threads
    // start on at once (the dry terms of a 1e4-fiber network cost about as much as 2e4 bridge elements).
    // Chunks bound the Hessian blocks' buffer (2 KB per element); without a Hessian one chunk holds every element.
    // Threads get at least kParallelMin / 2 elements each, dry elements counted a quarter (a thread start costs about
    // as much as 20 bridge elements).
    const size_t ne = elements_.size();
    const size_t nd = dry_.model().segments.size() + dry_.model().hinges.size();
    const size_t chunk = H ? std::min(ne, chunk_) : ne;
    const int threads =
        static_cast<int>(std::min<size_t>(thread_count(), std::max<size_t>(1, 2 * (ne + nd / 4) / kParallelMin)));
    chunk_E_.resize(chunk);
    if (g) chunk_g_.resize(chunk);
    if (H) chunk_H_.resize(chunk);
    double E = 0;
    double* hv = nullptr;
    auto dry_terms = [&] {
        dry_.evaluate(q, F_, Eigen::Matrix2d::Zero(), want, eval_, H ? &dry_H_ : nullptr);
        E = eval_.energy;
        if (g) g->swap(eval_.gradient);
        if (H) {
            if (H->nonZeros() != hessian_pattern().nonZeros()) throw std::logic_error("Hessian lacks the wet energy's pattern");
            hv = assign_subpattern(dry_H_, dry_slot_, *H);
        }
    };
    for (size_t c0 = 0; c0 < ne; c0 += chunk) {
        const size_t c1 = std::min(ne, c0 + chunk);
        parallel_blocks(c1 - c0, threads, 64, [&] { if (c0 == 0) dry_terms(); }, [&](size_t lo, size_t hi) {
            for (size_t i = lo; i < hi; ++i) {
                const BridgeElement& e = elements_[c0 + i];
                chunk_E_[i] = bridge_element_energy(e, element_coordinates(e, x, B), params_.beta, params_.law,
                                                    g ? &chunk_g_[i] : nullptr, H ? &chunk_H_[i] : nullptr, psd);
            }
        });
        for (size_t k = c0; k < c1; ++k) {
            const size_t i = k - c0;
            const BridgeElement& e = elements_[k];
            E += chunk_E_[i];
            if (g)
                for (int a = 0; a < 16; ++a) {
                    const int r = e.node[a / 2] < 0 ? -1 : dry_.dof(e.node[a / 2], a % 2);
                    if (r >= 0) (*g)[r] += chunk_g_[i][a];
                }
            if (H) {
                const int* sl = &bridge_slots_[256 * k];
                const Matrix16d& he = chunk_H_[i];
                for (int j = 0; j < 256; ++j)
                    if (sl[j] >= 0) hv[sl[j]] += he(j / 16, j % 16);
            }
        }
    }
    return E;
}

double WetEnergy::value(const Eigen::VectorXd& q) { return eval(q, nullptr, nullptr, false); }
double WetEnergy::gradient(const Eigen::VectorXd& q, Eigen::VectorXd& g) { return eval(q, &g, nullptr, false); }
double WetEnergy::hessian(const Eigen::VectorXd& q, Eigen::VectorXd& g, Eigen::SparseMatrix<double>& H, bool psd) {
    return eval(q, &g, &H, psd);
}

void WetEnergy::strain_derivatives(const Eigen::VectorXd& q, const Eigen::Matrix2d& dF, EnergyEval& out,
                                   bool comoving) const {
    dry_.evaluate(q, F_, dF, kStrain | (comoving ? kComoving : 0u), out);
    if (!active()) return;
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    Vector16d g;
    Matrix16d He;
    for (const BridgeElement& e : elements_) {
        const Vector16d X = element_coordinates(e, x, B);
        bridge_element_energy(e, X, params_.beta, params_.law, &g, &He);
        add_strain_terms<8>(dry_, F_, dF, comoving, e.node, e.shift, X, g, He, out);
    }
}

std::vector<double> WetEnergy::bridge_energies(const Eigen::VectorXd& q) const {
    std::vector<double> out(elements_.size(), 0.0);
    if (params_.beta == 0) return out;
    const Eigen::VectorXd x = dry_.positions(q, F_);
    const Eigen::Matrix2d B = F_ * dry_.model().box.B0();
    for (size_t k = 0; k < elements_.size(); ++k)
        out[k] = bridge_element_energy(elements_[k], element_coordinates(elements_[k], x, B), params_.beta,
                                       params_.law, nullptr, nullptr);
    return out;
}

WetSplit WetEnergy::split(const Eigen::VectorXd& q) const {
    EnergyEval ev;
    dry_.evaluate(q, F_, Eigen::Matrix2d::Zero(), kValue, ev);
    WetSplit s;
    s.stretch = ev.stretch, s.bend = ev.bend;
    for (double e : bridge_energies(q)) s.capillary += e;
    return s;
}

}  // namespace fibernet
