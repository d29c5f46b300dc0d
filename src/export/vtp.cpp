#include "fibernet/export/vtp.hpp"

#include <cmath>
#include <map>
#include <ostream>
#include <tuple>

#include "fibernet/util/error.hpp"

namespace fibernet {

namespace {

template <class T, class Get>
void data_array(std::ostream& os, const char* type, const std::string& name, int components, size_t n, Get get) {
    os << "<DataArray type=\"" << type << "\" Name=\"" << name << "\" NumberOfComponents=\"" << components
       << "\" format=\"ascii\">\n";
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < components; ++c) os << static_cast<T>(get(i, c)) << ' ';
        if (i % 8 == 7 || i + 1 == n) os << '\n';
    }
    os << "</DataArray>\n";
}

// Each hinge's energy, half to each of its two segments (found by their nodes and image shift).
std::vector<double> bend_per_segment(const NetworkEnergy& e, const Eigen::VectorXd& u, const Eigen::Matrix2d& F) {
    const Model& m = e.model();
    std::map<std::tuple<int, int, int, int>, int> seg;
    for (size_t k = 0; k < m.segments.size(); ++k) {
        const auto& s = m.segments[k];
        seg.emplace(std::make_tuple(s.i, s.j, s.shift.x(), s.shift.y()), static_cast<int>(k));
    }
    std::vector<double> bend(m.segments.size(), 0.0);
    for (size_t k = 0; k < m.hinges.size(); ++k) {
        const auto& h = m.hinges[k];
        const double E = e.hinge_term(static_cast<int>(k), u, F, nullptr, nullptr, false);
        if (!std::isfinite(E))
            throw InputError("model: hinge " + std::to_string(k) + " (nodes " + std::to_string(h.i) + ", " +
                             std::to_string(h.j) + ", " + std::to_string(h.k) + ") has a segment of zero length");
        const auto a = seg.find(std::make_tuple(h.i, h.j, h.shift1.x(), h.shift1.y()));
        const auto b = seg.find(std::make_tuple(h.j, h.k, h.shift2.x(), h.shift2.y()));
        if (a == seg.end() || b == seg.end())
            throw InputError("model: hinge " + std::to_string(k) + " (nodes " + std::to_string(h.i) + ", " +
                             std::to_string(h.j) + ", " + std::to_string(h.k) +
                             ") does not follow two of the model's segments");
        bend[a->second] += E / 2, bend[b->second] += E / 2;
    }
    return bend;
}

}  // namespace

void write_vtp(std::ostream& os, const NetworkEnergy& e, const Eigen::VectorXd& q, const Eigen::Matrix2d& F,
               const VtpFields& fields) {
    const Model& m = e.model();
    const Eigen::VectorXd u = e.displacements(q, F);
    const Eigen::VectorXd x = m.x + u;
    const Eigen::Matrix2d B = F * m.box.B0();
    const size_t ns = m.segments.size();
    std::vector<double> eps(ns), stretch(ns);
    std::vector<Eigen::Vector2d> p0(ns), p1(ns);
    for (size_t k = 0; k < ns; ++k) {
        const auto& s = m.segments[k];
        const Eigen::Vector2d d = x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i) + B * s.shift.cast<double>();
        p0[k] = x.segment<2>(2 * s.i), p1[k] = p0[k] + d;
        eps[k] = d.norm() / s.l0 - 1;
        stretch[k] = e.segment_term(static_cast<int>(k), u, F, nullptr, nullptr, false);
        if (!std::isfinite(stretch[k]))  // the softcore diverges at zero length: no state a solver returns
            throw InputError("model: segment " + std::to_string(k) + " (nodes " + std::to_string(s.i) + ", " +
                             std::to_string(s.j) + ") has collapsed to length " + show(d.norm()) +
                             ": its energy is infinite");
    }
    const std::vector<double> bend = bend_per_segment(e, u, F);
    std::vector<char> crosslink(m.num_nodes(), 0);
    for (const auto& sn : m.supernodes) crosslink[sn.node] = 1;
    for (const auto& [name, values] : fields.per_fiber)
        for (const auto& s : m.segments)
            if (s.fiber < 0 || static_cast<size_t>(s.fiber) >= values.size())
                throw std::invalid_argument("write_vtp: field '" + name + "' has no value for fiber " +
                                            std::to_string(s.fiber));
    const size_t nb = fields.bridges.size(), np = 2 * ns + nb;  // points: segments' pairs, then bridges
    if (fields.bridge_locked.size() != nb) throw std::invalid_argument("write_vtp: bridge_locked has the wrong size");
    auto node_of = [&](size_t point) -> int {
        if (point >= 2 * ns) return -1;
        const auto& s = m.segments[point / 2];
        return point % 2 ? s.j : s.i;
    };
    auto seg = [&](size_t cell) { return cell - nb; };  // cells: bridges' vertices first, then segments' lines

    os.precision(17);
    os << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n";
    if (!fields.scalars.empty()) {
        os << "<FieldData>\n";
        for (const auto& [name, v] : fields.scalars)
            os << "<DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfTuples=\"1\" format=\"ascii\">" << v
               << "</DataArray>\n";
        os << "</FieldData>\n";
    }
    os << "<Piece NumberOfPoints=\"" << np << "\" NumberOfVerts=\"" << nb << "\" NumberOfLines=\"" << ns
       << "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>\n";
    data_array<double>(os, "Float64", "position", 3, np, [&](size_t i, int c) {
        if (c == 2) return 0.0;
        if (i >= 2 * ns) return fields.bridges[i - 2 * ns][c];
        return (i % 2 ? p1[i / 2] : p0[i / 2])[c];
    });
    os << "</Points>\n<PointData Vectors=\"displacement\">\n";
    data_array<double>(os, "Float64", "displacement", 3, np,
                       [&](size_t i, int c) { return c == 2 || node_of(i) < 0 ? 0.0 : u[2 * node_of(i) + c]; });
    data_array<int>(os, "Int32", "node", 1, np, [&](size_t i, int) { return node_of(i); });
    data_array<int>(os, "Int32", "crosslink", 1, np,
                    [&](size_t i, int) { return node_of(i) < 0 ? 0 : int(crosslink[node_of(i)]); });
    os << "</PointData>\n<CellData Scalars=\"strain\">\n";
    const size_t nc = nb + ns;
    auto per_segment = [&](const std::vector<double>& v) {
        return [&v, &seg, nb](size_t c, int) { return c < nb ? 0.0 : v[seg(c)]; };
    };
    data_array<int>(os, "Int32", "fiber", 1, nc, [&](size_t c, int) { return c < nb ? -1 : m.segments[seg(c)].fiber; });
    data_array<double>(os, "Float64", "strain", 1, nc, per_segment(eps));
    data_array<double>(os, "Float64", "stretch_energy", 1, nc, per_segment(stretch));
    data_array<double>(os, "Float64", "bend_energy", 1, nc, per_segment(bend));
    for (const auto& [name, values] : fields.per_fiber)
        data_array<int>(os, "Int32", name, 1, nc,
                        [&, &v = values](size_t c, int) { return c < nb ? -1 : v[m.segments[seg(c)].fiber]; });
    if (nb)
        data_array<int>(os, "Int32", "bridge", 1, nc,
                        [&](size_t c, int) { return c < nb ? 1 + (fields.bridge_locked[c] != 0) : 0; });
    os << "</CellData>\n";
    if (nb) {
        os << "<Verts>\n";
        data_array<int>(os, "Int32", "connectivity", 1, nb, [&](size_t b, int) { return static_cast<int>(2 * ns + b); });
        data_array<int>(os, "Int32", "offsets", 1, nb, [](size_t b, int) { return static_cast<int>(b + 1); });
        os << "</Verts>\n";
    }
    os << "<Lines>\n";
    data_array<int>(os, "Int32", "connectivity", 1, 2 * ns, [](size_t i, int) { return static_cast<int>(i); });
    data_array<int>(os, "Int32", "offsets", 1, ns, [](size_t k, int) { return static_cast<int>(2 * k + 2); });
    os << "</Lines>\n</Piece>\n</PolyData>\n</VTKFile>\n";
}

namespace {
std::string xml_attribute(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            default: out += c;
        }
    }
    return out;
}
}  // namespace

void write_pvd(std::ostream& os, const std::vector<std::pair<double, std::string>>& steps) {
    os.precision(17);
    os << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "<Collection>\n";
    for (const auto& [t, file] : steps)
        os << "<DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << xml_attribute(file) << "\"/>\n";
    os << "</Collection>\n</VTKFile>\n";
}

}  // namespace fibernet
