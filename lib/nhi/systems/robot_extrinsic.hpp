// The robot in the Constrained Coordinate Formulation (paper section 4, eq. 17):
// its two circles embedded in R^2 as unit vectors instead of angle charts.
//   V = R^6, v = (x, y, c1, s1, c2, s2), (c1, s1) = (cos theta, sin theta),
//   (c2, s2) = (cos psi, sin psi); Q is the submanifold g(v) = 0 with
//   g = ( (c1^2 + s1^2 - 1)/2, (c2^2 + s2^2 - 1)/2 )        (holonomic, l = 2)
//   L = 1/2 m (xd^2 + yd^2) + 1/2 I (c1d^2 + s1d^2) + 3/2 Iw (c2d^2 + s2d^2) - V0 s2
//   omega: xd - R c1 (c2 s2d - s2 c2d) = 0,  yd - R s1 (c2 s2d - s2 c2d) = 0
// On TQ (|u| = 1, u.ud = 0) these are the robot's L and omega (robot.hpp):
// c1d^2 + s1d^2 = thetad^2 and c2 s2d - s2 c2d = psid.  The embedding
// J(x, y, theta, psi) = (x, y, cos theta, sin theta, cos psi, sin psi) is not
// linear in the angle chart, so Theorem 4.3 does not apply: the extrinsic DLA is
// a different integrator from the intrinsic one (robot.hpp), and we compare them.
#pragma once

#include <cmath>

#include "nhi/systems/robot.hpp"

namespace nhi {

struct RobotExtrinsic {
  static constexpr int n = 6;
  static constexpr int m = 2;
  static constexpr int l = 2;
  static constexpr const char* name = "robot (unit vectors)";

  Robot r;  // the physical parameters

  template <class T>
  T lagrangian(const Vec<T, 6>& q, const Vec<T, 6>& v) const {
    return cst<T>(0.5 * r.mass) * (v[0] * v[0] + v[1] * v[1]) + cst<T>(0.5 * r.I) * (v[2] * v[2] + v[3] * v[3]) +
           cst<T>(1.5 * r.Iw) * (v[4] * v[4] + v[5] * v[5]) - cst<T>(r.V0) * q[5];
  }

  template <class T>
  void partials(const Vec<T, 6>& q, const Vec<T, 6>& v, Vec<T, 6>* dLdq, Vec<T, 6>* dLdv) const {
    *dLdq << cst<T>(0.0), cst<T>(0.0), cst<T>(0.0), cst<T>(0.0), cst<T>(0.0), -cst<T>(r.V0);
    *dLdv << cst<T>(r.mass) * v[0], cst<T>(r.mass) * v[1], cst<T>(r.I) * v[2], cst<T>(r.I) * v[3],
        cst<T>(3.0 * r.Iw) * v[4], cst<T>(3.0 * r.Iw) * v[5];
  }

  template <class T>
  Mat<T, 2, 6> omega(const Vec<T, 6>& q) const {
    Mat<T, 2, 6> w;
    const T R = cst<T>(r.R);
    w << cst<T>(1.0), cst<T>(0.0), cst<T>(0.0), cst<T>(0.0), R * q[2] * q[5], -R * q[2] * q[4],  //
        cst<T>(0.0), cst<T>(1.0), cst<T>(0.0), cst<T>(0.0), R * q[3] * q[5], -R * q[3] * q[4];
    return w;
  }

  template <class T>
  Vec<T, 2> g(const Vec<T, 6>& q) const {
    return Vec<T, 2>(cst<T>(0.5) * (q[2] * q[2] + q[3] * q[3] - cst<T>(1.0)),
                     cst<T>(0.5) * (q[4] * q[4] + q[5] * q[5] - cst<T>(1.0)));
  }

  // The embedding J and its tangent map: (q, qdot) of the robot -> (v, vdot).
  static Vec<double, 6> embed(const Vec<double, 4>& q) {
    Vec<double, 6> v;
    v << q[0], q[1], std::cos(q[2]), std::sin(q[2]), std::cos(q[3]), std::sin(q[3]);
    return v;
  }
  static Vec<double, 6> embed_velocity(const Vec<double, 4>& q, const Vec<double, 4>& qd) {
    Vec<double, 6> vd;
    vd << qd[0], qd[1], -std::sin(q[2]) * qd[2], std::cos(q[2]) * qd[2], -std::sin(q[3]) * qd[3],
        std::cos(q[3]) * qd[3];
    return vd;
  }
  // The chart's tangent map at v applied to vd: (xd, yd, u1 x u1d, u2 x u2d).
  static Vec<double, 4> chart_velocity(const Vec<double, 6>& v, const Vec<double, 6>& vd) {
    return Vec<double, 4>(vd[0], vd[1], v[2] * vd[3] - v[3] * vd[2], v[4] * vd[5] - v[5] * vd[4]);
  }
  // Back to the angle chart; `near` picks the branch of each angle (continuity).
  static Vec<double, 4> chart(const Vec<double, 6>& v, const Vec<double, 4>& near) {
    auto lift = [](double a, double ref) { return a + 2 * M_PI * std::round((ref - a) / (2 * M_PI)); };
    return Vec<double, 4>(v[0], v[1], lift(std::atan2(v[3], v[2]), near[2]), lift(std::atan2(v[5], v[4]), near[3]));
  }
};

}  // namespace nhi
