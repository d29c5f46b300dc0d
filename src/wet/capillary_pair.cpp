#include "fibernet/wet/capillary_pair.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "fibernet/util/error.hpp"
#include "fibernet/wet/jet.hpp"

namespace fibernet {

namespace {

// The pair's energy is invariant under translation: it is differentiated in the 6 coordinates of p1, q0, q1 relative to
// p0 (Y below), whose jets carry 36 Hessian entries instead of 64, and mapped back by X -> Y's constant Jacobian T.
using J = Jet<6>;

// f(x) from f, f', f'' at x's value: the double itself, or the chain rule on a jet.
inline double lift(double, double f, double, double) { return f; }
inline J lift(const J& x, double f, double df, double d2f) { return apply(x, f, df, d2f); }
using std::sqrt;
inline J rcp(const J& x) { return inverse(x); }
inline double rcp(double x) { return 1 / x; }

// C2 step from 0 at t <= -1 to 1 at t >= 1 (quintic in u = (t + 1) / 2).
template <class T>
T step(const T& t) {
    const double tv = value_of(t);
    if (tv <= -1) return T(0.0);
    if (tv >= 1) return T(1.0);
    const double u = 0.5 * (tv + 1), v = 1 - u;
    return lift(t, u * u * u * (10 - 15 * u + 6 * u * u), 15 * u * u * v * v, 15 * u * v * (v - u));
}

// |x| / 2 smoothed over |x| < w with A'' = 15 / (16 w) (1 - (x / w)^2)^2 (C2; A(0) = 5 w / 32).
template <class T>
T half_abs(const T& x, double w) {
    const double xv = value_of(x);
    if (xv >= w) return lift(x, 0.5 * xv, 0.5, 0.0);
    if (xv <= -w) return lift(x, -0.5 * xv, -0.5, 0.0);
    const double r = xv / w, r2 = r * r, k = 15.0 / 16;
    const double f = 5 * w / 32 + k * w * (r2 / 2 - r2 * r2 / 6 + r2 * r2 * r2 / 30);
    const double df = k * r * (1 - 2 * r2 / 3 + r2 * r2 / 5);
    const double d2f = k / w * (1 - r2) * (1 - r2);
    return lift(x, f, df, d2f);
}

template <class T>
struct V2 {
    T x, y;
};
template <class T>
V2<T> operator-(const V2<T>& a, const V2<T>& b) { return {a.x - b.x, a.y - b.y}; }
template <class T>
V2<T> operator+(const V2<T>& a, const V2<T>& b) { return {a.x + b.x, a.y + b.y}; }
template <class T>
T dot(const V2<T>& a, const V2<T>& b) { return a.x * b.x + a.y * b.y; }
template <class T>
T cross(const V2<T>& a, const V2<T>& b) { return a.x * b.y - a.y * b.x; }
template <class T>
V2<T> scaled(const V2<T>& a, const T& s) { return {a.x * s, a.y * s}; }

// The geometry both terms share, and which of them can be non-zero (decided on values, so that a vanishing term is
// never differentiated).
struct Consts {
    double eps, w, contact, s_lo, s_hi;
};

template <class T>
struct Geometry {
    V2<T> p0, p1, q0, q1, d1, d2;
    T L1s, L2s, cr, dt, s;  // |d1|^2, |d2|^2, d1 x d2, d1.d2, sin^2
    T blend;                // b(s)
};

template <class T>
Geometry<T> geometry(const T* X, const Consts& k) {
    Geometry<T> G;
    G.p0 = {X[0], X[1]}, G.p1 = {X[2], X[3]}, G.q0 = {X[4], X[5]}, G.q1 = {X[6], X[7]};
    G.d1 = G.p1 - G.p0, G.d2 = G.q1 - G.q0;
    G.L1s = dot(G.d1, G.d1), G.L2s = dot(G.d2, G.d2);
    G.cr = cross(G.d1, G.d2), G.dt = dot(G.d1, G.d2);
    G.s = G.cr * G.cr * rcp(G.L1s * G.L2s);
    G.blend = step(2.0 * (G.s - k.s_lo) / (k.s_hi - k.s_lo) - 1.0);
    return G;
}

// W_A W_B (capillary_pair.hpp).
template <class T>
T crossing_shares(const Geometry<T>& G, const Consts& k) {
    const double sg = value_of(G.cr) > 0 ? 1.0 : -1.0;
    const V2<T> n2{-G.d2.y, G.d2.x}, n1{-G.d1.y, G.d1.x};
    const T i2 = rcp(k.eps * sqrt(G.L2s)), i1 = rcp(k.eps * sqrt(G.L1s));
    const T WA = sg * (step(dot(G.p0 - G.q0, n2) * i2) - step(dot(G.p1 - G.q0, n2) * i2));
    if (value_of(WA) == 0) return T(0.0);
    const T WB = sg * (step(dot(G.q1 - G.p0, n1) * i1) - step(dot(G.q0 - G.p0, n1) * i1));
    return WA * WB;
}

// overlap and D(delta) of the contact term.
template <class T>
void contact_parts(const Geometry<T>& G, const Consts& k, T& overlap, T& D) {
    const double sd = value_of(G.dt) >= 0 ? 1.0 : -1.0;
    const T i1 = rcp(sqrt(G.L1s)), i2 = sd * rcp(sqrt(G.L2s));
    V2<T> e = scaled(G.d1, i1) + scaled(G.d2, i2);
    const T ie = rcp(sqrt(dot(e, e)));
    e = scaled(e, ie);
    const T a1 = dot(G.d1, e), b0 = dot(G.q0 - G.p0, e), b1 = dot(G.q1 - G.p0, e);
    const T c0 = sd > 0 ? b0 : b1, c1 = sd > 0 ? b1 : b0;
    const double a1v = value_of(a1), c0v = value_of(c0), c1v = value_of(c1);
    if (c0v >= a1v + k.w || c1v <= -k.w) {  // apart by at least w: exactly no overlap
        overlap = T(0.0), D = T(0.0);
        return;
    }
    const T zero(0.0);
    overlap = half_abs(zero - c1, k.w) + half_abs(a1 - c0, k.w) - half_abs(zero - c0, k.w) - half_abs(a1 - c1, k.w);
    const V2<T> n{-e.y, e.x};
    const T delta = 0.5 * dot((G.q0 + G.q1) - (G.p0 + G.p1), n);
    const double dv = std::abs(value_of(delta));
    if (dv <= k.contact) D = T(1.0);
    else if (dv >= 1.5 * k.contact) D = T(0.0);
    else D = 1.0 - step(4.0 * (sqrt(delta * delta) - k.contact) / k.contact - 1.0);
}

Consts consts(const CapillaryPairParams& p) {
    // The blend's ends in sin^2, computed once per pair of angles (every pair term asks).
    thread_local double last_lo = NAN, last_hi = NAN, s_lo = 0, s_hi = 0;
    if (p.angle_lo_deg != last_lo || p.angle_hi_deg != last_hi) {
        const double lo = std::sin(p.angle_lo_deg * M_PI / 180), hi = std::sin(p.angle_hi_deg * M_PI / 180);
        s_lo = lo * lo, s_hi = hi * hi, last_lo = p.angle_lo_deg, last_hi = p.angle_hi_deg;
    }
    return {p.crossing_width, p.overlap_width, p.contact, s_lo, s_hi};
}

// Which terms can be non-zero at X (values only).
struct Active {
    bool crossing = false, contact = false;
};
Active active_terms(const double* X, bool wet_crossing, const Consts& k, CapillaryPairParts* parts) {
    const Geometry<double> G = geometry(X, k);
    Active a;
    if (parts) parts->sin2 = G.s;
    if (wet_crossing && G.blend > 0) {
        const double w = crossing_shares(G, k);
        a.crossing = w != 0;
        if (parts) parts->crossing_weight = G.blend * w;
    }
    if (G.blend < 1) {
        double ov, D;
        contact_parts(G, k, ov, D);
        a.contact = ov != 0 && D != 0;
        if (parts) parts->contact_weight = (1 - G.blend) * D, parts->overlap = ov;
    }
    return a;
}

// The active terms' energies.
template <class T>
void terms(const T* X, double lbar, const CapillaryPairParams& p, const Consts& k, Active a, T& Ex, T& Ec) {
    const Geometry<T> G = geometry(X, k);
    Ex = T(0.0), Ec = T(0.0);
    if (a.crossing) {
        const T c = G.dt * G.dt * rcp(G.L1s * G.L2s);
        double phi, dphi, d2phi;
        p.law.eval(value_of(c), phi, dphi, d2phi);
        Ex = (p.beta * lbar) * lift(c, phi, dphi, d2phi) * crossing_shares(G, k) * G.blend;
    }
    if (a.contact) {
        T ov, D;
        contact_parts(G, k, ov, D);
        Ec = (-p.beta) * ov * D * (1.0 - G.blend);
    }
}

}  // namespace

double CapillaryPairParams::support_distance(double max_length) const { return PairSupport(*this)(max_length); }

PairSupport::PairSupport(const CapillaryPairParams& p)
    : crossing(2 * p.crossing_width / std::sin(p.angle_lo_deg * M_PI / 180)),
      contact(p.overlap_width + 1.5 * p.contact),
      slope(std::sin(p.angle_hi_deg * M_PI / 360)) {}

void CapillaryPairParams::check(const char* where) const {
    auto positive = [&](double v, const char* name) {
        if (!(v > 0) || !std::isfinite(v))
            throw InputError(std::string(where) + ": " + name + " = " + std::to_string(v) + " must be a finite number > 0");
    };
    positive(crossing_width, "crossing_width");
    positive(contact, "contact_distance");
    positive(overlap_width, "overlap_width");
    if (!(angle_lo_deg > 0 && angle_lo_deg < angle_hi_deg && angle_hi_deg < 90))
        throw InputError(std::string(where) + ": the contact angles " + std::to_string(angle_lo_deg) + " and " +
                         std::to_string(angle_hi_deg) + " deg must satisfy 0 < lo < hi < 90");
}


namespace {

// Y = (0, 0, p1 - p0, q0 - p0, q1 - p0): the pair with p0 at the origin (the terms see the same geometry).
Vector8d relative(const Vector8d& X) {
    Vector8d Y;
    for (int i = 0; i < 8; ++i) Y[i] = X[i] - X[i % 2];
    return Y;
}

// The gradient and Hessian in X from those in Y's 6 free coordinates: g_X = T^T g_Y, H_X = T^T H_Y T.
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
Vector8d to_pair(const Vector6d& gy) {
    Vector8d g;
    g.segment<6>(2) = gy;
    g[0] = -(gy[0] + gy[2] + gy[4]), g[1] = -(gy[1] + gy[3] + gy[5]);
    return g;
}
Matrix8d to_pair(const Matrix6d& Hy) {
    Eigen::Matrix<double, 8, 6> A;  // T^T H_Y
    A.bottomRows<6>() = Hy;
    A.row(0) = -(Hy.row(0) + Hy.row(2) + Hy.row(4)), A.row(1) = -(Hy.row(1) + Hy.row(3) + Hy.row(5));
    Matrix8d H;
    H.rightCols<6>() = A;
    H.col(0) = -(A.col(0) + A.col(2) + A.col(4)), H.col(1) = -(A.col(1) + A.col(3) + A.col(5));
    return 0.5 * (H + H.transpose());  // exactly symmetric (the two sums of the node-0 block differ in round-off)
}

}  // namespace

bool capillary_pair_vanishes(const Vector8d& X, bool wet_crossing, const CapillaryPairParams& p) {
    const Active a = active_terms(relative(X).data(), wet_crossing, consts(p), nullptr);
    return !a.crossing && !a.contact;
}

double capillary_pair_energy(const Vector8d& X, double l0a, double l0b, bool wet_crossing,
                             const CapillaryPairParams& p, Vector8d* grad, Matrix8d* hess, bool project_psd,
                             CapillaryPairParts* parts, double contact_scale, Vector8d* contact_grad) {
    const Consts k = consts(p);
    const Vector8d Y = relative(X);
    const Active a = active_terms(Y.data(), wet_crossing, k, parts);
    const double lbar = 0.5 * (l0a + l0b);
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    if (contact_grad) contact_grad->setZero();
    if (!a.crossing && !a.contact) return 0;
    if (!grad && !hess && !contact_grad) {
        double Ex, Ec;
        terms(Y.data(), lbar, p, k, a, Ex, Ec);
        if (parts) parts->crossing_energy = Ex, parts->contact_energy = Ec;
        return contact_scale == 1 ? Ex + Ec : Ex + contact_scale * Ec;
    }
    J Yj[8];
    Yj[0] = J(0.0), Yj[1] = J(0.0);
    for (int i = 0; i < 6; ++i) Yj[2 + i] = J::variable(Y[2 + i], i);
    J Ex, Ec;
    terms(Yj, lbar, p, k, a, Ex, Ec);
    if (parts) parts->crossing_energy = Ex.v, parts->contact_energy = Ec.v;
    if (contact_grad) *contact_grad = to_pair(Ec.g);
    const J E = contact_scale == 1 ? Ex + Ec : Ex + contact_scale * Ec;
    if (grad) *grad = to_pair(E.g);
    if (hess) {
        Matrix6d Hy = 0.5 * (E.h + E.h.transpose());
        if (project_psd) {
            Eigen::SelfAdjointEigenSolver<Matrix6d> es(Hy);
            const Vector6d ev = es.eigenvalues().cwiseMax(0.0);
            Hy = es.eigenvectors() * ev.asDiagonal() * es.eigenvectors().transpose();
        }
        *hess = to_pair(Hy);
    }
    return E.v;
}

double segment_distance(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& q0,
                        const Eigen::Vector2d& q1) {
    auto orient = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
        const Eigen::Vector2d u = b - a, v = c - a;
        return u.x() * v.y() - u.y() * v.x();
    };
    const double o1 = orient(p0, p1, q0), o2 = orient(p0, p1, q1), o3 = orient(q0, q1, p0), o4 = orient(q0, q1, p1);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) return 0;
    auto point_segment = [](const Eigen::Vector2d& x, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
        const Eigen::Vector2d d = b - a;
        const double l2 = d.squaredNorm();
        const double t = l2 > 0 ? std::clamp((x - a).dot(d) / l2, 0.0, 1.0) : 0.0;
        return (a + t * d - x).norm();
    };
    return std::min({point_segment(p0, q0, q1), point_segment(p1, q0, q1), point_segment(q0, p0, p1),
                     point_segment(q1, p0, p1)});
}

}  // namespace fibernet
