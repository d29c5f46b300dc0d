#include "fibernet/wet/bridge.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fibernet/wet/jet.hpp"

namespace fibernet {

BridgeElement resolve(const Model& m, const Bridge& b) {
    BridgeElement e;
    e.locked = b.locked;
    for (int s = 0; s < 2; ++s) {
        const FiberChain& ch = m.chains[s == 0 ? b.f1 : b.f2];
        const int k = s == 0 ? b.k1 : b.k2;
        const int nseg = static_cast<int>(ch.segments.size());
        if (k < 0 || k >= nseg) throw std::logic_error("bridge home segment out of range");
        const Eigen::Vector2i base = s == 0 ? Eigen::Vector2i(0, 0) : b.image;
        const Segment& h = m.segments[ch.segments[k]];
        int* nd = e.node + 4 * s;
        Eigen::Vector2i* sh = e.shift + 4 * s;
        double* l0 = e.l0 + 3 * s;
        nd[1] = ch.nodes[k], sh[1] = base;
        nd[2] = ch.nodes[k + 1], sh[2] = base + h.shift;
        l0[1] = h.l0;
        if (k > 0) {
            const Segment& p = m.segments[ch.segments[k - 1]];
            nd[0] = ch.nodes[k - 1], sh[0] = base - p.shift, l0[0] = p.l0;
        } else {
            nd[0] = -1, sh[0] = base, l0[0] = 0;
        }
        if (k + 1 < nseg) {
            const Segment& n = m.segments[ch.segments[k + 1]];
            nd[3] = ch.nodes[k + 2], sh[3] = sh[2] + n.shift, l0[2] = n.l0;
        } else {
            nd[3] = -1, sh[3] = sh[2], l0[2] = 0;
        }
    }
    return e;
}

Vector16d element_coordinates(const BridgeElement& e, const Eigen::VectorXd& x, const Eigen::Matrix2d& B) {
    Vector16d X = Vector16d::Zero();
    for (int a = 0; a < 8; ++a)
        if (e.node[a] >= 0) X.segment<2>(2 * a) = x.segment<2>(2 * e.node[a]) + B * e.shift[a].cast<double>();
    return X;
}

namespace {

// C2 smoothstep from 0 at x = -1 to 1 at x = 1 (quintic), S(0) = 1/2.
template <class T>
T smoothstep(const T& x) {
    const T u = 0.5 * (x + 1.0);
    return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
}

template <class T>
struct Vec2 {
    T x, y;
};
template <class T>
Vec2<T> sub(const Vec2<T>& a, const Vec2<T>& b) { return {a.x - b.x, a.y - b.y}; }
template <class T>
T cross(const Vec2<T>& a, const Vec2<T>& b) { return a.x * b.y - a.y * b.x; }
template <class T>
T dot(const Vec2<T>& a, const Vec2<T>& b) { return a.x * b.x + a.y * b.y; }

inline double sqrt_(double v) { return std::sqrt(v); }
template <int N>
Jet<N> sqrt_(const Jet<N>& v) { return sqrt(v); }

inline double law_(const CapillaryLaw& law, double c) {
    double p, dp, d2p;
    law.eval(c, p, dp, d2p);
    return p;
}
template <int N>
Jet<N> law_(const CapillaryLaw& law, const Jet<N>& c) {
    double p, dp, d2p;
    law.eval(c.v, p, dp, d2p);
    return apply(c, p, dp, d2p);
}

// z at the two home nodes of side s (see bridge.hpp) and the rates r = dg/ds there, in type T.
// Returns false if a rate is zero (parallel lines).
template <class T>
bool side_z(const BridgeElement& e, const Vec2<T>* P, int s, T z[2], T r[2]) {
    const int o = 1 - s;
    const Vec2<T> A = P[4 * o + 1], D = sub(P[4 * o + 2], A);
    const T len = sqrt_(dot(D, D));
    const int* nd = e.node + 4 * s;
    const double* l0 = e.l0 + 3 * s;
    T g[4];
    for (int a = 0; a < 4; ++a)
        if (nd[a] >= 0) g[a] = cross(D, sub(P[4 * s + a], A)) / len;
    const T r0 = (g[2] - g[1]) / l0[1];
    r[0] = nd[0] >= 0 ? 0.5 * (r0 + (g[1] - g[0]) / l0[0]) : r0;
    r[1] = nd[3] >= 0 ? 0.5 * (r0 + (g[3] - g[2]) / l0[2]) : r0;
    if (value_of(r[0]) == 0 || value_of(r[1]) == 0) return false;
    z[0] = -g[1] / r[0];
    z[1] = -g[2] / r[1];
    return std::isfinite(value_of(z[0])) && std::isfinite(value_of(z[1]));
}

void deltas(const BridgeElement& e, int s, double d[2]) {
    const double* l0 = e.l0 + 3 * s;
    d[0] = 0.25 * (e.node[4 * s] >= 0 ? std::min(l0[0], l0[1]) : l0[1]);
    d[1] = 0.25 * (e.node[4 * s + 3] >= 0 ? std::min(l0[1], l0[2]) : l0[1]);
}

// Near-parallel pairs: the crossing runs off to infinity as the rates r (~ sin alpha) vanish, and it jumps from one
// end to the other as r changes sign. The blend is therefore faded into the home-only weights as any |r| falls from
// kSinBlend to kSinHome: lambda = prod over the 4 rates of S01((r^2 - kSinHome^2) / (kSinBlend^2 - kSinHome^2)).
constexpr double kSinHome = 0.03489949670250097;   // sin 2 deg
constexpr double kSinBlend = 0.08715574274765817;  // sin 5 deg

template <class T>
T step01(const T& u) { return u * u * u * (10.0 - 15.0 * u + 6.0 * u * u); }

// Weights of segments -, 0, + of both sides and the fade lambda. Returns whether they depend on X.
template <class T>
bool bridge_weights(const BridgeElement& e, const Vec2<T>* P, T w[2][3], T& lambda) {
    T z[2][2], r[2][2];
    bool defined = !e.locked;
    for (int s = 0; s < 2 && defined; ++s) defined = side_z(e, P, s, z[s], r[s]);
    bool varies = false;
    lambda = T(defined ? 1.0 : 0.0);
    if (defined) {
        const double lo = kSinHome * kSinHome, hi = kSinBlend * kSinBlend;
        for (int s = 0; s < 2; ++s)
            for (int n = 0; n < 2; ++n) {
                const double r2 = value_of(r[s][n]) * value_of(r[s][n]);
                if (r2 <= lo) lambda = T(0.0);
                else if (r2 < hi && value_of(lambda) != 0) lambda = lambda * step01((r[s][n] * r[s][n] - lo) / (hi - lo)), varies = true;
            }
    }
    for (int s = 0; s < 2; ++s) {
        w[s][0] = T(0.0), w[s][2] = T(0.0);
        if (value_of(lambda) != 0) {
            double d[2];
            deltas(e, s, d);
            const double z0 = value_of(z[s][0]), z1 = value_of(z[s][1]);
            if (std::abs(z0) < d[0]) w[s][0] = 1.0 - smoothstep(z[s][0] / d[0]), varies = true;
            else if (z0 <= -d[0]) w[s][0] = T(1.0);
            if (std::abs(z1) < d[1]) w[s][2] = smoothstep(z[s][1] / d[1]), varies = true;
            else if (z1 >= d[1]) w[s][2] = T(1.0);
            if (value_of(lambda) != 1) w[s][0] = lambda * w[s][0], w[s][2] = lambda * w[s][2];
        }
        w[s][1] = 1.0 - w[s][0] - w[s][2];
    }
    if (value_of(lambda) == 0) varies = false;
    return varies;
}

template <class T>
T blended_energy(const BridgeElement& e, const Vec2<T>* P, double beta, const CapillaryLaw& law) {
    T w[2][3], lambda;
    bridge_weights(e, P, w, lambda);
    T E(0.0);
    for (int i = 0; i < 3; ++i) {
        if (e.node[i] < 0 || e.node[i + 1] < 0 || value_of(w[0][i]) == 0) continue;
        const Vec2<T> d1 = sub(P[i + 1], P[i]);
        for (int j = 0; j < 3; ++j) {
            if (e.node[4 + j] < 0 || e.node[5 + j] < 0 || value_of(w[1][j]) == 0) continue;
            const Vec2<T> d2 = sub(P[5 + j], P[4 + j]);
            const T p = dot(d1, d2);
            const T c = p * p / (dot(d1, d1) * dot(d2, d2));
            const double l = 0.5 * (e.l0[i] + e.l0[3 + j]);
            E = E + w[0][i] * w[1][j] * (beta * l) * law_(law, c);
        }
    }
    return E;
}

void to_points(const Vector16d& X, Vec2<double>* P) {
    for (int a = 0; a < 8; ++a) P[a] = {X[2 * a], X[2 * a + 1]};
}

}  // namespace

namespace {
template <int M>
Eigen::Matrix<double, M, M> psd(const Eigen::Matrix<double, M, M>& h) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, M, M>> es(h);
    return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
}
}  // namespace

double bridge_element_energy(const BridgeElement& e, const Vector16d& X, double beta, const CapillaryLaw& law,
                             Vector16d* grad, Matrix16d* hess, bool project_psd) {
    Vec2<double> P[8];
    to_points(X, P);
    if (!grad && !hess) return blended_energy<double>(e, P, beta, law);
    double w[2][3], lambda;
    const bool blended = bridge_weights<double>(e, P, w, lambda);
    using J = Jet<16>;
    J W[2][3], lam;
    if (blended) {
        // Inside a blend zone the weights depend on all 16 coordinates: their exact derivatives by jets; the pair
        // terms stay closed form (capillary.hpp) and are combined by the product rule.
        Vec2<J> PJ[8];
        for (int a = 0; a < 8; ++a) PJ[a] = {J::variable(X[2 * a], 2 * a), J::variable(X[2 * a + 1], 2 * a + 1)};
        bridge_weights<J>(e, PJ, W, lam);
    }
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    double E = 0;
    Eigen::Vector4d g4;
    Eigen::Matrix4d H4;
    for (int i = 0; i < 3; ++i) {
        if (e.node[i] < 0 || e.node[i + 1] < 0) continue;
        const Eigen::Vector2d d1 = X.segment<2>(2 * i + 2) - X.segment<2>(2 * i);
        for (int j = 0; j < 3; ++j) {
            if (e.node[4 + j] < 0 || e.node[5 + j] < 0) continue;
            J Wij;
            if (blended) {
                Wij = W[0][i] * W[1][j];
                if (Wij.v == 0 && Wij.g.isZero(0)) continue;
            } else {
                if (w[0][i] * w[1][j] == 0) continue;
                Wij = J(w[0][i] * w[1][j]);
            }
            const Eigen::Vector2d d2 = X.segment<2>(2 * (5 + j)) - X.segment<2>(2 * (4 + j));
            const double l = 0.5 * (e.l0[i] + e.l0[3 + j]);
            const double eij = bridge_energy(d1, d2, l, beta, law, &g4, hess ? &H4 : nullptr);
            E += Wij.v * eij;
            // d = X_end - X_start for both segments: local map A (4 x 16).
            Eigen::Matrix<double, 4, 16> A = Eigen::Matrix<double, 4, 16>::Zero();
            A.block<2, 2>(0, 2 * i) = -Eigen::Matrix2d::Identity();
            A.block<2, 2>(0, 2 * i + 2) = Eigen::Matrix2d::Identity();
            A.block<2, 2>(2, 2 * (4 + j)) = -Eigen::Matrix2d::Identity();
            A.block<2, 2>(2, 2 * (5 + j)) = Eigen::Matrix2d::Identity();
            const Vector16d G = A.transpose() * g4;
            if (grad) *grad += eij * Wij.g + Wij.v * G;
            if (hess) {
                if (blended) {
                    *hess += eij * Wij.h + Wij.g * G.transpose() + G * Wij.g.transpose() +
                             A.transpose() * (Wij.v * H4) * A;
                } else {
                    // Constant weights are 0, 1 or (a kinked pair with both neighbours on) -1: project the pair term.
                    const Eigen::Matrix4d h = Wij.v * H4;
                    *hess += A.transpose() * (project_psd ? psd<4>(h) : h) * A;
                }
            }
        }
    }
    if (hess && blended && project_psd) *hess = psd<16>(*hess);
    return E;
}

CrossingPosition crossing_position(const BridgeElement& e, const Vector16d& X) {
    Vec2<double> P[8];
    to_points(X, P);
    CrossingPosition c;
    double r[2];
    for (int s = 0; s < 2; ++s) {
        deltas(e, s, c.delta[s]);
        if (e.locked || !side_z<double>(e, P, s, c.z[s], r)) c.defined = false;
        for (int n = 0; n < 2; ++n) c.defined = c.defined && std::abs(r[n]) >= kSinBlend;
    }
    if (!c.defined)
        for (int s = 0; s < 2; ++s) c.z[s][0] = c.z[s][1] = 0;
    return c;
}

}  // namespace fibernet
