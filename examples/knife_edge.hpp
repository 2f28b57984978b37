// A user's system, not in the library's registry: a knife edge (a skate)
// sliding without friction on a plane inclined at angle alpha, which cannot
// move sideways (Neimark & Fufaev; Bloch, Nonholonomic Mechanics and Control,
// section 1.6).  q = (x, y, phi): x down the slope, y across it, phi the
// blade's heading from the x axis.
//   L = 1/2 mass (xd^2 + yd^2) + 1/2 inertia phid^2 + mass g sin(alpha) x
//   constraint  -sin(phi) xd + cos(phi) yd = 0     (no velocity across the blade)
// Closed form: phid = w is constant, phi = phi0 + w t, and the speed u along
// the blade obeys u' = g sin(alpha) cos(phi), so with phi0 = 0 and c = g
// sin(alpha) / w:  u = u0 + c sin(w t),
//   x = x0 + (u0 / w) sin(w t) + (c / 2w) sin^2(w t),
//   y = y0 + (u0 / w)(1 - cos(w t)) + (c / 2)(t - sin(2 w t) / (2 w)):
// the skate does not slide down on average; it drifts across the slope.
#pragma once

#include <cmath>

#include "nhi/roles/system.hpp"

struct KnifeEdge {
  // What every method needs (nhi/roles/system.hpp: the system concept).
  static constexpr int n = 3, m = 1;
  double mass = 1.0, inertia = 0.2, g = 9.81, incline = 0.3;  // incline: the plane's angle alpha

  template <class T>
  T lagrangian(const nhi::Vec<T, 3>& q, const nhi::Vec<T, 3>& v) const {
    using nhi::cst;
    return cst<T>(0.5 * mass) * (v[0] * v[0] + v[1] * v[1]) + cst<T>(0.5 * inertia) * v[2] * v[2] +
           cst<T>(mass * g * std::sin(incline)) * q[0];
  }
  template <class T>
  nhi::Mat<T, 1, 3> omega(const nhi::Vec<T, 3>& q) const {
    using std::cos, std::sin;
    nhi::Mat<T, 1, 3> w;
    w << -sin(q[2]), cos(q[2]), nhi::cst<T>(0.0);
    return w;
  }

  // RK4 (and the reference solution) integrate the index-reduced ODE; here
  // derived from L and omega by automatic differentiation.
  nhi::Vec<double, 3> acceleration(const nhi::Vec<double, 3>& q, const nhi::Vec<double, 3>& v) const {
    return nhi::generic_acceleration(*this, q, v);
  }

  // Optional fast paths.  L = 1/2 v^T M v - U(q) with M constant: mp06 then
  // solves for the multiplier alone (nhi/roles/hamiltonian.hpp).
  static constexpr bool separable = true;
  // dL/dq and dL/dqdot by hand: without them the DLA's Jacobian needs a Jet of Jets.
  template <class T>
  void partials(const nhi::Vec<T, 3>&, const nhi::Vec<T, 3>& v, nhi::Vec<T, 3>* dLdq, nhi::Vec<T, 3>* dLdv) const {
    using nhi::cst;
    *dLdq << cst<T>(mass * g * std::sin(incline)), cst<T>(0.0), cst<T>(0.0);
    *dLdv << cst<T>(mass) * v[0], cst<T>(mass) * v[1], cst<T>(inertia) * v[2];
  }

  // The closed form above (phi0 = 0): the state at time t.
  void exact(const nhi::Vec<double, 3>& q0, const nhi::Vec<double, 3>& v0, double t, nhi::Vec<double, 3>* q,
             nhi::Vec<double, 3>* v) const {
    const double w = v0[2], u0 = v0[0], c = g * std::sin(incline) / w, s = std::sin(w * t), co = std::cos(w * t);
    const double u = u0 + c * s;
    *q << q0[0] + (u0 / w) * s + (c / (2 * w)) * s * s,
        q0[1] + (u0 / w) * (1 - co) + (c / 2) * (t - std::sin(2 * w * t) / (2 * w)), q0[2] + w * t;
    *v << u * co, u * s, w;
  }
};
