// Scene: a non-integrable nonholonomic oscillator, in the family of McLachlan &
// Perlmutter's contact oscillator (2006, sec. 5):
//   Q = R^5, q = (x, y1, y2, z1, z2)
//   L = 1/2 |qd|^2 - 1/2 |q|^2 - (eps/2) (y1^2 z1^2 + y2^2 z2^2 + z1^2 z2^2)
//   constraint  xd + y1 z1d + y2 z2d = 0,  omega = (1, 0, 0, y1, y2)
// (eps = 1 by default; `epsilon` scales the coupling).  L and
// omega are invariant under (q, v) -> (q, -v) (reversible) but the coupling
// makes the motion chaotic: only the energy is conserved, so reversible KAM
// theory does not apply (not declared `integrable`).
//
// Index-reduced ODE: a = f + omega^T lambda with f = dL/dq,
//   lambda = -(f_x + y1 f_z1 + y2 f_z2 + y1d z1d + y2d z2d) / (1 + y1^2 + y2^2).
//
// Default run (experiments/scenes/chaotic_oscillator.json): q0 = (0.5, 0.6, -0.4,
// 0.3, 0.7), v0 = (-0.54, 0.4, -0.3, 0.5, -0.6) (xd0 = -(y1 z1d + y2 z2d)):
// every coordinate moves, E0 = 1.32825 (kinetic 0.5758, potential 0.75245).
#pragma once

#include <array>

#include "nhi/roles/system.hpp"

namespace nhi {

struct ChaoticOscillator {
  static constexpr int n = 5;
  static constexpr int m = 1;
  static constexpr const char* name = "chaotic_oscillator";
  static constexpr bool reversible = true;
  static constexpr const char* behaviour = "chaotic";
  static constexpr bool separable = true;

  double epsilon = 1.0;

  static auto parameters() { return std::array{Param<ChaoticOscillator>{"epsilon", &ChaoticOscillator::epsilon}}; }
  static Vec<double, 5> default_q0() { return (Vec<double, 5>() << 0.5, 0.6, -0.4, 0.3, 0.7).finished(); }
  static Vec<double, 5> default_v0() { return (Vec<double, 5>() << -0.54, 0.4, -0.3, 0.5, -0.6).finished(); }

  template <class T>
  T lagrangian(const Vec<T, 5>& q, const Vec<T, 5>& v) const {
    T kin = cst<T>(0.0), pot = cst<T>(0.0);
    for (int i = 0; i < 5; ++i) {
      kin += v[i] * v[i];
      pot += q[i] * q[i];
    }
    const T c = q[1] * q[1] * q[3] * q[3] + q[2] * q[2] * q[4] * q[4] + q[3] * q[3] * q[4] * q[4];
    return cst<T>(0.5) * kin - cst<T>(0.5) * pot - cst<T>(0.5 * epsilon) * c;
  }

  template <class T>
  void partials(const Vec<T, 5>& q, const Vec<T, 5>& v, Vec<T, 5>* dLdq, Vec<T, 5>* dLdv) const {
    const T e = cst<T>(epsilon);
    const T y1 = q[1], y2 = q[2], z1 = q[3], z2 = q[4];
    *dLdq << -q[0], -y1 - e * y1 * z1 * z1, -y2 - e * y2 * z2 * z2, -z1 - e * (y1 * y1 * z1 + z1 * z2 * z2),
        -z2 - e * (y2 * y2 * z2 + z1 * z1 * z2);
    *dLdv = v;
  }

  template <class T>
  Vec<T, 5> velocity(const Vec<T, 5>&, const Vec<T, 5>& p) const {
    return p;
  }

  template <class T>
  Mat<T, 1, 5> omega(const Vec<T, 5>& q) const {
    Mat<T, 1, 5> w;
    w << cst<T>(1.0), cst<T>(0.0), cst<T>(0.0), q[1], q[2];
    return w;
  }

  Vec<double, 5> acceleration(const Vec<double, 5>& q, const Vec<double, 5>& v) const {
    Vec<double, 5> f, dv;
    partials<double>(q, v, &f, &dv);
    const double y1 = q[1], y2 = q[2];
    const double lambda = -(f[0] + y1 * f[3] + y2 * f[4] + v[1] * v[3] + v[2] * v[4]) / (1.0 + y1 * y1 + y2 * y2);
    f[0] += lambda;
    f[3] += y1 * lambda;
    f[4] += y2 * lambda;
    return f;
  }
};

}  // namespace nhi
