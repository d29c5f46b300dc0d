#include "fibernet/energy/capillary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "fibernet/util/error.hpp"
#include "fibernet/util/utf8.hpp"

namespace fibernet {

CapillaryLaw CapillaryLaw::tabulated(const std::vector<double>& alpha, const std::vector<double>& value,
                                     const std::string& where) {
    if (alpha.size() != value.size() || alpha.size() < 2)
        throw InputError(where + ": a tabulated capillary law needs at least 2 (alpha, value) rows");
    for (size_t i = 0; i < alpha.size(); ++i) {
        const std::string row = where + ": row " + std::to_string(i + 1);
        check_value(alpha[i] >= 0 && alpha[i] <= 90, alpha[i], row, "alpha", "must lie in [0, 90] degrees");
        // Values are E / (beta l): of order 1 (the default law spans -1 to 0). Larger ones are a table left in other
        // units, and made a run grow without bound (98,625 bridges on 38 fibers in 120 s): scale beta instead.
        check_value(std::abs(value[i]) <= kMaxLawValue, value[i], row, "value",
                    "is not E / (beta l) of order 1 (|value| <= " + show(kMaxLawValue) + "); rescale the table and give the "
                    "scale as beta");
        if (i > 0 && !(alpha[i] > alpha[i - 1]))
            throw InputError(row + ": alpha = " + show(alpha[i]) + " is not above the previous " + show(alpha[i - 1]) +
                             " (angles must be strictly increasing)");
    }
    // Knots in c = cos^2 alpha, which decreases with alpha: reverse so c increases.
    CapillaryLaw law;
    const size_t n = alpha.size();
    for (size_t i = 0; i < n; ++i) {
        const double a = alpha[n - 1 - i] * M_PI / 180;
        law.c_.push_back(std::cos(a) * std::cos(a));
        law.y_.push_back(value[n - 1 - i]);
    }
    // Natural cubic spline second derivatives (tridiagonal solve).
    law.m_.assign(n, 0.0);
    if (n > 2) {
        std::vector<double> a(n, 0), b(n, 1), cc(n, 0), r(n, 0);
        for (size_t i = 1; i + 1 < n; ++i) {
            const double h0 = law.c_[i] - law.c_[i - 1], h1 = law.c_[i + 1] - law.c_[i];
            a[i] = h0 / 6, b[i] = (h0 + h1) / 3, cc[i] = h1 / 6;
            r[i] = (law.y_[i + 1] - law.y_[i]) / h1 - (law.y_[i] - law.y_[i - 1]) / h0;
        }
        for (size_t i = 1; i < n; ++i) {
            const double w = a[i] / b[i - 1];
            b[i] -= w * cc[i - 1];
            r[i] -= w * r[i - 1];
        }
        for (size_t i = n - 1; i-- > 1;) law.m_[i] = (r[i] - cc[i] * law.m_[i + 1]) / b[i];
    }
    return law;
}

CapillaryLaw CapillaryLaw::read(const std::string& path) {
    std::ifstream is(path);
    if (!is) throw InputError("capillary law file '" + path + "' cannot be opened");
    std::vector<double> alpha, value;
    std::string line;
    int ln = 0;
    while (std::getline(is, line)) {
        ++ln;
        // The table's text goes into the wet summary (JSON): it must be UTF-8, comments included.
        if (const std::size_t at = invalid_utf8_at(line); at != std::string::npos) {
            char byte[8];
            std::snprintf(byte, sizeof byte, "0x%02x", static_cast<unsigned char>(line[at]));
            throw InputError(path + ":" + std::to_string(ln) + ": byte " + byte + " at column " + std::to_string(at + 1) +
                             " is not UTF-8 (save the law file as UTF-8 text)");
        }
        // '#' starts a comment, also after a row's two numbers ("90 0 # end").
        const std::string data = line.substr(0, line.find('#'));
        if (data.find_first_not_of(" \t\r") == std::string::npos) continue;
        std::istringstream ss(data);
        std::string ta, tv, extra;
        if (!(ss >> ta >> tv) || (ss >> extra))
            throw InputError(path + ":" + std::to_string(ln) + ": expected 'alpha_deg value', found '" + line + "'");
        char *ea, *ev;
        const double a = std::strtod(ta.c_str(), &ea), v = std::strtod(tv.c_str(), &ev);
        if (*ea || *ev) throw InputError(path + ":" + std::to_string(ln) + ": '" + line + "' is not two numbers");
        alpha.push_back(a), value.push_back(v);
    }
    return tabulated(alpha, value, path);
}

void CapillaryLaw::eval(double c, double& phi, double& dphi, double& d2phi) const {
    if (c_.empty()) {
        phi = -c, dphi = -1, d2phi = 0;
        return;
    }
    // Outside the table's c range: continue linearly (the spline is natural, so C2 at the ends).
    const size_t n = c_.size();
    size_t k = std::upper_bound(c_.begin(), c_.end(), c) - c_.begin();
    k = std::min(std::max<size_t>(k, 1), n - 1);
    const double h = c_[k] - c_[k - 1];
    double A = (c_[k] - c) / h, B = 1 - A;
    if (c < c_[0] || c > c_[n - 1]) {
        const size_t e = c < c_[0] ? 0 : n - 1;
        const double slope = c < c_[0] ? (y_[1] - y_[0]) / (c_[1] - c_[0]) - (c_[1] - c_[0]) * (2 * m_[0] + m_[1]) / 6
                                        : (y_[n - 1] - y_[n - 2]) / h + h * (m_[n - 2] + 2 * m_[n - 1]) / 6;
        phi = y_[e] + slope * (c - c_[e]), dphi = slope, d2phi = 0;
        return;
    }
    phi = A * y_[k - 1] + B * y_[k] + ((A * A * A - A) * m_[k - 1] + (B * B * B - B) * m_[k]) * h * h / 6;
    dphi = (y_[k] - y_[k - 1]) / h - (3 * A * A - 1) * h * m_[k - 1] / 6 + (3 * B * B - 1) * h * m_[k] / 6;
    d2phi = A * m_[k - 1] + B * m_[k];
}

double bridge_energy(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double l, double beta,
                     const CapillaryLaw& law, Eigen::Vector4d* grad, Eigen::Matrix4d* hess) {
    const double p = a.dot(b), A2 = a.squaredNorm(), B2 = b.squaredNorm();
    const double c = p * p / (A2 * B2);
    double phi, dphi, d2phi;
    law.eval(c, phi, dphi, d2phi);
    const double k = beta * l;
    if (!grad && !hess) return k * phi;
    // c = p^2 / (A2 B2): dc/da = 2 p b/(A2 B2) - 2 c a/A2, dc/db likewise.
    const Eigen::Vector2d ca = 2 * p * b / (A2 * B2) - 2 * c * a / A2;
    const Eigen::Vector2d cb = 2 * p * a / (A2 * B2) - 2 * c * b / B2;
    Eigen::Vector4d cg;
    cg << ca, cb;
    if (grad) *grad = k * dphi * cg;
    if (hess) {
        const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
        // Differentiate ca and cb once more.
        const Eigen::Matrix2d Caa = 2 * b * b.transpose() / (A2 * B2) - 4 * p * b * a.transpose() / (A2 * A2 * B2) -
                                    2 * a * ca.transpose() / A2 - 2 * c * I / A2 + 4 * c * a * a.transpose() / (A2 * A2);
        const Eigen::Matrix2d Cbb = 2 * a * a.transpose() / (A2 * B2) - 4 * p * a * b.transpose() / (A2 * B2 * B2) -
                                    2 * b * cb.transpose() / B2 - 2 * c * I / B2 + 4 * c * b * b.transpose() / (B2 * B2);
        // d(ca)/db: 2 (b a^T + p I)/(A2 B2) - 4 p b b^T/(A2 B2^2) - 2 a cb^T / A2
        const Eigen::Matrix2d Cab = 2 * (b * a.transpose() + p * I) / (A2 * B2) -
                                    4 * p * b * b.transpose() / (A2 * B2 * B2) - 2 * a * cb.transpose() / A2;
        Eigen::Matrix4d C2;
        C2 << Caa, Cab, Cab.transpose(), Cbb;
        *hess = k * (dphi * C2 + d2phi * cg * cg.transpose());
    }
    return k * phi;
}

}  // namespace fibernet
