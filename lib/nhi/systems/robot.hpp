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
// equation for psi, and x, y by quadrature (see reduced_flow()).
//
// The paper gives V0 = 10, h = 0.2 and no other values.  Defaults: m = I = R = 1,
// Iw = 1/3 (so the mass matrix is the identity), V0 = 10; q0 = (0, 0, 0, 0),
// v0 = (1, 0, 1, 1): the wheels turn (thetad0 = 1, so the constraint directions
// rotate) and psi librates in the well of -V0 sin(psi) around -pi/2 between
// about 0.10 and -3.24 (energy 1 against a barrier of 10), with small-amplitude
// angular frequency sqrt(V0 / (3 Iw + m R^2)) = 2.24.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>

#include "nhi/roles/system.hpp"

namespace nhi {

struct Robot {
  static constexpr int n = 4;
  static constexpr int m = 2;
  static constexpr const char* name = "robot";
  // Chaplygin split (reduced.hpp): shape r = (theta, psi), group s = (x, y).
  static constexpr std::array<int, 2> shape{2, 3};
  static constexpr std::array<int, 2> group{0, 1};

  // L and omega are invariant under (q, v) -> (q, -v): the standard reversing symmetry.
  static constexpr bool reversible = true;
  // Integrable: thetad is constant, psi a pendulum, x and y quadratures (reduced_flow).
  static constexpr bool integrable = true;
  static constexpr const char* paper_section = "6.2";
  // L = 1/2 v^T M v - U(q) with M constant (hamiltonian.hpp).
  static constexpr bool separable = true;

  double mass = 1.0;  // m
  double I = 1.0;
  double Iw = 1.0 / 3.0;
  double R = 1.0;
  double V0 = 10.0;

  // The scene's `params` (defaults: the members' initial values).
  static auto parameters() {
    using P = Param<Robot>;
    return std::array{P{"m", &Robot::mass, ParamCheck::kPositive}, P{"I", &Robot::I, ParamCheck::kPositive},
                      P{"Iw", &Robot::Iw, ParamCheck::kPositive}, P{"R", &Robot::R, ParamCheck::kPositive},
                      P{"V0", &Robot::V0}};
  }
  // Default initial state (experiments/scenes/robot.json has the same numbers).
  static Vec<double, 4> default_q0() { return {0.0, 0.0, 0.0, 0.0}; }
  static Vec<double, 4> default_v0() { return {1.0, 0.0, 1.0, 1.0}; }

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

  // The inverse Legendre map V(q, p) = M^-1 p (fast path; checked against the generic one).
  template <class T>
  Vec<T, 4> velocity(const Vec<T, 4>&, const Vec<T, 4>& p) const {
    Vec<T, 4> v;
    v << p[0] / cst<T>(mass), p[1] / cst<T>(mass), p[2] / cst<T>(I), p[3] / cst<T>(3.0 * Iw);
    return v;
  }

  template <class T>
  Mat<T, 2, 4> omega(const Vec<T, 4>& q) const {
    using std::cos;
    using std::sin;
    // cos and sin of theta before any store into w, so that GCC makes them one
    // sincos call (glibc's sincos gives the same bits as sin, cos).
    const T c = cos(q[2]), s = sin(q[2]);
    Mat<T, 2, 4> w;
    w << cst<T>(1.0), cst<T>(0.0), cst<T>(0.0), -cst<T>(R) * c,  //
        cst<T>(0.0), cst<T>(1.0), cst<T>(0.0), -cst<T>(R) * s;
    return w;
  }

  // Theorem 5.3 (eq. 24) with SE(2) acting on (x, y, theta): the section with
  // generator d/dtheta is xi(q) = (1, (y, -x)) (rotation about (x, y)), so
  // J_k = p_theta, and xi(q_{k+1}) - xi(q_k) is the translation (dy, -dx):
  // p_{theta,k+1} - p_{theta,k} = p_{x,k+1} (y_{k+1} - y_k) - p_{y,k+1} (x_{k+1} - x_k).
  static double nonholonomic_momentum(const Vec<double, 4>&, const Vec<double, 4>& p) { return p[2]; }
  static double momentum_equation_rhs(const Vec<double, 4>& q0, const Vec<double, 4>& q1, const Vec<double, 4>& p1) {
    return p1[0] * (q1[1] - q0[1]) - p1[1] * (q1[0] - q0[0]);
  }

  Vec<double, 4> acceleration(const Vec<double, 4>& q, const Vec<double, 4>& v) const {
    const double c = std::cos(q[2]), s = std::sin(q[2]);
    const double psidd = -V0 * std::cos(q[3]) / (3.0 * Iw + mass * R * R);
    const double tp = v[2] * v[3];
    return {R * (c * psidd - s * tp), R * (s * psidd + c * tp), 0.0, psidd};
  }

  // The exact reduced description, integrated on its own: theta(t) = theta0 +
  // thetad0 t exactly; (psi, psid, x, y) by classical RK4 with `substeps`
  // steps per unit time on  psidd = -V0 cos(psi) / (3 Iw + m R^2),
  // xd = R cos(theta(t)) psid,  yd = R sin(theta(t)) psid.  A formulation that
  // shares no code with the index-reduced ODE, used as a second benchmark.
  void reduced_flow(const Vec<double, 4>& q0, const Vec<double, 4>& v0, double t, long substeps_per_unit,
                    Vec<double, 4>* q, Vec<double, 4>* v) const {
    const double k = V0 / (3.0 * Iw + mass * R * R);
    auto rhs = [&](double tt, const Eigen::Vector4d& y) {
      const double th = q0[2] + v0[2] * tt;
      return Eigen::Vector4d(y[1], -k * std::cos(y[0]), R * std::cos(th) * y[1], R * std::sin(th) * y[1]);
    };
    Eigen::Vector4d y(q0[3], v0[3], q0[0], q0[1]);
    const long steps = std::max(1L, static_cast<long>(std::ceil(std::abs(t) * substeps_per_unit)));
    const double dt = t / steps;
    for (long i = 0; i < steps; ++i) {
      const double tt = i * dt;
      const Eigen::Vector4d k1 = rhs(tt, y), k2 = rhs(tt + dt / 2, y + dt / 2 * k1),
                            k3 = rhs(tt + dt / 2, y + dt / 2 * k2), k4 = rhs(tt + dt, y + dt * k3);
      y += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    const double th = q0[2] + v0[2] * t;
    *q << y[2], y[3], th, y[0];
    *v << R * std::cos(th) * y[1], R * std::sin(th) * y[1], v0[2], y[1];
  }
};

}  // namespace nhi
