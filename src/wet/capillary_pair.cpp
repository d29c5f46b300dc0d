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
// p0 (Y below), whose jets carry a 6 x 6 Hessian (21 entries packed) instead of an 8 x 8, and mapped back by X -> Y's
// constant Jacobian T.
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

struct Consts {
    double eps, w, contact, s_lo, s_hi;
};

// The nodes, the segments and what both terms need of them. X is the pair relative to p0 (relative() below): p0 = 0,
// so differences from p0 are the points themselves (the same numbers, without their jets' operations).
template <class T>
struct Geometry {
    V2<T> p1, q0, q1, d1, d2;
    T L1s, L2s, dt;  // |d1|^2, |d2|^2, d1.d2
};

template <class T>
Geometry<T> geometry(const T* X) {
    Geometry<T> G;
    G.p1 = {X[2], X[3]}, G.q0 = {X[4], X[5]}, G.q1 = {X[6], X[7]};
    G.d1 = G.p1, G.d2 = G.q1 - G.q0;
    G.L1s = dot(G.d1, G.d1), G.L2s = dot(G.d2, G.d2);
    G.dt = dot(G.d1, G.d2);
    return G;
}

// The pair in doubles: every factor's value and the argument of each smoothing it passes through. The derivative pass
// (terms<Jet>) differentiates only the factors whose smoothing is inside its window here; outside, a step is exactly 0
// or 1 and D exactly 1 or 0, constants whose jets would be spent on zero derivatives (most crossings lie away from
// both segments' nodes, most contacts within the contact distance and below angle_lo).
struct Shape {
    Geometry<double> G;
    double cr = 0, s = 0;   // d1 x d2, sin^2
    double blend_t = 0;     // the angle blend's argument; b(s) = step(blend_t)
    double blend = 0;
    double share_t[4] = {};  // W_A's two and W_B's two step arguments
    double WA = 0, WB = 0;
    double overlap = 0, delta = 0, D = 0;
    bool crossing = false, contact = false;  // the terms that are non-zero
};

// W_A, W_B's step arguments: the signed distances of a's nodes to b's line and of b's nodes to a's line, over eps.
template <class T>
void share_arguments(const Geometry<T>& G, const T& i1, const T& i2, const bool want[4], T t[4]) {
    const V2<T> n2{-G.d2.y, G.d2.x}, n1{-G.d1.y, G.d1.x};
    if (want[0]) t[0] = -dot(G.q0, n2) * i2;
    if (want[1]) t[1] = dot(G.p1 - G.q0, n2) * i2;
    if (want[2]) t[2] = dot(G.q1, n1) * i1;
    if (want[3]) t[3] = dot(G.q0, n1) * i1;
}

// The contact term's bisector frame: overlap's four smoothed |x| / 2 arguments and the offset delta across e.
template <class T>
struct ContactFrame {
    T a1, c0, c1;  // a's far end, b's two ends on e (a's near end is 0)
    V2<T> e;
};

template <class T>
ContactFrame<T> contact_frame(const Geometry<T>& G, double sd) {
    const T i1 = rcp(sqrt(G.L1s)), i2 = sd * rcp(sqrt(G.L2s));
    V2<T> e = scaled(G.d1, i1) + scaled(G.d2, i2);
    const T ie = rcp(sqrt(dot(e, e)));
    ContactFrame<T> f;
    f.e = scaled(e, ie);
    f.a1 = dot(G.d1, f.e);
    const T b0 = dot(G.q0, f.e), b1 = dot(G.q1, f.e);
    f.c0 = sd > 0 ? b0 : b1, f.c1 = sd > 0 ? b1 : b0;
    return f;
}

template <class T>
T overlap_of(const ContactFrame<T>& f, double w) {
    // A(a0 - c1) + A(a1 - c0) - A(a0 - c0) - A(a1 - c1) with a0 = 0, and A even.
    return half_abs(f.c1, w) + half_abs(f.a1 - f.c0, w) - half_abs(f.c0, w) - half_abs(f.a1 - f.c1, w);
}

template <class T>
T offset_of(const Geometry<T>& G, const ContactFrame<T>& f) {
    const V2<T> n{-f.e.y, f.e.x};
    return 0.5 * dot((G.q0 + G.q1) - G.p1, n);
}

template <class T>
T fade_of(const T& delta, double contact) {  // D(delta) inside its window
    return 1.0 - step(4.0 * (sqrt(delta * delta) - contact) / contact - 1.0);
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

void crossing_shape(Shape& S, const Consts& k) {
    const Geometry<double>& G = S.G;
    const bool all[4] = {true, true, true, true};
    share_arguments(G, 1 / (k.eps * std::sqrt(G.L1s)), 1 / (k.eps * std::sqrt(G.L2s)), all, S.share_t);
    const double sg = S.cr > 0 ? 1.0 : -1.0;
    S.WA = sg * (step(S.share_t[0]) - step(S.share_t[1]));
    if (S.WA == 0) return;
    S.WB = sg * (step(S.share_t[2]) - step(S.share_t[3]));
}

void contact_shape(Shape& S, const Consts& k) {
    const double sd = S.G.dt >= 0 ? 1.0 : -1.0;
    const ContactFrame<double> f = contact_frame(S.G, sd);
    if (f.c0 >= f.a1 + k.w || f.c1 <= -k.w) return;  // apart by at least w: exactly no overlap
    S.overlap = overlap_of(f, k.w);
    S.delta = offset_of(S.G, f);
    const double dv = std::abs(S.delta);
    S.D = dv <= k.contact ? 1.0 : dv >= 1.5 * k.contact ? 0.0 : fade_of(S.delta, k.contact);
}

Shape shape(const double* X, bool wet_crossing, const Consts& k) {
    Shape S;
    S.G = geometry(X);
    S.cr = cross(S.G.d1, S.G.d2);
    S.s = S.cr * S.cr * (1 / (S.G.L1s * S.G.L2s));
    S.blend_t = 2.0 * (S.s - k.s_lo) / (k.s_hi - k.s_lo) - 1.0;
    S.blend = step(S.blend_t);
    if (wet_crossing && S.blend > 0) {
        crossing_shape(S, k);
        S.crossing = S.WA * S.WB != 0;
    }
    if (S.blend < 1) {
        contact_shape(S, k);
        S.contact = S.overlap != 0 && S.D != 0;
    }
    return S;
}

// A factor of a term: a jet where it varies, its value where it is constant.
struct Factor {
    bool constant = true;
    double value = 0;
    J jet;
};
J times(const J& a, const Factor& f) {
    if (!f.constant) return a * f.jet;
    return f.value == 1 ? a : f.value * a;
}
Factor varying(const J& j) {
    Factor f;
    f.constant = false, f.value = j.v, f.jet = j;
    return f;
}
Factor constant(double v) {
    Factor f;
    f.value = v;
    return f;
}

// The angle blend b(s) (its jet only inside the blend).
Factor blend_factor(const Geometry<J>& G, const Shape& S, const Consts& k) {
    if (S.blend_t <= -1 || S.blend_t >= 1) return constant(S.blend);
    const J cr = cross(G.d1, G.d2);
    const J s = cr * cr * rcp(G.L1s * G.L2s);
    return varying(step(2.0 * (s - k.s_lo) / (k.s_hi - k.s_lo) - 1.0));
}

// W_A W_B (capillary_pair.hpp), differentiating only the steps inside their windows.
Factor shares_factor(const Geometry<J>& G, const Shape& S, const Consts& k) {
    bool want[4];
    bool any = false;
    for (int i = 0; i < 4; ++i) any |= want[i] = std::abs(S.share_t[i]) < 1;
    if (!any) return constant(S.WA * S.WB);
    J t[4];
    const J i2 = rcp(k.eps * sqrt(G.L2s)), i1 = rcp(k.eps * sqrt(G.L1s));
    share_arguments(G, i1, i2, want, t);
    const double sg = S.cr > 0 ? 1.0 : -1.0;
    auto H = [&](int i) { return want[i] ? step(t[i]) : J(step(S.share_t[i])); };
    const J WA = sg * (H(0) - H(1));
    const J WB = sg * (H(2) - H(3));
    return varying(WA * WB);
}

// The contact term's overlap and D(delta) (D's jet only inside its fade).
void contact_factors(const Geometry<J>& G, const Shape& S, const Consts& k, J& overlap, Factor& D) {
    const double sd = S.G.dt >= 0 ? 1.0 : -1.0;
    const ContactFrame<J> f = contact_frame(G, sd);
    overlap = overlap_of(f, k.w);
    const double dv = std::abs(S.delta);
    D = dv <= k.contact || dv >= 1.5 * k.contact ? constant(S.D) : varying(fade_of(offset_of(G, f), k.contact));
}

// The active terms' energies in doubles (the same arithmetic as their jets' values).
void terms(const Shape& S, double lbar, const CapillaryPairParams& p, double& Ex, double& Ec) {
    Ex = 0, Ec = 0;
    if (S.crossing) {
        const Geometry<double>& G = S.G;
        const double c = G.dt * G.dt * (1 / (G.L1s * G.L2s));
        double phi, dphi, d2phi;
        p.law.eval(c, phi, dphi, d2phi);
        Ex = (p.beta * lbar) * phi * (S.WA * S.WB) * S.blend;
    }
    if (S.contact) Ec = (-p.beta) * S.overlap * S.D * (1.0 - S.blend);
}

void terms(const J* X, const Shape& S, double lbar, const CapillaryPairParams& p, const Consts& k, J& Ex, J& Ec) {
    const Geometry<J> G = geometry(X);
    Ex = J(0.0), Ec = J(0.0);
    const Factor b = S.crossing || S.contact ? blend_factor(G, S, k) : constant(0);
    if (S.crossing) {
        const J c = G.dt * G.dt * rcp(G.L1s * G.L2s);
        double phi, dphi, d2phi;
        p.law.eval(c.v, phi, dphi, d2phi);
        Ex = times(times((p.beta * lbar) * apply(c, phi, dphi, d2phi), shares_factor(G, S, k)), b);
    }
    if (S.contact) {
        J ov;
        Factor D;
        contact_factors(G, S, k, ov, D);
        const Factor one_minus_b = b.constant ? constant(1.0 - b.value) : varying(1.0 - b.jet);
        Ec = times(times((-p.beta) * ov, D), one_minus_b);
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
    const Shape S = shape(relative(X).data(), wet_crossing, consts(p));
    return !S.crossing && !S.contact;
}

double capillary_pair_energy(const Vector8d& X, double l0a, double l0b, bool wet_crossing,
                             const CapillaryPairParams& p, Vector8d* grad, Matrix8d* hess, bool project_psd,
                             CapillaryPairParts* parts, double contact_scale, Vector8d* contact_grad) {
    const Consts k = consts(p);
    const Vector8d Y = relative(X);
    const Shape S = shape(Y.data(), wet_crossing, k);
    if (parts) {
        parts->sin2 = S.s, parts->nonzero = S.crossing || S.contact;
        if (wet_crossing && S.blend > 0) parts->crossing_weight = S.blend * (S.WA * S.WB);
        if (S.blend < 1) parts->contact_weight = (1 - S.blend) * S.D, parts->overlap = S.overlap;
    }
    const double lbar = 0.5 * (l0a + l0b);
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    if (contact_grad) contact_grad->setZero();
    if (!S.crossing && !S.contact) return 0;
    if (!grad && !hess && !contact_grad) {
        double Ex, Ec;
        terms(S, lbar, p, Ex, Ec);
        if (parts) parts->crossing_energy = Ex, parts->contact_energy = Ec;
        return contact_scale == 1 ? Ex + Ec : Ex + contact_scale * Ec;
    }
    J Yj[8];
    Yj[0] = J(0.0), Yj[1] = J(0.0);
    for (int i = 0; i < 6; ++i) Yj[2 + i] = J::variable(Y[2 + i], i);
    J Ex, Ec;
    terms(Yj, S, lbar, p, k, Ex, Ec);
    if (parts) parts->crossing_energy = Ex.v, parts->contact_energy = Ec.v;
    if (contact_grad) *contact_grad = to_pair(Ec.g);
    const J E = contact_scale == 1 ? Ex + Ec : Ex + contact_scale * Ec;
    if (grad) *grad = to_pair(E.g);
    if (hess) {
        Matrix6d Hy = E.hessian();
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
