// Scene: the vertical rolling disk (Bloch, "Nonholonomic Mechanics and Control",
// sec. 1.4; the VerticalRollingDisk test problem of odelab, Verdier & Modin's Python
// code, odelab/system/nonholonomic/rolling.py).
//   Q = R^2 x S^1 x S^1, q = (x, y, theta, phi): (x, y) the contact point, theta the
//   rolling angle (about the disk's axis), phi the heading (the angle between the
//   disk's plane and the x axis); the angles are real coordinates (the identity
//   chart on their lift, paper Remark 4.1).
//   L = 1/2 m (xd^2 + yd^2) + 1/2 I thetad^2 + 1/2 J phid^2            (Bloch 1.4; no potential)
//   constraints  xd - R cos(phi) thetad = 0,   yd - R sin(phi) thetad = 0   (rolling without slipping)
//   omega = [ 1 0 -R cos(phi) 0 ]
//           [ 0 1 -R sin(phi) 0 ]
// I is the moment of inertia about the disk's axis (odelab's Irot), J about a
// vertical diameter (odelab's Iflip).  odelab orders q as (x, y, phi, theta); here
// theta comes first.  It is the robot of robot.hpp with V0 = 0 and its two angles
// in the other order (there theta is the heading and psi the rolling angle).
//
// Index-reduced ODE (eq. 3 with M = diag(m, m, I, J), no force, and eq. 4
// differentiated once):
//   m xdd = lambda_1,  m ydd = lambda_2,  J phidd = 0,
//   I thetadd = -R (cos(phi) lambda_1 + sin(phi) lambda_2),
//   xdd = R (cos(phi) thetadd - sin(phi) thetad phid),  ydd = R (sin(phi) thetadd + cos(phi) thetad phid).
// The last three give (I + m R^2) thetadd = 0, so
//   a = (-R sin(phi) thetad phid, R cos(phi) thetad phid, 0, 0),   lambda = m (xdd, ydd):
// the constraint force is the centripetal force that bends the contact point's path.
//
// Exact solution (exact_solution() below): thetad = Omega and phid = w are constant,
//   theta = theta0 + Omega t,   phi = phi0 + w t,
//   (x, y) = (x0, y0) + c t + R Omega s(t) (cos(phi0 + w t/2), sin(phi0 + w t/2)),
//   s(t) = 2 sin(w t/2) / w   (s = t for w = 0: a straight line),
//   (xd, yd) = c + R Omega (cos(phi), sin(phi)),
// with c = omega(q0) v0, zero on the constraint (the index-reduced ODE keeps
// omega(q) v constant, so the formula is its solution from any (q0, v0)).  For
// w != 0 the contact point runs at speed R |Omega| round a circle of radius
// R |Omega / w| (odelab's `exact`: x0 + rho (sin(phi) - sin(phi0)), rho = R Omega / w);
// the chord form above has no cancellation as w -> 0.  Besides the energy
// E = 1/2 (m R^2 + I) Omega^2 + 1/2 J w^2 (on the constraint), thetad and phid are
// first integrals: the motion is integrable, and reversible (L is even in v and
// omega does not depend on v).
//
// Default run (experiments/scenes/rolling_disk.json): odelab's parameters and its
// test state, m = R = I = J = 1, q0 = (0, 0, 0, 0), v0 = (1, 0, 1, 2) (Omega = 1,
// w = 2: odelab's ohm_theta, ohm_phi; xd0 = R cos(phi0) Omega, yd0 = R sin(phi0) Omega),
// h = 0.1 as in odelab's tests, 200 steps (T = 20).  The disk rolls at unit speed
// while it turns, so the constraint directions rotate: the contact point circles
// (0, 1/2) with radius 1/2 and period pi (about 6.4 turns), E = 3.
#pragma once

#include <array>
#include <cmath>

#include "nhi/roles/system.hpp"

namespace nhi {

struct RollingDisk {
  static constexpr int n = 4;
  static constexpr int m = 2;
  static constexpr const char* name = "rolling_disk";

  // L and omega are invariant under (q, v) -> (q, -v): the standard reversing symmetry.
  static constexpr bool reversible = true;
  // Integrable: thetad and phid are constant, x and y follow in closed form.
  static constexpr bool integrable = true;
  // L = 1/2 v^T M v with M constant (hamiltonian.hpp).
  static constexpr bool separable = true;
  // The angles move linearly and x, y are integrals of known functions of t, so
  // a Runge-Kutta method integrates the index-reduced ODE as a quadrature rule
  // (RK4: Simpson's rule), which is symmetric and rho-reversible: the tests that
  // require a non-symmetric method to be measurably so skip this scene.
  static constexpr bool quadrature_flow = true;

  double mass = 1.0;  // m
  double R = 1.0;
  double I = 1.0;  // about the disk's axis
  double J = 1.0;  // about a vertical diameter

  // The scene's `params` (defaults: the members' initial values).
  static auto parameters() {
    using P = Param<RollingDisk>;
    return std::array{P{"m", &RollingDisk::mass, ParamCheck::kPositive}, P{"R", &RollingDisk::R, ParamCheck::kPositive},
                      P{"I", &RollingDisk::I, ParamCheck::kPositive}, P{"J", &RollingDisk::J, ParamCheck::kPositive}};
  }
  // Default initial state (experiments/scenes/rolling_disk.json has the same numbers).
  static Vec<double, 4> default_q0() { return {0.0, 0.0, 0.0, 0.0}; }
  static Vec<double, 4> default_v0() { return {1.0, 0.0, 1.0, 2.0}; }

  template <class T>
  T lagrangian(const Vec<T, 4>&, const Vec<T, 4>& v) const {
    return cst<T>(0.5 * mass) * (v[0] * v[0] + v[1] * v[1]) + cst<T>(0.5 * I) * v[2] * v[2] +
           cst<T>(0.5 * J) * v[3] * v[3];
  }

  // Hand-written dL/dq, dL/dqdot (fast path; checked against autodiff of L).
  template <class T>
  void partials(const Vec<T, 4>&, const Vec<T, 4>& v, Vec<T, 4>* dLdq, Vec<T, 4>* dLdv) const {
    *dLdq << cst<T>(0.0), cst<T>(0.0), cst<T>(0.0), cst<T>(0.0);
    *dLdv << cst<T>(mass) * v[0], cst<T>(mass) * v[1], cst<T>(I) * v[2], cst<T>(J) * v[3];
  }

  // The inverse Legendre map V(q, p) = M^-1 p (fast path; checked against the generic one).
  template <class T>
  Vec<T, 4> velocity(const Vec<T, 4>&, const Vec<T, 4>& p) const {
    Vec<T, 4> v;
    v << p[0] / cst<T>(mass), p[1] / cst<T>(mass), p[2] / cst<T>(I), p[3] / cst<T>(J);
    return v;
  }

  template <class T>
  Mat<T, 2, 4> omega(const Vec<T, 4>& q) const {
    using std::cos;
    using std::sin;
    const T c = cos(q[3]), s = sin(q[3]);  // one sincos call (robot.hpp)
    Mat<T, 2, 4> w;
    w << cst<T>(1.0), cst<T>(0.0), -cst<T>(R) * c, cst<T>(0.0),  //
        cst<T>(0.0), cst<T>(1.0), -cst<T>(R) * s, cst<T>(0.0);
    return w;
  }

  Vec<double, 4> acceleration(const Vec<double, 4>& q, const Vec<double, 4>& v) const {
    const double c = std::cos(q[3]), s = std::sin(q[3]);
    const double k = R * v[2] * v[3];
    return {-s * k, c * k, 0.0, 0.0};
  }

  // Conserved besides the energy: the rolling and turning rates.
  static std::array<const char*, 2> first_integral_names() { return {"thetad", "phid"}; }
  std::array<double, 2> first_integrals(const Vec<double, 4>&, const Vec<double, 4>& v) const { return {v[2], v[3]}; }

  // The exact solution at time t from (q0, v0) (see the top of this file); always true.
  bool exact_solution(const Vec<double, 4>& q0, const Vec<double, 4>& v0, double t, Vec<double, 4>* q,
                      Vec<double, 4>* v) const {
    const double Om = v0[2], w = v0[3], phi0 = q0[3];
    const Vec<double, 2> c = omega<double>(q0) * v0;  // zero on the constraint
    const double half = 0.5 * w * t;
    const double s = half == 0.0 ? t : 2.0 * std::sin(half) / w;  // the chord's length / (R Omega)
    const double mid = phi0 + half, phi = phi0 + w * t;
    *q << q0[0] + c[0] * t + R * Om * s * std::cos(mid), q0[1] + c[1] * t + R * Om * s * std::sin(mid), q0[2] + Om * t,
        phi;
    *v << c[0] + R * Om * std::cos(phi), c[1] + R * Om * std::sin(phi), Om, w;
    return true;
  }
};

}  // namespace nhi
