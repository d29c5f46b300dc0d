#pragma once
// A second-order forward-mode number: value, gradient and Hessian with respect to N inputs, carried through
// arithmetic. The blended bridge element's weights (bridge.hpp) are a long composition (signed distances, rates,
// crossing positions, smoothstep weights, the fade); writing their Hessians by hand would be error-prone, so they are
// written once as a template and evaluated in Jet<8> (in the 8 signed distances, bridge.cpp) where exact derivatives
// are needed.
#include <Eigen/Core>
#include <cmath>

namespace fibernet {

template <int N>
struct Jet {
    // Like a double (and an Eigen matrix), a default-initialized jet is left unset: zeroing an N x N Hessian costs
    // about as much as a cheap operation, and the operations below assign all of their result. Constants: Jet(x).
    double v;
    Eigen::Matrix<double, N, 1> g;
    Eigen::Matrix<double, N, N> h;

    Jet() = default;
    Jet(double x)  // NOLINT: a constant
        : v(x), g(Eigen::Matrix<double, N, 1>::Zero()), h(Eigen::Matrix<double, N, N>::Zero()) {}
    static Jet variable(double x, int i) {
        Jet j(x);
        j.g[i] = 1;
        return j;
    }
};

// f(a) given f, f', f'' at a.v (chain rule to second order).
template <int N>
Jet<N> apply(const Jet<N>& a, double f, double df, double d2f) {
    Jet<N> r;
    r.v = f;
    r.g = df * a.g;
    r.h = df * a.h;
    r.h.noalias() += (d2f * a.g) * a.g.transpose();  // in place, as in operator* below
    return r;
}

template <int N>
Jet<N> operator+(const Jet<N>& a, const Jet<N>& b) {
    Jet<N> r;
    r.v = a.v + b.v, r.g = a.g + b.g, r.h = a.h + b.h;
    return r;
}
template <int N>
Jet<N> operator-(const Jet<N>& a, const Jet<N>& b) {
    Jet<N> r;
    r.v = a.v - b.v, r.g = a.g - b.g, r.h = a.h - b.h;
    return r;
}
template <int N>
Jet<N> operator-(const Jet<N>& a) {
    Jet<N> r;
    r.v = -a.v, r.g = -a.g, r.h = -a.h;
    return r;
}
template <int N>
Jet<N> operator*(const Jet<N>& a, const Jet<N>& b) {
    Jet<N> r;
    r.v = a.v * b.v;
    r.g = a.v * b.g + b.v * a.g;
    // In three statements, so that no temporary holds the outer products; each entry sums in the order of the one
    // expression ((a.v b.h + b.v a.h) + a.g b.g^T) + b.g a.g^T, so the result is the same (products commute exactly).
    r.h = a.v * b.h + b.v * a.h;
    r.h.noalias() += a.g * b.g.transpose();
    r.h.noalias() += b.g * a.g.transpose();
    return r;
}
template <int N>
Jet<N> operator*(double s, const Jet<N>& a) {
    Jet<N> r;
    r.v = s * a.v, r.g = s * a.g, r.h = s * a.h;
    return r;
}
template <int N>
Jet<N> operator*(const Jet<N>& a, double s) { return s * a; }
template <int N>
Jet<N> operator+(const Jet<N>& a, double s) {
    Jet<N> r = a;
    r.v += s;
    return r;
}
template <int N>
Jet<N> operator+(double s, const Jet<N>& a) { return a + s; }
template <int N>
Jet<N> operator-(double s, const Jet<N>& a) {
    Jet<N> r;
    r.v = s - a.v, r.g = -a.g, r.h = -a.h;
    return r;
}
template <int N>
Jet<N> operator-(const Jet<N>& a, double s) { return a + (-s); }
template <int N>
Jet<N> inverse(const Jet<N>& a) {
    const double i = 1 / a.v;
    return apply(a, i, -i * i, 2 * i * i * i);
}
template <int N>
Jet<N> operator/(const Jet<N>& a, const Jet<N>& b) { return a * inverse(b); }
template <int N>
Jet<N> operator/(const Jet<N>& a, double s) { return (1 / s) * a; }
template <int N>
Jet<N> sqrt(const Jet<N>& a) {
    const double s = std::sqrt(a.v);
    return apply(a, s, 0.5 / s, -0.25 / (s * a.v));
}

// Plain doubles share the element template.
inline double value_of(double x) { return x; }
template <int N>
double value_of(const Jet<N>& x) { return x.v; }

}  // namespace fibernet
