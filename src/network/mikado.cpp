#include "fibernet/network/mikado.hpp"

#include <algorithm>
#include <cmath>

#include "fibernet/util/error.hpp"
#include "fibernet/util/random.hpp"

namespace fibernet {

void MikadoParams::check(const std::string& where) const {
    check_value(q > 0, q, where, "q (density)", "must be > 0");
    check_value(pl >= 0 && pl <= 1, pl, where, "pl (crosslink probability)", "must lie in [0, 1]");
    if (periodic)
        check_value(L > 2, L, where, "L (box side in fiber lengths)",
                    "must be > 2 for a periodic box (a fiber pair may otherwise cross twice through images)");
    else
        check_value(L > 0, L, where, "L (box side in fiber lengths)", "must be > 0");
    const double n = std::round(q * L * L);
    if (n > 5e7) throw InputError(where + ": q L^2 = " + show(n) + " fibers is more than the 5e7 this build supports");
}

Network generate_mikado(const MikadoParams& p) {
    p.check("mikado parameters");
    Network net;
    net.L = p.L;
    net.periodic = p.periodic;
    net.seed = p.seed;
    net.q = p.q;
    net.pl = p.pl;
    const long n = std::lround(p.q * p.L * p.L);
    Rng rng(derive_seed(p.seed, 1));
    net.fibers.resize(n);
    for (auto& f : net.fibers) {
        const double cx = rng.uniform(0, p.L), cy = rng.uniform(0, p.L);
        f.theta = rng.uniform(0, M_PI);
        f.length = 1;
        f.start = Eigen::Vector2d(cx, cy) - 0.5 * f.direction();
    }
    net.crossings = find_crossings(net);
    assign_crosslinks(net, p.pl, p.seed);
    return net;
}

namespace {
void sort_crossings(std::vector<Crossing>& c) {
    std::sort(c.begin(), c.end(), [](const Crossing& a, const Crossing& b) {
        return a.f1 != b.f1 ? a.f1 < b.f1 : a.f2 != b.f2 ? a.f2 < b.f2 : a.s1 < b.s1;
    });
}

// Adds the crossing of fibers i < j, with j shifted by `image` boxes, if they intersect. u: unit directions.
void try_pair(const Network& net, const std::vector<Eigen::Vector2d>& u, int i, int j, const Eigen::Vector2i& image,
              std::vector<Crossing>& out) {
    double si, sj;
    const Fiber &a = net.fibers[i], &b = net.fibers[j];
    if (intersect(a.start, u[i], a.length, b.start + net.L * image.cast<double>(), u[j], b.length, si, sj)) {
        Crossing c;
        c.f1 = i, c.f2 = j, c.s1 = si, c.s2 = sj, c.image = image;
        out.push_back(c);
    }
}
}  // namespace

std::vector<Crossing> find_crossings(const Network& net) {
    std::vector<Crossing> out;
    const int n = static_cast<int>(net.fibers.size());
    if (n == 0) return out;
    // Directions and centres once (cos/sin per fiber, not per candidate pair).
    std::vector<Eigen::Vector2d> u(n), centre(n);
    for (int i = 0; i < n; ++i) u[i] = net.fibers[i].direction(), centre[i] = net.fibers[i].start + 0.5 * net.fibers[i].length * u[i];
    double lmax = 0;
    for (const auto& f : net.fibers) lmax = std::max(lmax, f.length);
    // Two fibers can cross only if their centres are within lmax: bin centres in cells of side >= lmax.
    // Open boxes: centres may lie outside [0, L) for hand-made networks, so bin over their bounding box.
    Eigen::Vector2d lo(0, 0), hi(net.L, net.L);
    if (!net.periodic)
        for (const auto& c : centre) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    const Eigen::Vector2d ext = hi - lo;
    // At most about 4 cells per fiber: a sparse network in a huge box would otherwise allocate (L / lmax)^2 cells
    // (1e12 at L = 1e6). Fewer, larger cells stay correct (side >= lmax).
    const double most = std::max(1.0, std::floor(std::sqrt(4.0 * n)));
    const int nx = static_cast<int>(std::max(1.0, std::min(most, std::floor(ext.x() / lmax))));
    const int ny = static_cast<int>(std::max(1.0, std::min(most, std::floor(ext.y() / lmax))));
    auto cell_of = [&](const Eigen::Vector2d& c, int& cx, int& cy) {
        Eigen::Vector2d r = c - lo;
        if (net.periodic) r = r - net.L * (r / net.L).array().floor().matrix();
        cx = std::min(nx - 1, std::max(0, static_cast<int>(r.x() / ext.x() * nx)));
        cy = std::min(ny - 1, std::max(0, static_cast<int>(r.y() / ext.y() * ny)));
    };
    // Counting sort of fibers into cells.
    std::vector<int> cell(n), start(static_cast<size_t>(nx) * ny + 1, 0), order(n);
    for (int i = 0; i < n; ++i) {
        int cx, cy;
        cell_of(centre[i], cx, cy);
        cell[i] = cy * nx + cx;
        ++start[cell[i] + 1];
    }
    for (size_t c = 0; c + 1 < start.size(); ++c) start[c + 1] += start[c];
    {
        std::vector<int> fill(start.begin(), start.end() - 1);
        for (int i = 0; i < n; ++i) order[fill[cell[i]]++] = i;
    }
    std::vector<int> neighbours;
    // Fibers in cell order: consecutive fibers share their neighbour cells, whose data then stay in cache.
    for (int k0 = 0; k0 < n; ++k0) {
        const int i = order[k0];
        const int cx = cell[i] % nx, cy = cell[i] / nx;
        neighbours.clear();
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                int x = cx + dx, y = cy + dy;
                if (net.periodic) {
                    x = (x % nx + nx) % nx, y = (y % ny + ny) % ny;
                } else if (x < 0 || y < 0 || x >= nx || y >= ny) {
                    continue;
                }
                neighbours.push_back(y * nx + x);
            }
        std::sort(neighbours.begin(), neighbours.end());
        neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
        const Eigen::Vector2d ci = centre[i];
        for (int c : neighbours)
            for (int k = start[c]; k < start[c + 1]; ++k) {
                const int j = order[k];
                if (j <= i) continue;
                Eigen::Vector2i image(0, 0);
                if (net.periodic) {
                    // L > 2 lmax makes the crossing image unique: the nearest image of j's centre.
                    const Eigen::Vector2d dc = centre[j] - ci;
                    image = Eigen::Vector2i(static_cast<int>(-std::round(dc.x() / net.L)),
                                            static_cast<int>(-std::round(dc.y() / net.L)));
                }
                try_pair(net, u, i, j, image, out);
            }
    }
    sort_crossings(out);
    return out;
}

std::vector<Crossing> find_crossings_brute_force(const Network& net) {
    std::vector<Crossing> out;
    const int n = static_cast<int>(net.fibers.size());
    const int r = net.periodic ? 2 : 0;
    std::vector<Eigen::Vector2d> u(n);
    for (int i = 0; i < n; ++i) u[i] = net.fibers[i].direction();
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            for (int my = -r; my <= r; ++my)
                for (int mx = -r; mx <= r; ++mx) try_pair(net, u, i, j, Eigen::Vector2i(mx, my), out);
    sort_crossings(out);
    return out;
}

void assign_crosslinks(Network& net, double pl, std::uint64_t seed) {
    Rng rng(derive_seed(seed, 2));
    for (auto& c : net.crossings) c.crosslink = pl >= 1 || rng.bernoulli(pl);
}

}  // namespace fibernet
