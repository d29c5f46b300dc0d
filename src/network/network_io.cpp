#include "fibernet/network/network_io.hpp"

#include <algorithm>
#include <atomic>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>
#include <sys/stat.h>
#include <unistd.h>

#include "fibernet/util/error.hpp"
#include "fibernet/util/hash.hpp"

namespace fibernet {

void write_network(std::ostream& os, const Network& net) {
    os.precision(17);
    os << "fibernet-network 1\n";
    os << "box " << net.L << ' ' << (net.periodic ? "periodic" : "open") << '\n';
    os << "meta seed " << net.seed << " q " << net.q << " pl " << net.pl << '\n';
    os << "fibers " << net.fibers.size() << '\n';
    for (const auto& f : net.fibers)
        os << f.start.x() << ' ' << f.start.y() << ' ' << f.theta << ' ' << f.length << '\n';
    os << "crossings " << net.crossings.size() << '\n';
    for (const auto& c : net.crossings)
        os << c.f1 << ' ' << c.f2 << ' ' << c.s1 << ' ' << c.s2 << ' ' << c.image.x() << ' ' << c.image.y() << ' '
           << (c.crosslink ? 1 : 0) << '\n';
    size_t nb = 0;
    for (const auto& f : net.fibers) nb += f.breakpoints.size();
    if (nb > 0) {
        os << "breakpoints " << nb << '\n';
        for (size_t i = 0; i < net.fibers.size(); ++i)
            for (double s : net.fibers[i].breakpoints) os << i << ' ' << s << '\n';
    }
}

namespace {
// Entries reserved ahead of reading them: a file's count is believed only as far as its lines bear it out.
constexpr long kNetworkReserveAtMost = 1 << 16;
struct LineReader {
    std::istream& is;
    std::string source;
    int line = 0;
    std::string text;

    std::string where() const { return source + ":" + std::to_string(line); }
    [[noreturn]] void fail(const std::string& msg) const { throw InputError(where() + ": " + msg); }

    // Next non-empty, non-comment line as a token stream.
    std::istringstream next(const std::string& expecting) {
        while (std::getline(is, text)) {
            ++line;
            auto p = text.find_first_not_of(" \t\r");
            if (p == std::string::npos || text[p] == '#') continue;
            return std::istringstream(text);
        }
        ++line;
        fail("unexpected end of file, expected " + expecting);
    }
    void expect_end(std::istringstream& ss) {
        std::string extra;
        if (ss >> extra) fail("unexpected extra field '" + extra + "' in line '" + text + "'");
    }
    double number(std::istringstream& ss, const std::string& name) {
        std::string tok;
        if (!(ss >> tok)) fail("missing " + name + " in line '" + text + "'");
        char* end = nullptr;
        double v = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0') fail(name + " = '" + tok + "' is not a number");
        if (!std::isfinite(v)) fail(name + " = " + tok + " is not a finite number");
        return v;
    }
    long integer(std::istringstream& ss, const std::string& name, long lo, long hi) {
        std::string tok;
        if (!(ss >> tok)) fail("missing " + name + " in line '" + text + "'");
        char* end = nullptr;
        long v = std::strtol(tok.c_str(), &end, 10);
        if (end == tok.c_str() || *end != '\0') fail(name + " = '" + tok + "' is not an integer");
        if (v < lo || v > hi) fail(name + " = " + tok + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return v;
    }
    void keyword(std::istringstream& ss, const std::string& kw) {
        std::string tok;
        if (!(ss >> tok) || tok != kw) fail("expected '" + kw + "', found '" + text + "'");
    }
};
}  // namespace

namespace {
// The header and the box line.
void read_box(LineReader& r, Network& net) {
    {
        auto ss = r.next("header 'fibernet-network 1'");
        r.keyword(ss, "fibernet-network");
        r.integer(ss, "format version", 1, 1);
        r.expect_end(ss);
    }
    {
        auto ss = r.next("'box L periodic|open'");
        r.keyword(ss, "box");
        net.L = r.number(ss, "box side L");
        if (net.L <= 0) r.fail("box side L = " + show(net.L) + " must be > 0");
        std::string kind;
        ss >> kind;
        if (kind != "periodic" && kind != "open") r.fail("box kind '" + kind + "' must be 'periodic' or 'open'");
        net.periodic = kind == "periodic";
        r.expect_end(ss);
    }
}

// The optional meta line and the fibers; returns their count.
long read_fibers(LineReader& r, Network& net) {
    auto ss = r.next("'meta ...' or 'fibers N'");
    std::string kw;
    ss >> kw;
    if (kw == "meta") {
        std::string key;
        while (ss >> key) {
            if (key == "seed") {
                std::string tok;
                ss >> tok;
                net.seed = std::strtoull(tok.c_str(), nullptr, 10);
            } else if (key == "q") {
                net.q = r.number(ss, "meta q");
            } else if (key == "pl") {
                net.pl = r.number(ss, "meta pl");
            } else {
                r.fail("unknown meta key '" + key + "'");
            }
        }
        ss = r.next("'fibers N'");
        ss >> kw;
    }
    if (kw != "fibers") r.fail("expected 'fibers N', found '" + r.text + "'");
    const long nf = r.integer(ss, "fiber count", 0, 100000000);
    r.expect_end(ss);
    // Entries are appended as they are read: a corrupt count must not allocate that many (kNetworkReserveAtMost).
    net.fibers.clear();
    net.fibers.reserve(static_cast<size_t>(std::min(nf, kNetworkReserveAtMost)));
    for (long i = 0; i < nf; ++i) {
        auto ls = r.next("fiber " + std::to_string(i));
        Fiber& f = net.fibers.emplace_back();
        f.start.x() = r.number(ls, "fiber x0");
        f.start.y() = r.number(ls, "fiber y0");
        f.theta = r.number(ls, "fiber theta");
        f.length = r.number(ls, "fiber length");
        if (f.length <= 0) r.fail("fiber length = " + show(f.length) + " must be > 0");
        if (net.periodic && 2 * f.length >= net.L)
            r.fail("fiber length = " + show(f.length) + " must be < L/2 = " + show(net.L / 2) + " in a periodic box");
        r.expect_end(ls);
    }
    return nf;
}

// The crossings of the nf fibers, each checked against its fibers and for repeats.
void read_crossings(LineReader& r, Network& net, long nf) {
    auto cs = r.next("'crossings M'");
    r.keyword(cs, "crossings");
    const long nc = r.integer(cs, "crossing count", 0, 1000000000);
    r.expect_end(cs);
    net.crossings.clear();
    net.crossings.reserve(static_cast<size_t>(std::min(nc, kNetworkReserveAtMost)));
    // Two straight fibers cross at most once per periodic image: a repeated line would count twice. Found by
    // sorting (fiber pair, image, line) keys after reading (a map node per crossing cost ~200 MB at 2.5e6).
    std::vector<std::pair<std::array<int, 4>, std::array<long, 2>>> keys;  // key, (crossing, line)
    keys.reserve(static_cast<size_t>(std::min(nc, kNetworkReserveAtMost)));
    for (long k = 0; k < nc; ++k) {
        auto ls = r.next("crossing " + std::to_string(k));
        Crossing& c = net.crossings.emplace_back();
        c.f1 = static_cast<int>(r.integer(ls, "crossing f1", 0, nf - 1));
        c.f2 = static_cast<int>(r.integer(ls, "crossing f2", 0, nf - 1));
        if (c.f1 == c.f2) r.fail("crossing joins fiber " + std::to_string(c.f1) + " to itself");
        c.s1 = r.number(ls, "crossing s1");
        c.s2 = r.number(ls, "crossing s2");
        if (c.s1 < 0 || c.s1 > net.fibers[c.f1].length)
            r.fail("crossing s1 = " + show(c.s1) + " lies outside fiber " + std::to_string(c.f1));
        if (c.s2 < 0 || c.s2 > net.fibers[c.f2].length)
            r.fail("crossing s2 = " + show(c.s2) + " lies outside fiber " + std::to_string(c.f2));
        c.image.x() = static_cast<int>(r.integer(ls, "crossing image x", -1000000, 1000000));
        c.image.y() = static_cast<int>(r.integer(ls, "crossing image y", -1000000, 1000000));
        if (!net.periodic && (c.image.x() != 0 || c.image.y() != 0))
            r.fail("crossing image must be 0 0 in an open box");
        c.crosslink = r.integer(ls, "crossing crosslink flag", 0, 1) == 1;
        r.expect_end(ls);
        // The two arc positions must name the same point (within round-off of the geometry).
        const Eigen::Vector2d p1 = net.fibers[c.f1].point(c.s1);
        const Eigen::Vector2d p2 = net.fibers[c.f2].point(c.s2) + net.L * c.image.cast<double>();
        if ((p1 - p2).norm() > 1e-8 * std::max(1.0, net.L))
            r.fail("crossing " + std::to_string(k) + " points on fibers " + std::to_string(c.f1) + " and " +
                   std::to_string(c.f2) + " are " + show((p1 - p2).norm()) + " apart (must coincide)");
        keys.push_back({c.f1 < c.f2 ? std::array<int, 4>{c.f1, c.f2, c.image.x(), c.image.y()}
                                    : std::array<int, 4>{c.f2, c.f1, -c.image.x(), -c.image.y()},
                        {k, static_cast<long>(r.line)}});
    }
    std::sort(keys.begin(), keys.end());
    // Of all repeats, the one whose later line comes first in the file.
    auto rep = keys.end();
    for (auto it = keys.begin(); it + 1 < keys.end(); ++it)
        if (it->first == (it + 1)->first && (rep == keys.end() || (it + 1)->second[0] < (rep + 1)->second[0])) rep = it;
    if (rep != keys.end()) {
        const long first = rep->second[0], later = std::next(rep)->second[0];
        r.line = static_cast<int>(std::next(rep)->second[1]);  // the message names the later line
        r.fail("crossing " + std::to_string(later) + " repeats crossing " + std::to_string(first) + " (fibers " +
               std::to_string(rep->first[0]) + " and " + std::to_string(rep->first[1]) + ")");
    }
}

// The optional breakpoint blocks after the crossings.
void read_breakpoints(std::istream& is, LineReader& r, Network& net, long nf) {
    std::string rest;
    while (std::getline(is, rest)) {
        ++r.line;
        const auto p = rest.find_first_not_of(" \t\r");
        if (p == std::string::npos || rest[p] == '#') continue;
        std::istringstream bs(rest);
        std::string kw;
        bs >> kw;
        if (kw != "breakpoints") r.fail("unexpected content after the crossings: '" + rest + "'");
        r.text = rest;
        const long nb = r.integer(bs, "breakpoint count", 0, 1000000000);
        r.expect_end(bs);
        for (long k = 0; k < nb; ++k) {
            auto ls = r.next("breakpoint " + std::to_string(k));
            const long f = r.integer(ls, "breakpoint fiber", 0, nf - 1);
            const double s = r.number(ls, "breakpoint s");
            if (s < 0 || s > net.fibers[f].length)
                r.fail("breakpoint s = " + show(s) + " lies outside fiber " + std::to_string(f));
            r.expect_end(ls);
            net.fibers[f].breakpoints.push_back(s);
        }
    }
}
}  // namespace

Network read_network(std::istream& is, const std::string& source) {
    LineReader r{is, source, 0, {}};
    Network net;
    read_box(r, net);
    const long nf = read_fibers(r, net);
    read_crossings(r, net, nf);
    read_breakpoints(is, r, net, nf);
    return net;
}

void write_file_atomic(const std::string& path, const std::string& content) {
    // Written, flushed and closed before it counts: a full device fails at the flush, not at operator<<.
    auto write_all = [&](const std::string& target) -> bool {
        std::ofstream os(target, std::ios::binary);
        if (!os) return false;
        os.write(content.data(), static_cast<std::streamsize>(content.size()));
        os.close();
        return !os.fail();
    };
    auto failed = [&](const std::string& what) {
        return OutputError("cannot " + what + " output '" + path + "' (" + (errno ? std::strerror(errno) : "the write failed") + ")");
    };
    struct stat st;
    if (stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        // A device or pipe (/dev/null, /dev/stdout): write straight to it; renaming over it would replace it.
        errno = 0;
        if (!write_all(path)) throw failed("write");
        return;
    }
    // A temporary name of this process's own (host and pid hashed, and a count): processes that write the same file
    // at once (fibernet scan's shards in one directory) must not rename one another's half-written temporary.
    static std::atomic<unsigned> count{0};
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    char tag[32];
    std::snprintf(tag, sizeof tag, ".%08llx%u.tmp",
                  static_cast<unsigned long long>(fnv1a_bytes(std::string(host) + "/" + std::to_string(getpid())) &
                                                  0xffffffffull),
                  count++);
    const std::string tmp = path + tag;
    errno = 0;
    if (!write_all(tmp)) {
        const OutputError e = failed("write");
        std::remove(tmp.c_str());
        throw e;
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const OutputError e = failed("rename '" + tmp + "' to the");
        std::remove(tmp.c_str());
        throw e;
    }
}

void save_network(const Network& net, const std::string& path) {
    std::ostringstream os;
    write_network(os, net);
    write_file_atomic(path, os.str());
}

Network load_network(const std::string& path) {
    std::ifstream is(path);
    if (!is) throw InputError("network file '" + path + "' cannot be opened");
    return read_network(is, path);
}

}  // namespace fibernet
