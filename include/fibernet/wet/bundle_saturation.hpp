#pragma once
// The smooth model's partner cap (issue 22; docs/wet.md, "The partner cap in the smooth model"): the smooth
// counterpart of the event model's --bundle-partners N.
//
// In 2D nothing keeps fibers from stacking on one line, and the contact term is a sum over pairs: a bundle of k
// collinear fibers holds k(k-1)/2 adhering pairs per length, so the energy falls as fibers pile up and where a solve
// stops depends on its path (docs/wet.md). The cap saturates each segment's adhesion instead. For segment a with rest
// length l_a and contact energies C_ab (the pair terms' contact parts, <= 0) with its partners b,
//   n_a = -sum_b C_ab / (beta l_a)            its partners' share of its length (1: one partner along its length)
//   E_contact = sum_a -(beta / 2) l_a S(n_a)
// S(n) = n for n <= N - h (so below the cap the contact energy is the pair sum unchanged, the two halves of each pair
// adding to C_ab), S(n) = N for n >= N + h, and in between a C2 blend (S' falls from 1 to 0 by a cubic smoothstep).
// h = 1/2, so N >= 2 leaves a two-fiber bundle (n = 1) exact. Each segment's adhesion is at most N beta l_a / 2, so
// E_contact >= -N beta (total length) / 2. N = 0: no cap (S(n) = n everywhere).
namespace fibernet {

struct Saturation {
    double S = 0, dS = 1, d2S = 0;  // S(n), S'(n), S''(n)
};

// S and its derivatives at n for a cap of N partners (N = 0: none, S(n) = n).
Saturation bundle_saturation(double n, int N);

constexpr double kSaturationHalfWidth = 0.5;  // h

}  // namespace fibernet
