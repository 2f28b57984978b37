// Scene: the nonholonomic contact oscillator (McLachlan & Perlmutter 2006,
// "Integrators for nonholonomic mechanical systems", J. Nonlinear Sci. 16, sec. 5.2;
// also Modin & Verdier 2020, "What makes nonholonomic integrators work?").
//   Q = R^3, q = (x, y, z)
//   L = 1/2 (xd^2 + yd^2 + zd^2) - 1/2 (x^2 + y^2 + z^2) - (eps/2) x^2 z^2
//   constraint  xd + y zd = 0,  omega = (1, 0, y)
// y decouples (ydd = -y), so besides the energy H the motion keeps
//   H_y = 1/2 (y^2 + yd^2)   and   R = H - H_y.
// L and omega are invariant under (q, v) -> (q, -v) (reversible), and the
// system is integrable: the reversible-integrable class on which Modin & Verdier
// show that reversible methods keep the first integrals bounded.
//
// Index-reduced ODE (eq. 3 with lambda from eq. 4 differentiated once):
//   a = f + omega^T lambda,  f = dL/dq = -(x + eps x z^2, y, z + eps x^2 z),
//   lambda = -(f_x + y f_z + yd zd) / (1 + y^2).
//
// Default run: y(t) = cos t (y0 = 1, yd0 = 0, so H_y = 1/2), z0 = 1/2, zd0 = 0,
// xd0 = -y0 zd0 = 0, and x0 > 0 from H = 3/2, i.e. R = 1:
//   1/2 x0^2 (1 + eps z0^2) + 1/2 z0^2 = 1  ->  x0 = sqrt(1.75 / (1 + eps / 4))
// (= 1.2758944...; eps = 0.3).  h = 2 sin(pi/40) (a leapfrog-type method then
// samples the y oscillation exactly every 40 steps, as McLachlan & Perlmutter
// and Modin & Verdier did).
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "nhi/roles/system.hpp"

namespace nhi {

struct ContactOscillator {
  static constexpr int n = 3;
  static constexpr int m = 1;
  static constexpr const char* name = "contact_oscillator";
  static constexpr bool reversible = true;
  // Integrable (H, H_y, R), so reversible KAM theory bounds the energy of reversible methods.
  static constexpr bool integrable = true;
  static constexpr bool separable = true;  // L = 1/2 |v|^2 - U(q)

  double epsilon = 0.3;

  static auto parameters() { return std::array{Param<ContactOscillator>{"epsilon", &ContactOscillator::epsilon}}; }
  // experiments/scenes/contact_oscillator.json has the same numbers (eps = 0.3).
  static Vec<double, 3> default_q0() { return {std::sqrt(1.75 / (1.0 + 0.3 / 4.0)), 1.0, 0.5}; }
  static Vec<double, 3> default_v0() { return {0.0, 0.0, 0.0}; }

  template <class T>
  T lagrangian(const Vec<T, 3>& q, const Vec<T, 3>& v) const {
    return cst<T>(0.5) * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) -
           cst<T>(0.5) * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) - cst<T>(0.5 * epsilon) * q[0] * q[0] * q[2] * q[2];
  }

  template <class T>
  void partials(const Vec<T, 3>& q, const Vec<T, 3>& v, Vec<T, 3>* dLdq, Vec<T, 3>* dLdv) const {
    *dLdq << -q[0] - cst<T>(epsilon) * q[0] * q[2] * q[2], -q[1], -q[2] - cst<T>(epsilon) * q[0] * q[0] * q[2];
    *dLdv = v;
  }

  template <class T>
  Vec<T, 3> velocity(const Vec<T, 3>&, const Vec<T, 3>& p) const {
    return p;
  }

  template <class T>
  Mat<T, 1, 3> omega(const Vec<T, 3>& q) const {
    Mat<T, 1, 3> w;
    w << cst<T>(1.0), cst<T>(0.0), q[1];
    return w;
  }

  Vec<double, 3> acceleration(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    const double x = q[0], y = q[1], z = q[2];
    const double fx = -x - epsilon * x * z * z, fy = -y, fz = -z - epsilon * x * x * z;
    const double lambda = -(fx + y * fz + v[1] * v[2]) / (1.0 + y * y);
    return {fx + lambda, fy, fz + y * lambda};
  }

  // The Poincare section family (experiments/studies/study_poincare.cpp): `count` states
  // on the default level H = 3/2, H_y = 1/2 at y's maximum (y0 = 1, yd0 = 0),
  // zd0 = xd0 = 0, z0 spread over [-0.9 sqrt 2, 0.9 sqrt 2] (|z0| < sqrt 2 for
  // R = 1), x0 = sqrt((2 - z0^2) / (1 + eps z0^2)) > 0.  The section plots
  // (q[section_coordinate], v[section_coordinate]) = (z, zd) once per y period.
  static constexpr int section_coordinate = 2;
  std::vector<std::pair<Vec<double, 3>, Vec<double, 3>>> section_states(int count) const {
    std::vector<std::pair<Vec<double, 3>, Vec<double, 3>>> out;
    for (int j = 0; j < count; ++j) {
      const double z0 = 0.9 * std::sqrt(2.0) * (2.0 * j / (count - 1) - 1.0);
      const double x0 = std::sqrt((2.0 - z0 * z0) / (1.0 + epsilon * z0 * z0));
      out.push_back({Vec<double, 3>(x0, 1.0, z0), Vec<double, 3>::Zero()});
    }
    return out;
  }

  // The first integrals besides the energy, reported per point by the runner
  // and followed by the long-horizon study.
  static std::array<const char*, 2> first_integral_names() { return {"H_y", "R"}; }
  std::array<double, 2> first_integrals(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    const double Hy = 0.5 * (q[1] * q[1] + v[1] * v[1]);
    const double H = 0.5 * v.squaredNorm() + 0.5 * q.squaredNorm() + 0.5 * epsilon * q[0] * q[0] * q[2] * q[2];
    return {Hy, H - Hy};
  }
};

}  // namespace nhi
