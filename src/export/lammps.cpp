#include "fibernet/export/lammps.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <ostream>

#include "fibernet/energy/stretch.hpp"
#include "fibernet/util/error.hpp"

namespace fibernet {

namespace {

// One LAMMPS type per distinct rest length: segments of equal l0 share K and r0 exactly.
template <class Key>
std::map<double, int> type_numbers(const std::vector<Key>& elems, double Key::*len) {
    std::map<double, int> types;
    for (const auto& e : elems) types.emplace(e.*len, 0);
    int t = 0;
    for (auto& [l, n] : types) n = ++t;
    return types;
}

struct BoxBounds {
    double xlo, xhi, ylo, yhi, xy;
};

BoxBounds lammps_box(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& F) {
    if (m.box.periodic) {
        if (F(1, 0) != 0)
            throw InputError("LAMMPS export: deformation F10 = " + show(F(1, 0)) +
                             " tilts the first box vector off x, which a LAMMPS box cannot represent");
        if (F(0, 0) <= 0 || F(1, 1) <= 0)
            throw InputError("LAMMPS export: deformation F00 = " + show(F(0, 0)) + ", F11 = " + show(F(1, 1)) +
                             " must both be > 0");
        return {0, F(0, 0) * m.box.L, 0, F(1, 1) * m.box.L, F(0, 1) * m.box.L};
    }
    // An open box: fixed LAMMPS boundaries around every node, with a margin so that no atom sits on a face.
    BoxBounds b{INFINITY, -INFINITY, INFINITY, -INFINITY, 0};
    for (int i = 0; i < m.num_nodes(); ++i) {
        b.xlo = std::min(b.xlo, x[2 * i]), b.xhi = std::max(b.xhi, x[2 * i]);
        b.ylo = std::min(b.ylo, x[2 * i + 1]), b.yhi = std::max(b.yhi, x[2 * i + 1]);
    }
    if (m.num_nodes() == 0) b = {0, m.box.L, 0, m.box.L, 0};
    b.xlo -= 1, b.xhi += 1, b.ylo -= 1, b.yhi += 1;
    return b;
}

// The longest current segment: the pair cutoff of `pair_style zero`, which sets how far LAMMPS keeps ghost atoms, must
// reach across every bond and angle.
double longest_bond(const Model& m, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    double l = 0;
    for (const auto& s : m.segments) {
        const Eigen::Vector2d d = x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i) + B * s.shift.cast<double>();
        l = std::max(l, d.norm());
    }
    return l;
}

void write_data(std::ostream& os, const Model& m, const Eigen::VectorXd& x, const BoxBounds& b,
                const std::map<double, int>& bt, const std::map<double, int>& at, const std::string& title) {
    const double k = 4 * m.aspect_ratio * m.aspect_ratio;
    os << "LAMMPS data file: " << title << "\n\n";
    os << m.num_nodes() << " atoms\n1 atom types\n";
    os << m.segments.size() << " bonds\n" << bt.size() << " bond types\n";
    os << m.hinges.size() << " angles\n" << at.size() << " angle types\n\n";
    os << b.xlo << ' ' << b.xhi << " xlo xhi\n" << b.ylo << ' ' << b.yhi << " ylo yhi\n-0.5 0.5 zlo zhi\n";
    if (m.box.periodic) os << b.xy << " 0 0 xy xz yz\n";
    os << "\nMasses\n\n1 1\n\nBond Coeffs # harmonic\n\n";
    for (const auto& [l0, t] : bt) os << t << ' ' << k / l0 << ' ' << l0 << '\n';
    os << "\nAngle Coeffs # cosine\n\n";
    for (const auto& [lt0, t] : at) os << t << ' ' << 2 / lt0 << '\n';
    // The molecule id is the fiber (1-based): a fiber's nodes, except a crosslink's, which keeps its first fiber's.
    std::vector<int> mol(m.num_nodes(), 0);
    for (const auto& s : m.segments) {
        if (!mol[s.i]) mol[s.i] = s.fiber + 1;
        if (!mol[s.j]) mol[s.j] = s.fiber + 1;
    }
    os << "\nAtoms # angle\n\n";
    for (int i = 0; i < m.num_nodes(); ++i)
        os << i + 1 << ' ' << mol[i] << " 1 " << x[2 * i] << ' ' << x[2 * i + 1] << " 0\n";
    os << "\nBonds\n\n";
    for (size_t e = 0; e < m.segments.size(); ++e) {
        const auto& s = m.segments[e];
        os << e + 1 << ' ' << bt.at(s.l0) << ' ' << s.i + 1 << ' ' << s.j + 1 << '\n';
    }
    os << "\nAngles\n\n";
    for (size_t e = 0; e < m.hinges.size(); ++e) {
        const auto& h = m.hinges[e];
        os << e + 1 << ' ' << at.at(h.lt0) << ' ' << h.i + 1 << ' ' << h.j + 1 << ' ' << h.k + 1 << '\n';
    }
}

void write_input(std::ostream& os, const Model& m, const BoxBounds& b, double cutoff, const LammpsExport& info,
                 const std::string& data_name, const std::string& title) {
    os << "# " << title << "\n";
    os << "# The energy is the fibernet model's (docs/formats.md, \"LAMMPS\"): bond harmonic K = 4 a^2 / l0, r0 = l0;\n"
          "# angle cosine K = 2 / lt0; seed units (ls = 1, bending energy of unit length at unit curvature).\n";
    if (info.softcore_segments)
        os << "# WARNING: " << info.softcore_segments << " segments are compressed below eps* = " << StretchLaw{}.eps_star
           << ", where fibernet's softcore branch adds energy that bond_style harmonic lacks.\n";
    // A periodic network wraps around the torus, so no image flags make every bond short; LAMMPS warns
    // "Inconsistent image flags" and takes each bond by minimum image, which is the model's as long as every segment
    // is shorter than half the box.
    os << "units lj\ndimension 2\natom_style angle\n";
    os << (m.box.periodic ? "boundary p p p\n" : "boundary f f p\n");
    if (m.box.periodic && std::abs(b.xy) > 0.5 * (b.xhi - b.xlo)) os << "box tilt large\n";
    os << "bond_style harmonic\nangle_style cosine\n";
    os << "read_data " << data_name << "  # relative to the directory lmp runs in\n";
    // No pair forces; the zero pair style and the communication cutoff only make every bond's and angle's atoms
    // ghosts of each other (an angle spans two bonds).
    os << "pair_style zero " << cutoff << "\npair_coeff * *\n";
    os << "comm_modify cutoff " << 2 * cutoff + 0.5 << "\n";
    os << "special_bonds lj/coul 0 0 0\n";
    os << "neighbor 0.3 bin\n";
    std::vector<int> clamped;
    for (int i = 0; i < m.num_nodes(); ++i)
        if (!m.fixed.empty() && m.fixed[i]) clamped.push_back(i + 1);
    if (!clamped.empty()) {
        os << "group clamped id";
        for (int id : clamped) os << ' ' << id;
        os << "\ngroup free subtract all clamped\nfix hold clamped setforce 0 0 0\n";
    } else {
        os << "group free union all\n";
    }
    os << "fix plane all enforce2d\n";
    os << "variable fxabs atom abs(fx)\nvariable fyabs atom abs(fy)\ncompute fmax free reduce max v_fxabs v_fyabs\n";
    os << "thermo_style custom step pe ebond eangle c_fmax[1] c_fmax[2]\nthermo_modify norm no format float %.17g\n";
    os << "run 0\n";
}

}  // namespace

LammpsExport write_lammps(std::ostream& data, std::ostream& input, const Model& m, const Eigen::VectorXd& u,
                          const Eigen::Matrix2d& F, const std::string& data_name, const std::string& title) {
    if (u.size() != m.x.size())
        throw std::invalid_argument("write_lammps: " + std::to_string(u.size()) + " displacements for " +
                                    std::to_string(m.x.size()) + " node coordinates");
    const Eigen::VectorXd x = m.x + u;
    const BoxBounds b = lammps_box(m, x, F);
    const Eigen::Matrix2d B = F * m.box.B0();
    LammpsExport info;
    const auto bt = type_numbers(m.segments, &Segment::l0);
    const auto at = type_numbers(m.hinges, &Hinge::lt0);
    info.bond_types = static_cast<int>(bt.size()), info.angle_types = static_cast<int>(at.size());
    for (const auto& s : m.segments) {
        const Eigen::Vector2d d = x.segment<2>(2 * s.j) - x.segment<2>(2 * s.i) + B * s.shift.cast<double>();
        if (d.norm() / s.l0 - 1 < StretchLaw{}.eps_star) ++info.softcore_segments;
    }
    data.precision(17), input.precision(17);
    write_data(data, m, x, b, bt, at, title);
    write_input(input, m, b, std::max(1.0, 1.01 * longest_bond(m, x, B)), info, data_name, title);
    return info;
}

}  // namespace fibernet
