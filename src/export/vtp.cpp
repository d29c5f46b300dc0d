#include "fibernet/export/vtp.hpp"

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
    }
    const std::vector<double> bend = bend_per_segment(e, u, F);
    std::vector<char> crosslink(m.num_nodes(), 0);
    for (const auto& sn : m.supernodes) crosslink[sn.node] = 1;
    for (const auto& [name, values] : fields.per_fiber)
        for (const auto& s : m.segments)
            if (s.fiber < 0 || static_cast<size_t>(s.fiber) >= values.size())
                throw std::invalid_argument("write_vtp: field '" + name + "' has no value for fiber " +
                                            std::to_string(s.fiber));
    auto node_of = [&](size_t point) {
        const auto& s = m.segments[point / 2];
        return point % 2 ? s.j : s.i;
    };

    os.precision(17);
    os << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n";
    if (!fields.scalars.empty()) {
        os << "<FieldData>\n";
        for (const auto& [name, v] : fields.scalars)
            os << "<DataArray type=\"Float64\" Name=\"" << name << "\" NumberOfTuples=\"1\" format=\"ascii\">" << v
               << "</DataArray>\n";
        os << "</FieldData>\n";
    }
    os << "<Piece NumberOfPoints=\"" << 2 * ns << "\" NumberOfVerts=\"0\" NumberOfLines=\"" << ns
       << "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n<Points>\n";
    data_array<double>(os, "Float64", "position", 3, 2 * ns, [&](size_t i, int c) {
        return c == 2 ? 0.0 : (i % 2 ? p1[i / 2] : p0[i / 2])[c];
    });
    os << "</Points>\n<PointData Vectors=\"displacement\">\n";
    data_array<double>(os, "Float64", "displacement", 3, 2 * ns,
                       [&](size_t i, int c) { return c == 2 ? 0.0 : u[2 * node_of(i) + c]; });
    data_array<int>(os, "Int32", "node", 1, 2 * ns, [&](size_t i, int) { return node_of(i); });
    data_array<int>(os, "Int32", "crosslink", 1, 2 * ns, [&](size_t i, int) { return int(crosslink[node_of(i)]); });
    os << "</PointData>\n<CellData Scalars=\"strain\">\n";
    data_array<int>(os, "Int32", "fiber", 1, ns, [&](size_t k, int) { return m.segments[k].fiber; });
    data_array<double>(os, "Float64", "strain", 1, ns, [&](size_t k, int) { return eps[k]; });
    data_array<double>(os, "Float64", "stretch_energy", 1, ns, [&](size_t k, int) { return stretch[k]; });
    data_array<double>(os, "Float64", "bend_energy", 1, ns, [&](size_t k, int) { return bend[k]; });
    for (const auto& [name, values] : fields.per_fiber)
        data_array<int>(os, "Int32", name, 1, ns, [&, &v = values](size_t k, int) { return v[m.segments[k].fiber]; });
    os << "</CellData>\n<Lines>\n";
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
