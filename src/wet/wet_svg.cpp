#include "fibernet/wet/wet_svg.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace fibernet {

namespace {
std::string color_of(int label) {
    static const char* palette[] = {"#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#bcbd22"};
    return palette[label % 8];
}
}  // namespace

Eigen::Vector2d bridge_point(const Model& m, const Bridge& b, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    const BridgeElement el = resolve(m, b);
    const Vector16d Z = element_coordinates(el, x, B);
    const Eigen::Vector2d p1 = Z.segment<2>(2), d1 = Z.segment<2>(4) - p1, p2 = Z.segment<2>(10), d2 = Z.segment<2>(12) - p2;
    const double den = d1.x() * d2.y() - d1.y() * d2.x();
    double t = 0.5;  // parallel segments: the middle of the first
    if (std::abs(den) > 1e-12 * d1.norm() * d2.norm()) {
        const Eigen::Vector2d w = p2 - p1;
        t = std::min(1.5, std::max(-0.5, (w.x() * d2.y() - w.y() * d2.x()) / den));
    }
    Eigen::Vector2d c = p1 + t * d1;
    if (m.box.periodic) c -= B * (B.inverse() * c).array().floor().matrix();
    return c;
}

namespace {
// A bar one fiber length long (at the panels' scale) and what the marks mean, on one line at height y.
std::string scale_and_legend(const Model& m, double px, double gap, double y) {
    std::ostringstream os;
    os.precision(5);
    const double bar = px / m.box.L * m.fiber_length;
    os << "<line x1=\"" << gap << "\" y1=\"" << y << "\" x2=\"" << gap + bar << "\" y2=\"" << y
       << "\" stroke=\"black\" stroke-width=\"3\"/>\n<text x=\"" << gap + bar + 6 << "\" y=\"" << y + 4
       << "\">1 fiber length (" << m.fiber_length << " seed units)</text>\n";
    double x = gap + bar + 200;
    auto item = [&](const std::string& mark, const std::string& label) {
        os << mark << "<text x=\"" << x + 14 << "\" y=\"" << y + 4 << "\">" << label << "</text>\n";
        x += 26 + 7 * label.size();
    };
    auto dot = [&](const char* fill, double r) {
        std::ostringstream d;
        d << "<circle cx=\"" << x + 5 << "\" cy=\"" << y << "\" r=\"" << r << "\" fill=\"" << fill << "\"/>";
        return d.str();
    };
    auto dash = [&](const std::string& col, double w) {
        std::ostringstream d;
        d << "<line x1=\"" << x << "\" y1=\"" << y << "\" x2=\"" << x + 10 << "\" y2=\"" << y << "\" stroke=\"" << col
          << "\" stroke-width=\"" << w << "\"/>";
        return d.str();
    };
    item(dot("#ff4d4d", 2.2), "capillary bridge");
    item(dot("#d62728", 1.3), "locked (zipped) bridge");
    item(dash(color_of(0), 1.6) , "bundle (one colour each)");
    item(dash("#555", 0.8), "fiber");
    return os.str();
}
}  // namespace

std::string network_svg(const Model& m, const std::vector<SvgPanel>& panels, double px) {
    std::ostringstream os;
    os.precision(5);
    const double gap = 20, head = 24, foot = 30;  // the foot holds the scale bar and the legend
    os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << panels.size() * (px + gap) + gap << "\" height=\""
       << px + head + gap + foot << "\" font-family=\"sans-serif\" font-size=\"13\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    for (size_t p = 0; p < panels.size(); ++p) {
        const SvgPanel& P = panels[p];
        const double ox = gap + p * (px + gap), oy = head;
        const double L = m.box.L, s = px / L;
        os << "<text x=\"" << ox << "\" y=\"16\">" << P.title << "</text>\n";
        os << "<clipPath id=\"c" << p << "\"><rect x=\"" << ox << "\" y=\"" << oy << "\" width=\"" << px << "\" height=\"" << px
           << "\"/></clipPath>\n<g clip-path=\"url(#c" << p << ")\" stroke-linecap=\"round\">\n";
        os << "<rect x=\"" << ox << "\" y=\"" << oy << "\" width=\"" << px << "\" height=\"" << px << "\" fill=\"none\" stroke=\"#999\"/>\n";
        // Screen position of a model point (y up).
        auto X = [&](const Eigen::Vector2d& v) { return ox + s * v.x(); };
        auto Y = [&](const Eigen::Vector2d& v) { return oy + px - s * v.y(); };
        const Eigen::Matrix2d Bi = P.B.inverse();
        for (size_t f = 0; f < m.chains.size(); ++f) {
            const bool bundled = !P.bundle_of_fiber.empty() && P.bundle_size[P.bundle_of_fiber[f]] >= 2;
            const std::string col = bundled ? color_of(P.bundle_of_fiber[f]) : "#555";
            for (int e : m.chains[f].segments) {
                const Segment& sg = m.segments[e];
                Eigen::Vector2d a = P.x.segment<2>(2 * sg.i);
                const Eigen::Vector2d d = P.x.segment<2>(2 * sg.j) - a + P.B * sg.shift.cast<double>();
                if (m.box.periodic) a -= P.B * (Bi * a).array().floor().matrix();
                for (int ix = -1; ix <= 1; ++ix)
                    for (int iy = -1; iy <= 1; ++iy) {
                        if (!m.box.periodic && (ix || iy)) continue;
                        const Eigen::Vector2d a2 = a + P.B * Eigen::Vector2d(ix, iy), b2 = a2 + d;
                        if (std::max(a2.x(), b2.x()) < 0 || std::min(a2.x(), b2.x()) > L || std::max(a2.y(), b2.y()) < 0 ||
                            std::min(a2.y(), b2.y()) > L)
                            continue;
                        os << "<line x1=\"" << X(a2) << "\" y1=\"" << Y(a2) << "\" x2=\"" << X(b2) << "\" y2=\"" << Y(b2)
                           << "\" stroke=\"" << col << "\" stroke-width=\"" << (bundled ? 1.6 : 0.8) << "\"/>\n";
                    }
            }
        }
        for (const Bridge& b : P.bridges) {
            const Eigen::Vector2d c = bridge_point(m, b, P.x, P.B);
            os << "<circle cx=\"" << X(c) << "\" cy=\"" << Y(c) << "\" r=\"" << (b.locked ? 1.3 : 2.2) << "\" fill=\""
               << (b.locked ? "#d62728" : "#ff4d4d") << "\"/>\n";
        }
        os << "</g>\n";
    }
    os << scale_and_legend(m, px, gap, head + px + gap + 6);
    os << "</svg>\n";
    return os.str();
}

std::string histogram_svg(const std::vector<std::string>& names, const std::vector<std::vector<double>>& values,
                          const std::string& xlabel, int bins) {
    double lo = 1e300, hi = 0;
    for (const auto& v : values)
        for (double a : v)
            if (a > 0) lo = std::min(lo, a), hi = std::max(hi, a);
    if (!(hi > lo)) lo = 0.5 * std::max(hi, 1e-12), hi = 2 * std::max(hi, 1e-12);
    // Log-spaced bins: pore sizes span decades.
    const double l0 = std::log10(lo), l1 = std::log10(hi) + 1e-9;
    std::vector<std::vector<double>> frac(values.size(), std::vector<double>(bins, 0.0));
    double fmax = 0;
    for (size_t k = 0; k < values.size(); ++k) {
        for (double a : values[k])
            if (a > 0) frac[k][std::min(bins - 1, static_cast<int>((std::log10(a) - l0) / (l1 - l0) * bins))] += 1;
        for (double& f : frac[k]) f /= std::max<size_t>(1, values[k].size()), fmax = std::max(fmax, f);
    }
    const double W = 560, H = 320, x0 = 60, y0 = 20, w = W - x0 - 20, h = H - y0 - 50;
    std::ostringstream os;
    os.precision(5);
    os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
       << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    os << "<rect x=\"" << x0 << "\" y=\"" << y0 << "\" width=\"" << w << "\" height=\"" << h << "\" fill=\"none\" stroke=\"black\"/>\n";
    static const char* cols[] = {"#555555", "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"};
    for (size_t k = 0; k < values.size(); ++k) {
        os << "<polyline fill=\"none\" stroke=\"" << cols[k % 6] << "\" stroke-width=\"2\" points=\"";
        for (int b = 0; b < bins; ++b) {
            const double ya = y0 + h - h * frac[k][b] / std::max(fmax, 1e-300);
            os << x0 + w * b / bins << "," << ya << " " << x0 + w * (b + 1) / bins << "," << ya << " ";
        }
        os << "\"/>\n<text x=\"" << x0 + 10 << "\" y=\"" << y0 + 18 + 16 * k << "\" fill=\"" << cols[k % 6] << "\">"
           << names[k] << " (" << values[k].size() << " pores)</text>\n";
    }
    for (int d = static_cast<int>(std::floor(l0)); d <= static_cast<int>(std::ceil(l1)); ++d) {
        const double xd = x0 + w * (d - l0) / (l1 - l0);
        if (xd < x0 - 1e-9 || xd > x0 + w + 1e-9) continue;
        os << "<line x1=\"" << xd << "\" y1=\"" << y0 + h << "\" x2=\"" << xd << "\" y2=\"" << y0 + h + 5
           << "\" stroke=\"black\"/><text x=\"" << xd - 12 << "\" y=\"" << y0 + h + 18 << "\">1e" << d << "</text>\n";
    }
    os << "<text x=\"" << x0 + w / 2 - 80 << "\" y=\"" << H - 8 << "\">" << xlabel << " (log bins)</text>\n";
    for (double f : {0.0, 0.5, 1.0}) {  // the y axis: fractions of the tallest bar
        const double yf = y0 + h - h * f;
        os << "<line x1=\"" << x0 - 5 << "\" y1=\"" << yf << "\" x2=\"" << x0 << "\" y2=\"" << yf
           << "\" stroke=\"black\"/><text x=\"" << x0 - 8 << "\" y=\"" << yf + 4 << "\" text-anchor=\"end\">"
           << f * fmax << "</text>\n";
    }
    os << "<text x=\"12\" y=\"" << y0 + h / 2 << "\" transform=\"rotate(-90 12 " << y0 + h / 2
       << ")\">fraction of pores</text>\n</svg>\n";
    return os.str();
}

}  // namespace fibernet
