#pragma once
// A second-order forward-mode number: value, gradient and Hessian with respect to N inputs, carried through
// arithmetic. The blended bridge element's weights (bridge.hpp) are a long composition (signed distances, rates,
// crossing positions, smoothstep weights, the fade); writing their Hessians by hand would be error-prone, so they are
// written once as a template and evaluated in Jet<8> (in the 8 signed distances, bridge.cpp) where exact derivatives
// are needed; the smooth model's pair term likewise in Jet<6> (capillary_pair.cpp).
#include <Eigen/Core>
#include <cmath>

namespace fibernet {

template <int N>
struct Jet {
    // The Hessian is symmetric: only its lower triangle is carried, packed column by column (column j holds rows
    // j..N-1 from offset off(j)), N (N + 1) / 2 numbers instead of N^2 in every operation (docs/benchmarks.md, "The
    // pair term's jets"). hessian() unpacks it.
    static constexpr int P = N * (N + 1) / 2;
    using Gradient = Eigen::Matrix<double, N, 1>;
    using Packed = Eigen::Matrix<double, P, 1>;
    static constexpr int off(int j) { return j * N - j * (j - 1) / 2; }

    // Like a double (and an Eigen matrix), a default-initialized jet is left unset: zeroing a Hessian costs about as
    // much as a cheap operation, and the operations below assign all of their result. Constants: Jet(x).
    double v;
    Gradient g;
    Packed h;

    Jet() = default;
    Jet(double x)  // NOLINT: a constant
        : v(x), g(Gradient::Zero()), h(Packed::Zero()) {}
    static Jet variable(double x, int i) {
        Jet j(x);
        j.g[i] = 1;
        return j;
    }
    Eigen::Matrix<double, N, N> hessian() const {
        Eigen::Matrix<double, N, N> H;
        for (int j = 0; j < N; ++j)
            for (int i = j; i < N; ++i) H(i, j) = H(j, i) = h[off(j) + i - j];
        return H;
    }
};

namespace jet_detail {
// Column by column of the packed lower triangle, each a fixed-size vector expression (J a compile-time column):
//   r.h = a * bh + b * ah + x y^T + y x^T    (product; each entry summed in this order)
template <int N, int J = 0>
void product_columns(typename Jet<N>::Packed& r, double a, const typename Jet<N>::Packed& bh, double b,
                     const typename Jet<N>::Packed& ah, const typename Jet<N>::Gradient& x,
                     const typename Jet<N>::Gradient& y) {
    if constexpr (J < N) {
        constexpr int o = Jet<N>::off(J), L = N - J;
        r.template segment<L>(o) = a * bh.template segment<L>(o) + b * ah.template segment<L>(o) +
                                   x.template tail<L>() * y[J] + y.template tail<L>() * x[J];
        product_columns<N, J + 1>(r, a, bh, b, ah, x, y);
    }
}
//   r.h = df * ah + s x^T    (chain rule, s = f'' x)
template <int N, int J = 0>
void chain_columns(typename Jet<N>::Packed& r, double df, const typename Jet<N>::Packed& ah,
                   const typename Jet<N>::Gradient& s, const typename Jet<N>::Gradient& x) {
    if constexpr (J < N) {
        constexpr int o = Jet<N>::off(J), L = N - J;
        r.template segment<L>(o) = df * ah.template segment<L>(o) + s.template tail<L>() * x[J];
        chain_columns<N, J + 1>(r, df, ah, s, x);
    }
}
}  // namespace jet_detail

// f(a) given f, f', f'' at a.v (chain rule to second order).
template <int N>
Jet<N> apply(const Jet<N>& a, double f, double df, double d2f) {
    Jet<N> r;
    r.v = f;
    r.g = df * a.g;
    const typename Jet<N>::Gradient s = d2f * a.g;
    jet_detail::chain_columns<N>(r.h, df, a.h, s, a.g);
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
    jet_detail::product_columns<N>(r.h, a.v, b.h, b.v, a.h, a.g, b.g);
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
