// Scene: the nonholonomic particle (paper section 6.1).
//   Q = R^3, q = (x, y, z)
//   L = 1/2 (xd^2 + yd^2 + zd^2) - (kx x^2 + ky y^2)        (paper: kx = ky = 1)
//   constraint  zd - y xd = 0,  omega = (-y, 0, 1)
// A Chaplygin system: G = R acts on z, connection A = dz - y dx.
// kx, ky are the `params` of the scene (default 1, the paper's potential);
// ky-only potentials (kx = 0) give the (x, z) translation symmetry of Thm 5.3.
//
// Index-reduced ODE (eq. 3 with lambda eliminated by differentiating eq. 4):
//   xdd = -2 kx x - y lambda,  ydd = -2 ky y,  zdd = lambda,
//   lambda = (xd yd - 2 kx x y) / (1 + y^2).
//
// Default run (the paper gives none): q0 = (1, 0.5, 0), v0 = (0.5, 1, 0.25)
// (zd0 = y0 xd0, so v0 satisfies the constraint), h = 0.2, 500 steps (T = 100).
// All three coordinates move and are coupled through the constraint from the
// start (y0 != 0, xd0 != 0), the energy E0 = 1.90625 is O(1), and T = 100 is
// about 22 periods of the y oscillation (period pi/sqrt(2)).
#pragma once

#include <array>

#include "nhi/roles/system.hpp"

namespace nhi {

struct Particle {
  static constexpr int n = 3;
  static constexpr int m = 1;
  static constexpr const char* name = "particle";
  // Chaplygin split (reduced.hpp): shape r = (x, y), group s = z.
  static constexpr std::array<int, 2> shape{0, 1};
  static constexpr std::array<int, 1> group{2};

  // L and omega are invariant under (q, v) -> (q, -v): the standard reversing symmetry.
  static constexpr bool reversible = true;
  // Integrable: E and the y energy 1/2 yd^2 + ky y^2 are conserved and z is cyclic, so
  // the reduced flow has two degrees of freedom and two integrals (system.hpp).
  static constexpr bool integrable = true;
  static constexpr const char* paper_section = "6.1";
  // L = 1/2 v^T M v - U(q) with M constant (hamiltonian.hpp).
  static constexpr bool separable = true;

  double kx = 1.0;  // potential V = kx x^2 + ky y^2
  double ky = 1.0;

  // The scene's `params` (defaults: the members' initial values).
  static auto parameters() {
    return std::array{Param<Particle>{"kx", &Particle::kx}, Param<Particle>{"ky", &Particle::ky}};
  }
  // Default initial state (experiments/scenes/particle.json has the same numbers).
  static Vec<double, 3> default_q0() { return {1.0, 0.5, 0.0}; }
  static Vec<double, 3> default_v0() { return {0.5, 1.0, 0.25}; }

  template <class T>
  T lagrangian(const Vec<T, 3>& q, const Vec<T, 3>& v) const {
    return cst<T>(0.5) * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) -
           (cst<T>(kx) * q[0] * q[0] + cst<T>(ky) * q[1] * q[1]);
  }

  // Hand-written dL/dq, dL/dqdot (fast path; checked against autodiff of L).
  template <class T>
  void partials(const Vec<T, 3>& q, const Vec<T, 3>& v, Vec<T, 3>* dLdq, Vec<T, 3>* dLdv) const {
    *dLdq << cst<T>(-2.0 * kx) * q[0], cst<T>(-2.0 * ky) * q[1], cst<T>(0.0);
    *dLdv = v;
  }

  // The inverse Legendre map V(q, p) = p (fast path; checked against the generic one).
  template <class T>
  Vec<T, 3> velocity(const Vec<T, 3>&, const Vec<T, 3>& p) const {
    return p;
  }

  template <class T>
  Mat<T, 1, 3> omega(const Vec<T, 3>& q) const {
    // (-y, 0) is written as one pair, (-y) (1, 0), not entry by entry: Eigen
    // reads the row's first two entries as one 16-byte packet, and after two
    // 8-byte stores that load misses the CPU's store-to-load forwarding and
    // stalls (a large share of mp06's particle step).  The same values as
    // entry by entry for finite y (w[1] = -0 for y > 0), so every step of the
    // particle is the same bit for bit.
    Mat<T, 1, 3> w;
    w.template head<2>() = Mat<T, 1, 2>::Constant(-q[1]).cwiseProduct(Mat<T, 1, 2>(cst<T>(1.0), cst<T>(0.0)));
    w[2] = cst<T>(1.0);
    return w;
  }

  // Theorem 5.3 (eq. 24) with kx = 0: translations in (x, z) are a symmetry and
  // the section xi(q) = (1, y) has generator d/dx + y d/dz in D.  The discrete
  // nonholonomic momentum J_k = <p_k, xi(q_k)_Q> = p_x + y p_z, and eq. (24) reads
  // J_{k+1} - J_k = <p_{k+1}, (xi(q_{k+1}) - xi(q_k))_Q> = p_{z,k+1} (y_{k+1} - y_k).
  // Continuous (eq. 23): d/dt (xd + y zd) = zd yd.
  static double nonholonomic_momentum(const Vec<double, 3>& q, const Vec<double, 3>& p) { return p[0] + q[1] * p[2]; }
  static double momentum_equation_rhs(const Vec<double, 3>& q0, const Vec<double, 3>& q1, const Vec<double, 3>& p1) {
    return p1[2] * (q1[1] - q0[1]);
  }

  Vec<double, 3> acceleration(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    const double y = q[1];
    const double lambda = (v[0] * v[1] - 2.0 * kx * q[0] * y) / (1.0 + y * y);
    return {-2.0 * kx * q[0] - y * lambda, -2.0 * ky * y, lambda};
  }
};

}  // namespace nhi
