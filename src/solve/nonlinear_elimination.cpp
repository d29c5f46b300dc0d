#include "fibernet/solve/nonlinear_elimination.hpp"

#include <algorithm>
#include <chrono>
#include <memory>

#include "fibernet/solve/newton.hpp"
#include "fibernet/solve/subset_objective.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

void EliminationOptions::check(const std::string& where) const {
    check_value(threshold > 0 && threshold < 1, threshold, where, "elimination.threshold", "must lie in (0, 1)");
    check_value(hops >= 0, hops, where, "elimination.hops", "must be >= 0");
    check_value(max_fraction > 0 && max_fraction <= 1, max_fraction, where, "elimination.max_fraction",
                "must lie in (0, 1]");
    check_value(local_rtol > 0 && local_rtol < 1, local_rtol, where, "elimination.local_rtol", "must lie in (0, 1)");
    check_value(local_max_iter >= 1, local_max_iter, where, "elimination.local_max_iter", "must be >= 1");
    check_value(block >= 0, block, where, "elimination.block", "must be >= 0 (0: the hot places only)");
    check_value(overlap >= 0, overlap, where, "elimination.overlap", "must be >= 0");
}

NonlinearElimination::NonlinearElimination(const Eigen::SparseMatrix<double>& P, EliminationOptions opt, bool median_floor,
                                           double max_step)
    : opt_(opt), median_floor_(median_floor), max_step_(max_step) {
    opt_.check("newton");
    set_pattern(P);
}

void NonlinearElimination::set_pattern(const Eigen::SparseMatrix<double>& P) {
    const int n = static_cast<int>(P.cols());
    // Both triangles of the pattern, without the diagonal: coordinate i couples j when some element holds both.
    adj_start_.assign(n + 1, 0);
    for (int j = 0; j < n; ++j)
        for (int p = P.outerIndexPtr()[j]; p < P.outerIndexPtr()[j + 1]; ++p)
            if (P.innerIndexPtr()[p] != j) ++adj_start_[j + 1], ++adj_start_[P.innerIndexPtr()[p] + 1];
    for (int i = 0; i < n; ++i) adj_start_[i + 1] += adj_start_[i];
    adj_.resize(adj_start_[n]);
    std::vector<int> fill(adj_start_.begin(), adj_start_.end() - 1);
    for (int j = 0; j < n; ++j)
        for (int p = P.outerIndexPtr()[j]; p < P.outerIndexPtr()[j + 1]; ++p) {
            const int i = P.innerIndexPtr()[p];
            if (i != j) adj_[fill[i]++] = j, adj_[fill[j]++] = i;
        }
    if (opt_.block > 0) partition();
}

void NonlinearElimination::partition() {
    const int n = static_cast<int>(adj_start_.size()) - 1;
    const int B = opt_.block;
    // Blocks grown breadth first from the lowest coordinate not yet taken, up to B coordinates each.
    std::vector<int> owner(n, -1);
    std::vector<std::vector<int>> blocks;
    for (int s = 0; s < n; ++s) {
        if (owner[s] >= 0) continue;
        const int b = static_cast<int>(blocks.size());
        std::vector<int> part{s};
        owner[s] = b;
        for (size_t k = 0; k < part.size() && static_cast<int>(part.size()) < B; ++k)
            for (int p = adj_start_[part[k]]; p < adj_start_[part[k] + 1] && static_cast<int>(part.size()) < B; ++p)
                if (owner[adj_[p]] < 0) owner[adj_[p]] = b, part.push_back(adj_[p]);
        blocks.push_back(std::move(part));
    }
    // A block that ran out of room (enclosed by blocks grown before it) joins a neighbouring block: many tiny blocks
    // would each cost a local solve's setup for little work.
    for (size_t b = 0; b < blocks.size(); ++b) {
        if (4 * static_cast<int>(blocks[b].size()) >= B) continue;
        int to = -1;
        for (int i : blocks[b])
            for (int p = adj_start_[i]; p < adj_start_[i + 1] && to < 0; ++p)
                if (owner[adj_[p]] != static_cast<int>(b)) to = owner[adj_[p]];
        if (to < 0) continue;  // a component of its own
        for (int i : blocks[b]) owner[i] = to;
        blocks[to].insert(blocks[to].end(), blocks[b].begin(), blocks[b].end());
        blocks[b].clear();
    }
    // Each block grown by `overlap` hops.
    blocks_.clear();
    std::vector<char> in(n, 0);
    std::vector<int> frontier, next;
    for (std::vector<int>& part : blocks) {
        if (part.empty()) continue;
        for (int i : part) in[i] = 1;
        frontier = part;
        for (int h = 0; h < opt_.overlap && !frontier.empty(); ++h) {
            next.clear();
            for (int i : frontier)
                for (int p = adj_start_[i]; p < adj_start_[i + 1]; ++p)
                    if (!in[adj_[p]]) in[adj_[p]] = 1, next.push_back(adj_[p]), part.push_back(adj_[p]);
            frontier.swap(next);
        }
        for (int i : part) in[i] = 0;
        std::sort(part.begin(), part.end());
        blocks_.push_back(std::move(part));
    }
}

bool NonlinearElimination::select(const Eigen::VectorXd& g) {
    parts_.clear();
    selected_ = 0;
    const int n = static_cast<int>(g.size());
    const double gmax = n > 0 ? g.lpNorm<Eigen::Infinity>() : 0.0;
    if (!(gmax > 0)) return false;
    if (opt_.block > 0) {  // parts() are the blocks
        selected_ = n;
        ++counts_.selections;
        return true;
    }
    // The hot coordinates, grown breadth first `hops` times.
    std::vector<char> in(n, 0);
    std::vector<int> frontier, next;
    for (int i = 0; i < n; ++i)
        if (std::abs(g[i]) > opt_.threshold * gmax) in[i] = 1, frontier.push_back(i);
    int count = static_cast<int>(frontier.size());
    const int cap = static_cast<int>(opt_.max_fraction * n);
    for (int h = 0; h < opt_.hops && !frontier.empty() && count <= cap; ++h) {
        next.clear();
        for (int i : frontier)
            for (int p = adj_start_[i]; p < adj_start_[i + 1]; ++p)
                if (!in[adj_[p]]) in[adj_[p]] = 1, next.push_back(adj_[p]), ++count;
        frontier.swap(next);
    }
    if (count > cap) return false;
    // Connected parts of the set: coordinates of distinct parts share no element, so their energies are independent
    // with the rest held.
    std::vector<char> seen(n, 0);
    for (int s = 0; s < n; ++s) {
        if (!in[s] || seen[s]) continue;
        std::vector<int> part{s};
        seen[s] = 1;
        for (size_t k = 0; k < part.size(); ++k)
            for (int p = adj_start_[part[k]]; p < adj_start_[part[k] + 1]; ++p) {
                const int j = adj_[p];
                if (in[j] && !seen[j]) seen[j] = 1, part.push_back(j);
            }
        std::sort(part.begin(), part.end());
        parts_.push_back(std::move(part));
    }
    selected_ = count;
    ++counts_.selections;
    return true;
}

void NonlinearElimination::eliminate(
    Objective& f, Eigen::VectorXd& q, double tol, double max_seconds,
    const std::function<void(const Eigen::VectorXd& q, int done, int total)>& between) {
    const auto t0 = std::chrono::steady_clock::now();
    const int solves_before = counts_.local_solves;
    SolverOptions o;
    o.tol = tol, o.max_iter = opt_.local_max_iter, o.median_floor = median_floor_, o.max_step = max_step_;
    for (const std::vector<int>& part : parts()) {
        if (max_seconds > 0) {
            const double left = max_seconds - std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (left <= 0) break;
            o.max_seconds = left;
        }
        std::unique_ptr<Objective> sub = f.restriction(q, part);
        if (!sub) sub = std::make_unique<SubsetObjective>(f, q, part);
        Eigen::VectorXd qa(part.size());
        for (size_t k = 0; k < part.size(); ++k) qa[k] = q[part[k]];
        NewtonSolver local(o);
        const SolveResult r = local.minimize(*sub, qa);
        ++counts_.local_solves;
        counts_.local_iterations += r.iterations, counts_.local_factorizations += r.factorizations;
        // Newton accepts only steps that lower the energy, so its last state is never worse than the start, converged
        // or not; a non-finite start leaves qa as it was.
        for (size_t k = 0; k < part.size(); ++k) q[part[k]] = qa[k];
        sub.reset();  // a restriction may hand what it changed back to f when it ends (SmoothWetRegion): before f is used
        if (between) between(q, counts_.local_solves - solves_before, static_cast<int>(parts().size()));
    }
    counts_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace fibernet
