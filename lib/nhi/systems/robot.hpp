// Scene: the mobile robot with fixed orientation and a potential (paper section 6.2).
//   Q = R^2 x S^1 x S^1, q = (x, y, theta, psi); the angles are real coordinates
//   (the identity chart on their lift, paper Remark 4.1).
//   L = 1/2 m (xd^2 + yd^2) + 1/2 I thetad^2 + 3/2 Iw psid^2 - V0 sin(psi)
//   constraints  xd - R cos(theta) psid = 0,   yd - R sin(theta) psid = 0
//   omega = [ 1 0 0 -R cos(theta) ]
//           [ 0 1 0 -R sin(theta) ]
// A Chaplygin system: G = (R^2, +) acts on (x, y); connection
// A = (dx - R cos(theta) dpsi) e1 + (dy - R sin(theta) dpsi) e2 (the paper prints
// "x - R cos theta dpsi" for the first term; dx is meant).
//
// Index-reduced ODE: thetadd = 0, (3 Iw + m R^2) psidd = -V0 cos(psi),
//   xdd = R (cos(theta) psidd - sin(theta) thetad psid),
//   ydd = R (sin(theta) psidd + cos(theta) thetad psid),
// with multipliers lambda = m (xdd, ydd).  This is also the exact reduced
// description: theta(t) = theta0 + thetad0 t, a one-degree-of-freedom pendulum-like
// equation for psi, and x, y by quadrature (see reduced_rhs()).
//
// The paper gives V0 = 10, h = 0.2 and no other values.  Defaults: m = I = R = 1,
// Iw = 1/3 (so the mass matrix is the identity), V0 = 10; q0 = (0, 0, 0, 0),
// v0 = (1, 0, 1, 1): the wheels turn (thetad0 = 1, so the constraint directions
// rotate) and psi librates in the well of -V0 sin(psi) around -pi/2 between
// about 0.10 and -3.24 (energy 1 against a barrier of 10), with small-amplitude
// angular frequency sqrt(V0 / (3 Iw + m R^2)) = 2.24.
#pragma once

#include <array>
#include <cmath>

#include "nhi/core.hpp"

namespace nhi {

struct Robot {
  static constexpr int n = 4;
  static constexpr int m = 2;
  static constexpr const char* name = "robot";

  double mass = 1.0;  // m
  double I = 1.0;
  double Iw = 1.0 / 3.0;
  double R = 1.0;
  double V0 = 10.0;

  template <class T>
  T lagrangian(const Vec<T, 4>& q, const Vec<T, 4>& v) const {
    using std::sin;
    return cst<T>(0.5 * mass) * (v[0] * v[0] + v[1] * v[1]) + cst<T>(0.5 * I) * v[2] * v[2] +
           cst<T>(1.5 * Iw) * v[3] * v[3] - cst<T>(V0) * sin(q[3]);
  }

  // Hand-written dL/dq, dL/dqdot (fast path; checked against autodiff of L).
  template <class T>
  void partials(const Vec<T, 4>& q, const Vec<T, 4>& v, Vec<T, 4>* dLdq, Vec<T, 4>* dLdv) const {
    using std::cos;
    *dLdq << cst<T>(0.0), cst<T>(0.0), cst<T>(0.0), -cst<T>(V0) * cos(q[3]);
    *dLdv << cst<T>(mass) * v[0], cst<T>(mass) * v[1], cst<T>(I) * v[2], cst<T>(3.0 * Iw) * v[3];
  }

  template <class T>
  Mat<T, 2, 4> omega(const Vec<T, 4>& q) const {
    using std::cos;
    using std::sin;
    Mat<T, 2, 4> w;
    w << cst<T>(1.0), cst<T>(0.0), cst<T>(0.0), -cst<T>(R) * cos(q[2]),  //
        cst<T>(0.0), cst<T>(1.0), cst<T>(0.0), -cst<T>(R) * sin(q[2]);
    return w;
  }

  Vec<double, 4> acceleration(const Vec<double, 4>& q, const Vec<double, 4>& v) const {
    const double c = std::cos(q[2]), s = std::sin(q[2]);
    const double psidd = -V0 * std::cos(q[3]) / (3.0 * Iw + mass * R * R);
    const double tp = v[2] * v[3];
    return {R * (c * psidd - s * tp), R * (s * psidd + c * tp), 0.0, psidd};
  }

  // The exact reduced description as a first-order ODE in y = (psi, psid, x, y),
  // with theta(t) = theta0 + thetad0 t given: an independent formulation of
  // the same motion, used as a second benchmark.
  std::array<double, 4> reduced_rhs(double theta, const std::array<double, 4>& y) const {
    const double psidd = -V0 * std::cos(y[0]) / (3.0 * Iw + mass * R * R);
    return {y[1], psidd, R * std::cos(theta) * y[1], R * std::sin(theta) * y[1]};
  }
};

}  // namespace nhi
