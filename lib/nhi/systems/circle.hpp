// Scene for Remark 3.3 (an integrable distribution): a particle on the unit
// circle in the plane under gravity, L = 1/2 |v|^2 - g y, written two ways.
//  - CircleParticle: as a "nonholonomic" system with omega = q^T (D = ker dG,
//    G = |q|^2 / 2).  The midpoint discrete constraint is
//    omega(q_mid) (q1 - q0)/h = (|q1|^2 - |q0|^2)/(2h), and omega(q_k)^T lambda =
//    lambda DG(q_k): the midpoint DLA is the SHAKE-type variational integrator
//    D1 L_d + D2 L_d = lambda DG(q_k), G(q_{k+1}) = G(q_k).
//  - CircleHolonomic: the Constrained Coordinate Formulation (eq. 17) with no
//    omega and one holonomic constraint g = (|q|^2 - 1)/2.
#pragma once

#include "nhi/roles/system.hpp"

namespace nhi {

struct CircleParticle {
  static constexpr int n = 2, m = 1;
  static constexpr const char* name = "particle on a circle";
  double gravity = 1.0;
  template <class T>
  T lagrangian(const Vec<T, 2>& q, const Vec<T, 2>& v) const {
    return cst<T>(0.5) * (v[0] * v[0] + v[1] * v[1]) - cst<T>(gravity) * q[1];
  }
  template <class T>
  Mat<T, 1, 2> omega(const Vec<T, 2>& q) const {
    Mat<T, 1, 2> w;
    w << q[0], q[1];
    return w;
  }
  Vec<double, 2> acceleration(const Vec<double, 2>& q, const Vec<double, 2>& v) const {
    return generic_acceleration(*this, q, v);
  }
};

struct CircleHolonomic {
  static constexpr int n = 2, m = 0, l = 1;
  static constexpr const char* name = "particle on a circle (g)";
  CircleParticle c;
  template <class T>
  T lagrangian(const Vec<T, 2>& q, const Vec<T, 2>& v) const {
    return c.lagrangian<T>(q, v);
  }
  template <class T>
  Mat<T, 0, 2> omega(const Vec<T, 2>&) const {
    return Mat<T, 0, 2>();
  }
  template <class T>
  Vec<T, 1> g(const Vec<T, 2>& q) const {
    return Vec<T, 1>(cst<T>(0.5) * (q[0] * q[0] + q[1] * q[1] - cst<T>(1.0)));
  }
};

}  // namespace nhi
