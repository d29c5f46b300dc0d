#include "fibernet/rigidity/cluster_svg.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace fibernet {

namespace {

const char* const kSpanning = "#d00000";

// "L = 4, q = 8, pl = 0.5, d = 0 (rigid spanning)" and what each colour means.
std::string title_and_legend(const Network& net, const RigidityResult& r) {
    std::ostringstream os;
    os << "<text x=\"10\" y=\"22\" font-family=\"sans-serif\" font-size=\"16\">L = " << net.L;
    if (net.q > 0) os << ", q = " << net.q;
    os << ", pl = " << net.pl << ", " << r.fibers << " fibers, " << r.clusters << " rigid clusters";
    if (r.clamped)
        os << ", d = " << r.d << (r.rigid_spanning ? " (rigid spanning)" : r.carries_shear ? " (carries shear)" : "");
    os << "</text>\n";
    struct Entry {
        const char* colour;
        double width;
        const char* label;
    };
    const Entry entries[] = {{kSpanning, 4, "rigid cluster holding both clamps"},
                             {"hsl(200,70%,45%)", 3, "other rigid clusters (one colour each)"},
                             {"#c8c8c8", 2, "fibers rigid on their own only"},
                             {"black", 5, "clamps"}};
    double x = 10;
    for (const Entry& e : entries) {
        if (!r.clamped && e.colour == kSpanning) continue;
        if (!r.clamped && std::string(e.colour) == "black") continue;
        os << "<line x1=\"" << x << "\" y1=\"45\" x2=\"" << x + 24 << "\" y2=\"45\" stroke=\"" << e.colour
           << "\" stroke-width=\"" << e.width << "\"/><text x=\"" << x + 30
           << "\" y=\"50\" font-family=\"sans-serif\" font-size=\"12\">" << e.label << "</text>\n";
        x += 40 + 6.5 * std::string(e.label).size();
    }
    return os.str();
}

}  // namespace

std::string rigid_cluster_svg(const Network& net, const RigidityResult& r) {
    // Bounding box of the fibers (open boxes: fibers stick out at the sides).
    double x0 = 0, y0 = 0, x1 = net.L, y1 = net.L;
    for (const auto& f : net.fibers)
        for (double s : {0.0, f.length}) {
            const auto p = f.point(s);
            x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
        }
    const double size = 800, margin = 10, header = 64;  // the title and the legend above the network
    const double scale = (size - 2 * margin) / std::max(x1 - x0, y1 - y0);
    const double stroke = std::clamp(0.02 * scale, 0.3, 3.0);
    auto X = [&](double x) { return margin + (x - x0) * scale; };
    auto Y = [&](double y) { return header + size - margin - (y - y0) * scale; };  // y up
    std::vector<int> size_of(r.clusters, 0);
    for (int i = 0; i < r.fibers; ++i) ++size_of[r.cluster[i]];
    const int spanning = r.clamped && r.rigid_spanning ? r.cluster[r.fibers] : -1;
    std::ostringstream os;
    os << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size << "\" height=\"" << size + header
       << "\" viewBox=\"0 0 " << size << " " << size + header << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    char buf[512];
    os << title_and_legend(net, r);
    std::snprintf(buf, sizeof buf, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"none\" stroke=\"#bbb\"/>\n",
                  X(0), Y(net.L), net.L * scale, net.L * scale);
    os << buf;
    for (int pass = 0; pass < 2; ++pass)  // floppy fibers first, clusters on top
        for (int i = 0; i < r.fibers; ++i) {
            const int c = r.cluster[i];
            const bool alone = size_of[c] <= 1 && c != spanning;
            if (alone != (pass == 0)) continue;
            std::string colour = "#c8c8c8";
            double w = stroke;
            if (c == spanning) colour = kSpanning, w = 2 * stroke;
            else if (!alone) {
                // Golden-angle hues, so that neighbouring labels get distinct colours, kept out of the spanning
                // cluster's red (hues 330..30).
                std::snprintf(buf, sizeof buf, "hsl(%d,70%%,45%%)", 30 + static_cast<int>(c * 137.508) % 300);
                colour = buf, w = 1.5 * stroke;
            }
            const auto& f = net.fibers[i];
            const auto a = f.point(0), b = f.point(f.length);
            std::snprintf(buf, sizeof buf, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"%s\" stroke-width=\"%.2f\"/>\n",
                          X(a.x()), Y(a.y()), X(b.x()), Y(b.y()), colour.c_str(), w);
            os << buf;
        }
    if (r.clamped)
        for (double y : {0.0, net.L}) {
            std::snprintf(buf, sizeof buf, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" stroke=\"black\" stroke-width=\"%.2f\"/>\n",
                          X(x0), Y(y), X(x1), Y(y), 3 * stroke);
            os << buf;
        }
    os << "</svg>\n";
    return os.str();
}

}  // namespace fibernet
