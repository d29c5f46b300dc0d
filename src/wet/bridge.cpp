#include "fibernet/wet/bridge.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fibernet/wet/jet.hpp"

namespace fibernet {

void bridge_nodes(const Model& m, const Bridge& b, int node[8]) {
    for (int s = 0; s < 2; ++s) {
        const std::vector<int>& nodes = m.chains[s == 0 ? b.f1 : b.f2].nodes;
        const int k = s == 0 ? b.k1 : b.k2, nseg = static_cast<int>(nodes.size()) - 1;
        if (k < 0 || k >= nseg) throw std::logic_error("bridge home segment out of range");
        int* nd = node + 4 * s;
        nd[0] = k > 0 ? nodes[k - 1] : -1, nd[1] = nodes[k], nd[2] = nodes[k + 1];
        nd[3] = k + 1 < nseg ? nodes[k + 2] : -1;
    }
}

BridgeElement resolve(const Model& m, const Bridge& b) {
    BridgeElement e;
    e.locked = b.locked;
    bridge_nodes(m, b, e.node);
    for (int s = 0; s < 2; ++s) {
        const FiberChain& ch = m.chains[s == 0 ? b.f1 : b.f2];
        const int k = s == 0 ? b.k1 : b.k2;
        const int nseg = static_cast<int>(ch.segments.size());
        const Eigen::Vector2i base = s == 0 ? Eigen::Vector2i(0, 0) : b.image;
        const Segment& h = m.segments[ch.segments[k]];
        Eigen::Vector2i* sh = e.shift + 4 * s;
        double* l0 = e.l0 + 3 * s;
        sh[1] = base, sh[2] = base + h.shift, l0[1] = h.l0;
        if (k > 0) {
            const Segment& p = m.segments[ch.segments[k - 1]];
            sh[0] = base - p.shift, l0[0] = p.l0;
        } else {
            sh[0] = base, l0[0] = 0;
        }
        if (k + 1 < nseg) {
            const Segment& n = m.segments[ch.segments[k + 1]];
            sh[3] = sh[2] + n.shift, l0[2] = n.l0;
        } else {
            sh[3] = sh[2], l0[2] = 0;
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

// Signed distances g of side s's nodes to the line of the other side's home segment (bridge.hpp), in type T.
// Absent nodes (fiber ends) are left untouched.
template <class T>
void side_g(const BridgeElement& e, const Vec2<T>* P, int s, T g[4]) {
    const int o = 1 - s;
    const Vec2<T> A = P[4 * o + 1], D = sub(P[4 * o + 2], A);
    const T len = sqrt_(dot(D, D));
    const int* nd = e.node + 4 * s;
    for (int a = 0; a < 4; ++a)
        if (nd[a] >= 0) g[a] = cross(D, sub(P[4 * s + a], A)) / len;
}

// z at the two home nodes of side s and the rates r = dg/ds there, from the side's g's, in type T.
// Returns false if a rate is zero (parallel lines).
template <class T>
bool side_z(const BridgeElement& e, const T g[4], int s, T z[2], T r[2]) {
    const int* nd = e.node + 4 * s;
    const double* l0 = e.l0 + 3 * s;
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

// In jets both steps by their closed-form derivatives: one operation instead of a dozen, the same value.
template <int N>
Jet<N> step01(const Jet<N>& u) {
    const double a = u.v, b = 1 - a;
    return apply(u, step01(a), 30 * a * a * b * b, 60 * a * b * (b - a));
}
template <int N>
Jet<N> smoothstep(const Jet<N>& x) {
    const double a = 0.5 * (x.v + 1.0), b = 1 - a;  // S(x) = step01(a): dS/dx = step01'(a) / 2
    return apply(x, smoothstep(x.v), 15 * a * a * b * b, 15 * a * b * (b - a));
}

// Weights of segments -, 0, + of both sides and the fade lambda, as functions of the 8 signed distances g[s][a]
// (side_g). Returns whether they depend on X.
template <class T>
bool bridge_weights(const BridgeElement& e, T g[2][4], T w[2][3], T& lambda) {
    T z[2][2], r[2][2];
    bool defined = !e.locked;
    for (int s = 0; s < 2 && defined; ++s) defined = side_z(e, g[s], s, z[s], r[s]);
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
        // Window fades: a neighbour's term fades out (C2) as the crossing passes the neighbour's far node, over a
        // quarter of its length, and the home's weight does not take that share. A crossing never gets there while
        // the set is kept consistent (it moves a bridge 0.1 blend half-widths past a node), but in a long solve of a
        // fixed set it can: the neighbour's term then kept full weight however far the crossing ran, a bridge between
        // segments that no longer cross (seen 5 fiber lengths away on a 100-fiber benchmark network).
        if (value_of(lambda) != 0) {
            const double* l0 = e.l0 + 3 * s;
            if (e.node[4 * s] >= 0 && value_of(w[s][0]) != 0) {  // beyond node k-1: z0 < -l0[0]
                const double df = 0.125 * l0[0], c = l0[0] + df;
                const double x = (value_of(z[s][0]) + c) / df;
                if (x <= -1) w[s][0] = T(0.0);
                else if (x < 1) w[s][0] = w[s][0] * smoothstep((z[s][0] + c) / df), varies = true;
            }
            if (e.node[4 * s + 3] >= 0 && value_of(w[s][2]) != 0) {  // beyond node k+2: z1 > l0[2]
                const double df = 0.125 * l0[2], c = l0[2] + df;
                const double x = (value_of(z[s][1]) - c) / df;
                if (x >= 1) w[s][2] = T(0.0);
                else if (x > -1) w[s][2] = w[s][2] * (1.0 - smoothstep((z[s][1] - c) / df)), varies = true;
            }
        }
    }
    if (value_of(lambda) == 0) varies = false;
    return varies;
}

// The weights at points P, in type T.
template <class T>
bool bridge_weights(const BridgeElement& e, const Vec2<T>* P, T w[2][3], T& lambda) {
    T g[2][4] = {};
    for (int s = 0; s < 2; ++s) side_g(e, P, s, g[s]);
    return bridge_weights(e, g, w, lambda);
}

double blended_energy(const BridgeElement& e, const Vec2<double>* P, double beta, const CapillaryLaw& law) {
    double w[2][3], lambda;
    bridge_weights(e, P, w, lambda);
    double E = 0;
    for (int i = 0; i < 3; ++i) {
        if (e.node[i] < 0 || e.node[i + 1] < 0 || w[0][i] == 0) continue;
        const Vec2<double> d1 = sub(P[i + 1], P[i]);
        for (int j = 0; j < 3; ++j) {
            if (e.node[4 + j] < 0 || e.node[5 + j] < 0 || w[1][j] == 0) continue;
            const Vec2<double> d2 = sub(P[5 + j], P[4 + j]);
            const double p = dot(d1, d2);
            const double c = p * p / (dot(d1, d1) * dot(d2, d2));
            const double l = 0.5 * (e.l0[i] + e.l0[3 + j]);
            E = E + w[0][i] * w[1][j] * (beta * l) * law_(law, c);
        }
    }
    return E;
}

void to_points(const Vector16d& X, Vec2<double>* P) {
    for (int a = 0; a < 8; ++a) P[a] = {X[2 * a], X[2 * a + 1]};
}

template <int M>
Eigen::Matrix<double, M, M> psd(const Eigen::Matrix<double, M, M>& h) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, M, M>> es(h);
    return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
}

// Pair (i, j) of bridge_energy: its inputs are d1 = P[i+1] - P[i], d2 = P[5+j] - P[4+j]. The local coordinates of
// each input's end and start node.
void pair_coordinates(int i, int j, int end[4], int start[4]) {
    const int e[4] = {2 * i + 2, 2 * i + 3, 2 * (5 + j), 2 * (5 + j) + 1};
    for (int c = 0; c < 4; ++c) end[c] = e[c], start[c] = e[c] - 2;
}

// The pair's 16-gradient A^T g4, A the 4 x 16 map X -> (d1, d2).
Vector16d pair_gradient(int i, int j, const Eigen::Vector4d& g4) {
    int end[4], start[4];
    pair_coordinates(i, j, end, start);
    Vector16d G = Vector16d::Zero();
    for (int c = 0; c < 4; ++c) G[end[c]] = g4[c], G[start[c]] = -g4[c];
    return G;
}

// H += A^T h A, scattered (A has one +-1 per column, so this is the dense product to the bit).
void add_pair_hessian(Matrix16d& H, int i, int j, const Eigen::Matrix4d& h) {
    int end[4], start[4];
    pair_coordinates(i, j, end, start);
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
            const double v = h(a, b);
            H(end[a], end[b]) += v, H(start[a], start[b]) += v;
            H(end[a], start[b]) -= v, H(start[a], end[b]) -= v;
        }
}

// A signed distance g = cross(D, Q - A) / |D|, D = B - A (side_g), with its gradient and Hessian in the 6 coordinates
// of A, B and Q, closed form. Every weight is a function of the 8 g's only, so the weights are differentiated in g
// (Jet<8>) and mapped to the 16 coordinates once, by these (bridge_element_energy).
struct Distance {
    double v;
    int col[6];  // local coordinates of A.x, A.y, B.x, B.y, Q.x, Q.y
    Eigen::Matrix<double, 6, 1> g;
    Eigen::Matrix<double, 6, 6> h;
};

void distance(const Vec2<double>* P, int ia, int ib, int iq, bool hessian, Distance& d) {
    const Vec2<double> A = P[ia], D = sub(P[ib], A), u = sub(P[iq], A);
    const double len = std::sqrt(dot(D, D)), c = cross(D, u);
    d.v = c / len;  // as side_g
    for (int k = 0; k < 2; ++k) d.col[k] = 2 * ia + k, d.col[2 + k] = 2 * ib + k, d.col[4 + k] = 2 * iq + k;
    // In (D, u): dc/dD = (u.y, -u.x) = cD, dc/du = (-D.y, D.x) = R D, R the rotation by +90 deg; g = c / |D|.
    const Eigen::Vector2d Dv(D.x, D.y), cD(u.y, -u.x), cu(-D.y, D.x);
    const double il = 1 / len, il2 = il * il;
    const Eigen::Vector2d gD = (cD - d.v * il * Dv) * il, gu = cu * il;
    // D = B - A, u = Q - A: d/dA = -(d/dD + d/du), d/dB = d/dD, d/dQ = d/du.
    d.g << -(gD + gu), gD, gu;
    if (!hessian) return;
    const Eigen::Matrix2d Hdd = (-(cD * Dv.transpose() + Dv * cD.transpose()) * il - d.v * Eigen::Matrix2d::Identity() +
                                 3 * d.v * il2 * Dv * Dv.transpose()) * il2;
    Eigen::Matrix2d R;
    R << 0, -1, 1, 0;
    const Eigen::Matrix2d Hud = (R - cu * Dv.transpose() * il2) * il;  // d2g / du dD; d2g / du2 = 0
    const Eigen::Matrix2d Hdu = Hud.transpose();
    d.h.block<2, 2>(0, 0) = Hdd + Hdu + Hud;
    d.h.block<2, 2>(0, 2) = -(Hdd + Hud);
    d.h.block<2, 2>(0, 4) = -Hdu;
    d.h.block<2, 2>(2, 0) = d.h.block<2, 2>(0, 2).transpose();
    d.h.block<2, 2>(2, 2) = Hdd;
    d.h.block<2, 2>(2, 4) = Hdu;
    d.h.block<2, 2>(4, 0) = d.h.block<2, 2>(0, 4).transpose();
    d.h.block<2, 2>(4, 2) = Hud;
    d.h.block<2, 2>(4, 4).setZero();
}

}  // namespace

double bridge_element_energy(const BridgeElement& e, const Vector16d& X, double beta, const CapillaryLaw& law,
                             Vector16d* grad, Matrix16d* hess, bool project_psd) {
    Vec2<double> P[8];
    to_points(X, P);
    if (!grad && !hess) return blended_energy(e, P, beta, law);
    double w[2][3], lambda;
    const bool blended = bridge_weights<double>(e, P, w, lambda);
    // Inside a blend zone the weights depend on X through the 8 signed distances g only (side_g): W(g) by Jet<8>,
    // the g's closed form (distance), the pair terms e_ij closed form (capillary.hpp). E = sum_ij W_ij(g(X)) e_ij(X):
    //   grad = J^T V_g + sum_ij W_ij de_ij
    //   hess = J^T V_gg J + sum_k V_g[k] d2g_k + J^T C + C^T J + sum_ij W_ij d2e_ij
    // with J = dg/dX (8 x 16), V(g) = sum_ij e_ij W_ij(g) at fixed e_ij, C = sum_ij dW_ij/dg de_ij^T (8 x 16).
    using J8 = Jet<8>;
    J8 W[2][3], lam, V;  // left unset outside a blend zone (jet.hpp)
    Distance dist[8];
    Eigen::Matrix<double, 8, 16> C;
    if (blended) {
        J8 G[2][4];
        for (int s = 0; s < 2; ++s)
            for (int a = 0; a < 4; ++a) {
                const int k = 4 * s + a, o = 1 - s;
                if (e.node[k] < 0) continue;
                distance(P, 4 * o + 1, 4 * o + 2, k, hess != nullptr, dist[k]);
                J8& x = G[s][a];  // the variable g_k, in place
                x.v = dist[k].v, x.g.setUnit(k), x.h.setZero();
            }
        bridge_weights<J8>(e, G, W, lam);
        V.v = 0, V.g.setZero(), V.h.setZero();
        if (hess) C.setZero();
    }
    if (grad) grad->setZero();
    if (hess) hess->setZero();
    double E = 0;
    // Pair (i, j) with weight wij; Wij its jet in a blend zone, else null.
    auto add_pair = [&](int i, int j, double wij, const J8* Wij) {
        const Eigen::Vector2d d1 = X.segment<2>(2 * i + 2) - X.segment<2>(2 * i);
        const Eigen::Vector2d d2 = X.segment<2>(2 * (5 + j)) - X.segment<2>(2 * (4 + j));
        const double l = 0.5 * (e.l0[i] + e.l0[3 + j]);
        Eigen::Vector4d g4;
        Eigen::Matrix4d H4;
        const double eij = bridge_energy(d1, d2, l, beta, law, &g4, hess ? &H4 : nullptr);
        E += wij * eij;
        const Vector16d G = pair_gradient(i, j, g4);
        if (grad) *grad += wij * G;
        if (Wij) {
            V.v += eij * wij, V.g += eij * Wij->g;
            if (hess) V.h += eij * Wij->h, C += Wij->g * G.transpose();
        }
        if (hess) {
            // Constant weights are 0, 1 or (a kinked pair with both neighbours on) -1: project the pair term.
            const Eigen::Matrix4d h = wij * H4;
            add_pair_hessian(*hess, i, j, !Wij && project_psd ? psd<4>(h) : h);
        }
    };
    for (int i = 0; i < 3; ++i) {
        if (e.node[i] < 0 || e.node[i + 1] < 0) continue;
        for (int j = 0; j < 3; ++j) {
            if (e.node[4 + j] < 0 || e.node[5 + j] < 0) continue;
            if (blended) {
                const J8 Wij = W[0][i] * W[1][j];
                if (Wij.v != 0 || !Wij.g.isZero(0)) add_pair(i, j, Wij.v, &Wij);
            } else if (w[0][i] * w[1][j] != 0) {
                add_pair(i, j, w[0][i] * w[1][j], nullptr);
            }
        }
    }
    if (blended) {
        // J has 6 nonzeros per row (Distance::col): scattered rather than multiplied densely.
        if (grad)
            for (int k = 0; k < 8; ++k)
                if (e.node[k] >= 0)
                    for (int c = 0; c < 6; ++c) (*grad)[dist[k].col[c]] += dist[k].g[c] * V.g[k];
        if (hess) {
            // J^T V_gg J + J^T C + C^T J = T + T^T with T = J^T K, K = V_gg J / 2 + C (V_gg symmetric).
            Eigen::Matrix<double, 8, 16> K = C;
            const Eigen::Matrix<double, 8, 8> Vgg = V.hessian();
            for (int l = 0; l < 8; ++l)
                if (e.node[l] >= 0)
                    for (int c = 0; c < 6; ++c) K.col(dist[l].col[c]) += (0.5 * dist[l].g[c]) * Vgg.col(l);
            Matrix16d Tt = Matrix16d::Zero();  // T^T = K^T J
            for (int k = 0; k < 8; ++k)
                if (e.node[k] >= 0)
                    for (int c = 0; c < 6; ++c) Tt.col(dist[k].col[c]) += dist[k].g[c] * K.row(k).transpose();
            *hess += Tt + Tt.transpose();
            for (int k = 0; k < 8; ++k) {
                if (e.node[k] < 0 || V.g[k] == 0) continue;
                const int* col = dist[k].col;
                for (int b = 0; b < 6; ++b)
                    for (int a = 0; a < 6; ++a) (*hess)(col[a], col[b]) += V.g[k] * dist[k].h(a, b);
            }
            if (project_psd) *hess = psd<16>(*hess);
        }
    }
    return E;
}

double bridge_element_energy_reference(const BridgeElement& e, const Vector16d& X, double beta,
                                       const CapillaryLaw& law, Vector16d* grad, Matrix16d* hess, bool project_psd) {
    // The original evaluation: the weights in Jet<16> through all 16 coordinates, a full 16 x 16 Hessian carried
    // through every operation (slow; kept to check bridge_element_energy against).
    Vec2<double> P[8];
    to_points(X, P);
    if (!grad && !hess) return blended_energy(e, P, beta, law);
    double w[2][3], lambda;
    const bool blended = bridge_weights<double>(e, P, w, lambda);
    using J = Jet<16>;
    J W[2][3], lam;
    if (blended) {
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
            Eigen::Matrix<double, 4, 16> A = Eigen::Matrix<double, 4, 16>::Zero();
            A.block<2, 2>(0, 2 * i) = -Eigen::Matrix2d::Identity();
            A.block<2, 2>(0, 2 * i + 2) = Eigen::Matrix2d::Identity();
            A.block<2, 2>(2, 2 * (4 + j)) = -Eigen::Matrix2d::Identity();
            A.block<2, 2>(2, 2 * (5 + j)) = Eigen::Matrix2d::Identity();
            const Vector16d G = A.transpose() * g4;
            if (grad) *grad += eij * Wij.g + Wij.v * G;
            if (hess) {
                if (blended) {
                    *hess += eij * Wij.hessian() + Wij.g * G.transpose() + G * Wij.g.transpose() +
                             A.transpose() * (Wij.v * H4) * A;
                } else {
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
        double g[4] = {};
        side_g(e, P, s, g);
        if (e.locked || !side_z(e, g, s, c.z[s], r)) c.defined = false;
        for (int n = 0; n < 2; ++n) c.defined = c.defined && std::abs(r[n]) >= kSinBlend;
    }
    if (!c.defined)
        for (int s = 0; s < 2; ++s) c.z[s][0] = c.z[s][1] = 0;
    return c;
}

}  // namespace fibernet
