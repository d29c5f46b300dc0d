#include "fibernet/model/model_io.hpp"

#include <algorithm>
#include <cmath>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "fibernet/util/error.hpp"

namespace fibernet {

void write_model(std::ostream& os, const Model& m, const Eigen::VectorXd& uin, const Eigen::Matrix2d& F) {
    const Eigen::VectorXd u = uin.size() ? uin : Eigen::VectorXd::Zero(m.x.size());
    if (u.size() != m.x.size())
        throw std::invalid_argument("write_model: " + std::to_string(u.size()) + " displacements for " +
                                    std::to_string(m.x.size()) + " node coordinates");
    os.precision(17);
    os << "fibernet-model 2\n";
    os << "box " << m.box.L << ' ' << (m.box.periodic ? "periodic" : "open") << '\n';
    os << "deformation " << F(0, 0) << ' ' << F(0, 1) << ' ' << F(1, 0) << ' ' << F(1, 1) << '\n';
    os << "aspect_ratio " << m.aspect_ratio << '\n';
    os << "fiber_length " << m.fiber_length << '\n';
    os << "softcore_eps_star -0.95\n";
    os << "nodes " << m.num_nodes() << '\n';
    // The position is for other programs; the state is x_ref + u, read back from u exactly (x itself has lost the
    // low bits of u that the gradient at an equilibrium depends on).
    for (int i = 0; i < m.num_nodes(); ++i)
        os << m.x[2 * i] + u[2 * i] << ' ' << m.x[2 * i + 1] + u[2 * i + 1] << ' '
           << (m.fixed.empty() ? 0 : int(m.fixed[i])) << ' ' << m.x[2 * i] << ' ' << m.x[2 * i + 1] << ' ' << u[2 * i]
           << ' ' << u[2 * i + 1] << '\n';
    const double k = 4 * m.aspect_ratio * m.aspect_ratio;
    os << "segments " << m.segments.size() << '\n';
    // Rest vectors too: derived from the rounded reference positions they would move |g| by 4 a^2 ulp(L) / l0, which
    // on a 1e-3 segment is 1e-9 (format 2; NaN, from positions, where the model has none).
    for (const auto& s : m.segments)
        os << s.i << ' ' << s.j << ' ' << s.shift.x() << ' ' << s.shift.y() << ' ' << s.l0 << ' ' << s.fiber << ' '
           << k / s.l0 << ' ' << s.d0.x() << ' ' << s.d0.y() << '\n';
    os << "hinges " << m.hinges.size() << '\n';
    for (const auto& h : m.hinges)
        os << h.i << ' ' << h.j << ' ' << h.k << ' ' << h.shift1.x() << ' ' << h.shift1.y() << ' ' << h.shift2.x()
           << ' ' << h.shift2.y() << ' ' << h.lt0 << ' ' << h.fiber << ' ' << 2 / h.lt0 << ' ' << h.d10.x() << ' '
           << h.d10.y() << ' ' << h.d20.x() << ' ' << h.d20.y() << '\n';
    os << "supernodes " << m.supernodes.size() << '\n';
    for (const auto& s : m.supernodes) {
        os << s.node << ' ' << s.crossings.size();
        for (int c : s.crossings) os << ' ' << c;
        os << '\n';
    }
}

namespace {
// Entries reserved ahead of reading them: a file's count is believed only as far as its lines bear it out.
constexpr long kModelReserveAtMost = 1 << 16;
struct Reader {
    std::istream& is;
    std::string source;
    int line = 0;
    std::string text;
    [[noreturn]] void fail(const std::string& msg) const {
        throw InputError(source + ":" + std::to_string(line) + ": " + msg);
    }
    std::istringstream next(const std::string& what) {
        while (std::getline(is, text)) {
            ++line;
            auto p = text.find_first_not_of(" \t\r");
            if (p == std::string::npos || text[p] == '#') continue;
            return std::istringstream(text);
        }
        fail("unexpected end of file, expected " + what);
    }
    double num(std::istringstream& ss, const char* name) {
        std::string t;
        if (!(ss >> t)) fail(std::string("missing ") + name);
        return parse(t, name);
    }
    double parse(const std::string& t, const char* name) {
        char* end;
        double v = std::strtod(t.c_str(), &end);
        if (*end || end == t.c_str() || !std::isfinite(v)) fail(std::string(name) + " = '" + t + "' is not a finite number");
        return v;
    }
    // A rest vector component: a finite number, or nan (derive it from the reference positions).
    double num_or_nan(std::istringstream& ss, const char* name) {
        std::string t;
        if (!(ss >> t)) fail(std::string("missing ") + name);
        return t == "nan" || t == "-nan" ? NAN : parse(t, name);
    }
    long integer(std::istringstream& ss, const char* name, long lo, long hi) {
        std::string t;
        if (!(ss >> t)) fail(std::string("missing ") + name);
        char* end;
        long v = std::strtol(t.c_str(), &end, 10);
        if (*end || end == t.c_str()) fail(std::string(name) + " = '" + t + "' is not an integer");
        if (v < lo || v > hi) fail(std::string(name) + " = " + t + " is out of range");
        return v;
    }
    long section(const char* kw) {
        auto ss = next(kw);
        std::string k;
        ss >> k;
        if (k != kw) fail(std::string("expected '") + kw + "', found '" + text + "'");
        return integer(ss, kw, 0, 2000000000);
    }
    double keyed(const char* kw) {
        auto ss = next(kw);
        std::string k;
        ss >> k;
        if (k != kw) fail(std::string("expected '") + kw + "', found '" + text + "'");
        return num(ss, kw);
    }
};
}  // namespace

Model read_model(std::istream& is, const std::string& source, Eigen::VectorXd* uout, Eigen::Matrix2d* Fout) {
    Reader r{is, source, 0, {}};
    Model m;
    int version = 0;
    {
        auto ss = r.next("header");
        std::string h;
        ss >> h;
        if (h != "fibernet-model") r.fail("not a fibernet model file (header '" + r.text + "')");
        version = static_cast<int>(r.integer(ss, "format version", 1, 2));
    }
    {
        auto ss = r.next("box");
        std::string k, kind;
        ss >> k;
        if (k != "box") r.fail("expected 'box L periodic|open'");
        m.box.L = r.num(ss, "box L");
        ss >> kind;
        if (kind != "periodic" && kind != "open") r.fail("box kind '" + kind + "' must be periodic or open");
        m.box.periodic = kind == "periodic";
    }
    Eigen::Matrix2d F;
    {
        auto ss = r.next("deformation");
        std::string k;
        ss >> k;
        if (k != "deformation") r.fail("expected 'deformation F00 F01 F10 F11'");
        F(0, 0) = r.num(ss, "F00"), F(0, 1) = r.num(ss, "F01"), F(1, 0) = r.num(ss, "F10"), F(1, 1) = r.num(ss, "F11");
    }
    m.aspect_ratio = r.keyed("aspect_ratio");
    m.fiber_length = r.keyed("fiber_length");
    r.keyed("softcore_eps_star");
    // Entries are appended as they are read: a corrupt count must not allocate that many.
    const long n = r.section("nodes");
    std::vector<double> x_ref, u_ref;
    x_ref.reserve(2 * static_cast<size_t>(std::min(n, kModelReserveAtMost)));
    u_ref.reserve(x_ref.capacity());
    m.fixed.clear();
    for (long i = 0; i < n; ++i) {
        auto ss = r.next("node");
        const double x = r.num(ss, "node x"), y = r.num(ss, "node y");
        m.fixed.push_back(static_cast<char>(r.integer(ss, "node fixed flag", 0, 1)));
        const double xr = r.num(ss, "node x_ref"), yr = r.num(ss, "node y_ref");
        double ux = x - xr, uy = y - yr;  // version 1: positions only; u as well as x can hold it
        if (version != 1) ux = r.num(ss, "node ux"), uy = r.num(ss, "node uy");
        // A node a thousand boxes away is no state of this network (and its energy overflows).
        const double reach = 1e3 * (std::abs(m.box.L) + std::abs(m.fiber_length));
        for (double v : {xr, yr, ux, uy})
            if (!(std::abs(v) <= reach))
                r.fail("node " + std::to_string(i) + ": coordinate " + show(v) + " lies beyond 1000 box sides (" +
                       show(reach) + ")");
        x_ref.insert(x_ref.end(), {xr, yr}), u_ref.insert(u_ref.end(), {ux, uy});
    }
    m.x = Eigen::Map<const Eigen::VectorXd>(x_ref.data(), static_cast<Eigen::Index>(x_ref.size()));
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(u_ref.data(), static_cast<Eigen::Index>(u_ref.size()));
    const long ns = r.section("segments");
    m.segments.clear();
    m.segments.reserve(static_cast<size_t>(std::min(ns, kModelReserveAtMost)));
    for (long e = 0; e < ns; ++e) {
        Segment& s = m.segments.emplace_back();
        auto ss = r.next("segment");
        s.i = r.integer(ss, "segment node i", 0, n - 1), s.j = r.integer(ss, "segment node j", 0, n - 1);
        s.shift.x() = r.integer(ss, "segment shift x", -1000000, 1000000);
        s.shift.y() = r.integer(ss, "segment shift y", -1000000, 1000000);
        s.l0 = r.num(ss, "segment l0");
        if (s.l0 <= 0) r.fail("segment l0 = " + show(s.l0) + " must be > 0");
        s.fiber = r.integer(ss, "segment fiber", 0, 2000000000);
        if (version >= 2) {
            r.num(ss, "segment K");
            s.d0.x() = r.num_or_nan(ss, "segment d0x"), s.d0.y() = r.num_or_nan(ss, "segment d0y");
        }
    }
    const long nh = r.section("hinges");
    m.hinges.clear();
    m.hinges.reserve(static_cast<size_t>(std::min(nh, kModelReserveAtMost)));
    for (long e = 0; e < nh; ++e) {
        Hinge& h = m.hinges.emplace_back();
        auto ss = r.next("hinge");
        h.i = r.integer(ss, "hinge node i", 0, n - 1), h.j = r.integer(ss, "hinge node j", 0, n - 1),
        h.k = r.integer(ss, "hinge node k", 0, n - 1);
        h.shift1.x() = r.integer(ss, "hinge shift1 x", -1000000, 1000000);
        h.shift1.y() = r.integer(ss, "hinge shift1 y", -1000000, 1000000);
        h.shift2.x() = r.integer(ss, "hinge shift2 x", -1000000, 1000000);
        h.shift2.y() = r.integer(ss, "hinge shift2 y", -1000000, 1000000);
        h.lt0 = r.num(ss, "hinge lt0");
        if (h.lt0 <= 0) r.fail("hinge lt0 = " + show(h.lt0) + " must be > 0");
        h.fiber = r.integer(ss, "hinge fiber", 0, 2000000000);
        if (version >= 2) {
            r.num(ss, "hinge Kb");
            h.d10.x() = r.num_or_nan(ss, "hinge d10x"), h.d10.y() = r.num_or_nan(ss, "hinge d10y");
            h.d20.x() = r.num_or_nan(ss, "hinge d20x"), h.d20.y() = r.num_or_nan(ss, "hinge d20y");
        }
    }
    const long nsn = r.section("supernodes");
    m.supernodes.clear();
    m.supernodes.reserve(static_cast<size_t>(std::min(nsn, kModelReserveAtMost)));
    for (long e = 0; e < nsn; ++e) {
        Supernode& s = m.supernodes.emplace_back();
        auto ss = r.next("supernode");
        s.node = r.integer(ss, "supernode node", 0, n - 1);
        const long k = r.integer(ss, "supernode crossing count", 0, 1000);
        for (long c = 0; c < k; ++c) s.crossings.push_back(r.integer(ss, "supernode crossing", 0, 2000000000));
    }
    if (uout) *uout = u;
    if (Fout) *Fout = F;
    return m;
}

}  // namespace fibernet
