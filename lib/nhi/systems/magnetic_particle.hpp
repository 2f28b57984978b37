// Scene: the nonholonomic particle of the paper (section 6.1, particle.hpp) with
// unit charge in a uniform magnetic field B e_z.
//   Q = R^3, q = (x, y, z)
//   L = 1/2 (xd^2 + yd^2 + zd^2) - U(q) + A(q) . qd,   A = (B/2) (-y, x, 0),
//   U = kx x^2 + ky y^2 + kxy x y
//     = (particle's L) - kxy x y + (B/2) (x yd - y xd)
//   constraint  zd - y xd = 0,  omega = (-y, 0, 1)               (the particle's)
// The term A . qd is the velocity-dependent potential of the Lorentz force
// (Goldstein, Poole & Safko, "Classical Mechanics", 3rd ed., sec. 1.5, eq. 1.62:
// U = e phi - e A . v, L = T - U); joining it to the paper's nonholonomic particle is this
// project's choice.  curl A = B e_z != 0, so A . qd is not a total time derivative
// (unlike the gauge term of contact_oscillator_nr): it changes the motion, adding
// the Lorentz force qd x B e_z = B (yd, -xd, 0) to the particle's equations.
//
// Index-reduced ODE (eq. 3, M = identity, f = -grad U = (-2 kx x - kxy y, -2 ky y - kxy x, 0),
// dL/dq = f + (B/2) (yd, -xd, 0), d/dt dL/dqd = qdd + (B/2) (-yd, xd, 0); lambda from
// eq. 4 differentiated once, zdd - xd yd - y xdd = 0):
//   xdd = f_x + B yd - y lambda,   ydd = f_y - B xd,   zdd = lambda,
//   lambda = (xd yd + y f_x + B y yd) / (1 + y^2).
// The energy p . qd - L = 1/2 |qd|^2 + U: the Lorentz force, like the
// constraint force, does no work.  y no longer decouples
// (B xd drives it), so the particle's second integral 1/2 yd^2 + ky y^2 is lost
// and no other is known: not declared integrable.
//
// Not reversible under rho(q, v) = (q, -v): rho leaves the kinetic and potential
// terms and the constraint alone but flips the sign of A . qd, so rho maps the
// flow for B to the flow for -B (the Lorentz force B (yd, -xd, 0) changes sign
// under v -> -v while the other forces do not) and is not a reversing symmetry
// for B != 0.  With kxy = 0 the reflections S = diag(1, -1, -1) and
// diag(-1, 1, -1) would preserve omega and U and reverse A . qd, so that
// (q, v) -> (S q, -S v) reversed the flow; the coupling kxy x y (default 0.5)
// breaks them, and of the eight sign reflections S none reverses the flow
// (checked numerically: there and back returns O(1) off the start).
// L = 1/2 |v|^2 + A(q) . v - U(q) has a term linear in v: not `separable`; the
// Legendre map p = v + A(q) is inverted by velocity() below.
//
// Default run (experiments/scenes/magnetic_particle.json): the particle's
// parameters kx = ky = 1 and state q0 = (1, 0.5, 0), v0 = (0.5, 1, 0.25) (on the
// constraint: zd0 = y0 xd0), kxy = 0.5, B = 1 (a cyclotron frequency of the
// order of the potential's, sqrt(2 kx) = 1.41), h = 0.2, 500 steps (T = 100).
// E0 = 2.15625; the field bends the (x, y) motion, which the constraint couples to z.
#pragma once

#include <array>

#include "nhi/systems/particle.hpp"

namespace nhi {

struct MagneticParticle {
  static constexpr int n = 3;
  static constexpr int m = 1;
  static constexpr const char* name = "magnetic_particle";
  // Not reversible under (q, v) -> (q, -v) and not known to be integrable (see above).
  static constexpr bool reversible = false;
  static constexpr bool integrable = false;
  // L has the term A(q) . v linear in v.
  static constexpr bool separable = false;

  double kx = 1.0;  // potential U = kx x^2 + ky y^2 + kxy x y
  double ky = 1.0;
  double kxy = 0.5;
  double B = 1.0;  // the field B e_z

  // The scene's `params` (defaults: the members' initial values).
  static auto parameters() {
    using P = Param<MagneticParticle>;
    return std::array{P{"kx", &MagneticParticle::kx}, P{"ky", &MagneticParticle::ky}, P{"kxy", &MagneticParticle::kxy},
                      P{"B", &MagneticParticle::B}};
  }
  // Default initial state: the particle's (experiments/scenes/magnetic_particle.json has the same numbers).
  static Vec<double, 3> default_q0() { return Particle::default_q0(); }
  static Vec<double, 3> default_v0() { return Particle::default_v0(); }

  Particle base() const {
    Particle b;
    b.kx = kx;
    b.ky = ky;
    return b;
  }

  template <class T>
  T lagrangian(const Vec<T, 3>& q, const Vec<T, 3>& v) const {
    return base().lagrangian<T>(q, v) - cst<T>(kxy) * q[0] * q[1] + cst<T>(0.5 * B) * (q[0] * v[1] - q[1] * v[0]);
  }

  // Hand-written dL/dq, dL/dqdot (fast path; checked against autodiff of L).
  template <class T>
  void partials(const Vec<T, 3>& q, const Vec<T, 3>& v, Vec<T, 3>* dLdq, Vec<T, 3>* dLdv) const {
    const T hb = cst<T>(0.5 * B);
    base().partials<T>(q, v, dLdq, dLdv);
    (*dLdq)[0] += hb * v[1] - cst<T>(kxy) * q[1];
    (*dLdq)[1] -= hb * v[0] + cst<T>(kxy) * q[0];
    (*dLdv)[0] -= hb * q[1];
    (*dLdv)[1] += hb * q[0];
  }

  // The inverse Legendre map V(q, p) = p - A(q) (fast path; checked against the generic one).
  template <class T>
  Vec<T, 3> velocity(const Vec<T, 3>& q, const Vec<T, 3>& p) const {
    const T hb = cst<T>(0.5 * B);
    Vec<T, 3> v = p;
    v[0] += hb * q[1];
    v[1] -= hb * q[0];
    return v;
  }

  template <class T>
  Mat<T, 1, 3> omega(const Vec<T, 3>& q) const {
    return base().omega<T>(q);
  }

  Vec<double, 3> acceleration(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    const double x = q[0], y = q[1];
    const double fx = -2.0 * kx * x - kxy * y, fy = -2.0 * ky * y - kxy * x;
    const double lambda = (v[0] * v[1] + y * fx + B * y * v[1]) / (1.0 + y * y);
    return {fx + B * v[1] - y * lambda, fy - B * v[0], lambda};
  }
};

}  // namespace nhi
