// Scene: the Chaplygin sphere, a ball of radius r and mass m whose centre of
// mass is its geometric centre, with unequal principal moments I1, I2, I3 about
// it, rolling without slipping on a horizontal plane (Chaplygin 1903; Borisov &
// Mamaev, Regul. Chaotic Dyn. 7, 2002, 177-200).
// On the unit-quaternion embedding (quaternion.hpp), as suslov.hpp:
//   Q = R^2 x R^4, q = (x, y, p), (x, y) the centre (at height r), p = (w, x, y, z),
//   Omega = 2 G(p) pdot (body frame), omega = 2 E(p) pdot (space frame), sigma = p . pdot,
//   L = 1/2 m (xd^2 + yd^2) + 1/2 Omega^T I Omega + (c/2) sigma^2,   c = 4 (I1 + I2 + I3) / 3,
//   constraints  sigma = 0,  xd - r omega_y = 0,  yd + r omega_x = 0
//   (the contact point's velocity, centre velocity + omega x (-r e_z), is zero):
//   omega = [ 0 0  p^T              ]
//           [ 1 0 -2 r e_y^T E(p)   ]
//           [ 0 1  2 r e_x^T E(p)   ].
// The radial term is the Suslov problem's (suslov.hpp): it vanishes with its
// partials on sigma = 0 and keeps L regular.  No potential: the centre's height
// is constant and the normal force passes through it.
//
// Index-reduced ODE (at any (q, v), s = |p|; R(p) = E(p) G(p)^T the rotation as
// a quadratic form, gamma = R(p)^T e_z, |gamma| = s^2; quaternion.hpp):
// m xdd = lambda_1, m ydd = lambda_2, and G(p) applied to the quaternion block of
// eq. 3 gives s^2 I Omegadot = Pi x Omega - 2 sigma Pi + r R(p)^T (lambda_2 e_x -
// lambda_1 e_y).  The rows differentiated: omegadot = 2 E(p) pddot = R(p) Omegadot / s^2
// (E(pdot) pdot = 0, E(p) p = 0), so (xdd, ydd) = r (u_y, -u_x), u = R(p) Omegadot / s^2,
// and with R^T diag(1, 1, 0) R = s^4 1 - gamma gamma^T,
//   [s^2 I + m r^2 (s^2 1 - gamma gamma^T / s^2)] Omegadot = Pi x Omega - 2 sigma Pi,
//   pddot = (-|pdot|^2 p + G(p)^T Omegadot / 2) / s^2.
// On |p| = 1: (I + m r^2 (1 - gamma gamma^T)) Omegadot = I Omega x Omega, Newton and
// Euler's equations with the contact force m r (R Omegadot) x e_z + m g e_z
// (tests/test_rigid.cpp derives it so and compares with generic_acceleration()).
//
// First integrals (first_integrals() below): besides the energy, with
// M = I Omega + m r^2 (Omega - <Omega, gamma> gamma) the angular momentum about the
// contact point (body frame), Mdot = M x Omega and gammadot = gamma x Omega, so
// |M|^2, <M, gamma> and |gamma|^2 are constant.  gamma is R(p)^T e_z with the
// quadratic R(p), so that |gamma|^2 = |p|^4 shows a method's drift off |p| = 1;
// M is the physical one on |p| = 1.  Integrable (Chaplygin: the reduced flow has
// an invariant measure and these integrals) and reversible (L even in v).
//
// Default run (experiments/scenes/chaplygin_sphere.json): m = r = 1, I = (0.2, 0.4, 0.5)
// (a ball of unevenly distributed mass: I_i < I_j + I_k, sum < 2 m r^2),
// p0 = (0.9, 0.3, 0.3, 0.1) (|p0| = 1, gamma0 = (-0.48, 0.6, 0.64): no axis vertical),
// Omega0 = (0.5, 0.25, 1), so pdot0 = p0 (0, Omega0) / 2 = (-0.1625, 0.3625, -0.0125, 0.4125),
// omega0 = R Omega0 = (1, -0.1, 0.55) and (xd0, yd0) = r (omega_y, -omega_x) = (-0.1, -1);
// E = 0.7925, h = 0.01, 2000 steps (T = 20).
#pragma once

#include <array>
#include <cmath>

#include <Eigen/LU>

#include "nhi/roles/system.hpp"
#include "nhi/groups/quaternion.hpp"

namespace nhi {

struct ChaplyginSphere {
  static constexpr int n = 6;
  static constexpr int m = 3;
  static constexpr const char* name = "chaplygin_sphere";
  // L and omega are invariant under (q, v) -> (q, -v).
  static constexpr bool reversible = true;
  // Chaplygin's integrable case of the rolling ball (see above).
  static constexpr bool integrable = true;
  // The orientation is q[2..5] (a unit quaternion) and row 0 of omega is
  // p . pdot = 0 (methods/group/ step on the group instead).
  static constexpr int orientation = 2;
  static constexpr int norm_row = 0;
  // L and omega read q only through xdot, 2 G(p) pdot, 2 E(p) pdot and p . pdot
  // (no potential): the DLA's alpha rules are all of order 2 here (system.hpp).
  static constexpr bool bilinear_kinematics = true;

  double mass = 1.0;  // m
  double r = 1.0;     // radius
  double I1 = 0.2, I2 = 0.4, I3 = 0.5;

  static auto parameters() {
    using P = Param<ChaplyginSphere>;
    return std::array{
        P{"m", &ChaplyginSphere::mass, ParamCheck::kPositive}, P{"r", &ChaplyginSphere::r, ParamCheck::kPositive},
        P{"I1", &ChaplyginSphere::I1, ParamCheck::kPositive}, P{"I2", &ChaplyginSphere::I2, ParamCheck::kPositive},
        P{"I3", &ChaplyginSphere::I3, ParamCheck::kPositive}};
  }
  // Default initial state (experiments/scenes/chaplygin_sphere.json has the same numbers).
  static Vec<double, 6> default_q0() { return {0.0, 0.0, 0.9, 0.3, 0.3, 0.1}; }
  static Vec<double, 6> default_v0() { return {-0.1, -1.0, -0.1625, 0.3625, -0.0125, 0.4125}; }

  // The radial term's coefficient c: the mean of the 4 I_i (suslov.hpp).
  double radial() const { return 4.0 * (I1 + I2 + I3) / 3.0; }

  template <class T>
  static Vec<T, 4> quat(const Vec<T, 6>& q) {
    return Vec<T, 4>(q[2], q[3], q[4], q[5]);
  }

  template <class T>
  T lagrangian(const Vec<T, 6>& q, const Vec<T, 6>& v) const {
    const double k[3] = {2.0 * I1, 2.0 * I2, 2.0 * I3};
    return quaternion::kinetic<T>(quat(q), quat(v), k, 0.5 * radial()) +
           cst<T>(0.5 * mass) * (v[0] * v[0] + v[1] * v[1]);
  }

  // Hand-written dL/dq, dL/dqdot (the DLA's fast path; autodiff's numbers bit for
  // bit: the translational part's derivatives m xd, m yd are exact either way).
  template <class T>
  void partials(const Vec<T, 6>& q, const Vec<T, 6>& v, Vec<T, 6>* dLdq, Vec<T, 6>* dLdv) const {
    const double k[3] = {2.0 * I1, 2.0 * I2, 2.0 * I3};
    Vec<T, 4> dp, du;
    quaternion::kinetic_partials<T>(quat(q), quat(v), k, 0.5 * radial(), &dp, &du);
    *dLdq << cst<T>(0.0), cst<T>(0.0), dp[0], dp[1], dp[2], dp[3];
    *dLdv << cst<T>(mass) * v[0], cst<T>(mass) * v[1], du[0], du[1], du[2], du[3];
  }

  // The inverse Legendre map (fast path; suslov.hpp for the quaternion block).
  template <class T>
  Vec<T, 6> velocity(const Vec<T, 6>& q, const Vec<T, 6>& P) const {
    const Vec<T, 4> p = quat(q), Pp = quat(P);
    const T s2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3];
    const Vec<T, 3> g = quaternion::G(p, Pp);
    Vec<T, 3> half_omega;
    half_omega << g[0] / (cst<T>(4.0 * I1) * s2), g[1] / (cst<T>(4.0 * I2) * s2), g[2] / (cst<T>(4.0 * I3) * s2);
    const T sigma = (p[0] * Pp[0] + p[1] * Pp[1] + p[2] * Pp[2] + p[3] * Pp[3]) / (cst<T>(radial()) * s2);
    const Vec<T, 4> gt = quaternion::Gt(p, half_omega);
    Vec<T, 6> v;
    v[0] = P[0] / cst<T>(mass);
    v[1] = P[1] / cst<T>(mass);
    for (int i = 0; i < 4; ++i) v[2 + i] = (sigma * p[i] + gt[i]) / s2;
    return v;
  }

  template <class T>
  Mat<T, 3, 6> omega(const Vec<T, 6>& q) const {
    const T zero = cst<T>(0.0), one = cst<T>(1.0), tr = cst<T>(2.0 * r);
    const T &w = q[2], &x = q[3], &y = q[4], &z = q[5];
    Mat<T, 3, 6> W;
    // rows of E(p): e_x^T E = (-x, w, -z, y), e_y^T E = (-y, z, w, -x)
    W << zero, zero, w, x, y, z,                          //
        one, zero, tr * y, -(tr * z), -(tr * w), tr * x,  // xd - 2 r e_y^T E(p) pdot
        zero, one, -(tr * x), tr * w, -(tr * z), tr * y;  // yd + 2 r e_x^T E(p) pdot
    return W;
  }

  Vec<double, 6> acceleration(const Vec<double, 6>& q, const Vec<double, 6>& v) const {
    const Vec<double, 4> p = quat(q), pd = quat(v);
    const Vec<double, 3> I(I1, I2, I3);
    const double s2 = p.squaredNorm(), sigma = p.dot(pd), mr2 = mass * r * r;
    const Vec<double, 3> Om = 2.0 * quaternion::G<double>(p, pd), Pi = I.cwiseProduct(Om);
    const Vec<double, 3> gamma = quaternion::vertical<double>(p);
    const Vec<double, 3> diag = s2 * I + Vec<double, 3>::Constant(mr2 * s2);
    Mat<double, 3, 3> K = diag.asDiagonal();
    K -= (mr2 / s2) * gamma * gamma.transpose();  // s^2 I + m r^2 (s^2 1 - gamma gamma^T / s^2)
    const Vec<double, 3> Omdot = K.partialPivLu().solve(Vec<double, 3>(Pi.cross(Om) - 2.0 * sigma * Pi));
    const Vec<double, 3> u = quaternion::rotate(p, Omdot) / s2;  // omegadot
    const Vec<double, 4> pdd = (-pd.squaredNorm() * p + quaternion::Gt<double>(p, Vec<double, 3>(0.5 * Omdot))) / s2;
    Vec<double, 6> a;
    a << r * u[1], -r * u[0], pdd;
    return a;
  }

  // M = I Omega + m r^2 (Omega - <Omega, gamma> gamma), the angular momentum about the contact point.
  Vec<double, 3> contact_momentum(const Vec<double, 6>& q, const Vec<double, 6>& v) const {
    const Vec<double, 3> Om = 2.0 * quaternion::G<double>(quat(q), quat(v)),
                         gamma = quaternion::vertical<double>(quat(q));
    return Vec<double, 3>(I1, I2, I3).cwiseProduct(Om) + mass * r * r * (Om - Om.dot(gamma) * gamma);
  }

  // Conserved besides the energy (see the top of this file).
  static std::array<const char*, 3> first_integral_names() { return {"M2", "M_gamma", "gamma2"}; }
  std::array<double, 3> first_integrals(const Vec<double, 6>& q, const Vec<double, 6>& v) const {
    const Vec<double, 3> M = contact_momentum(q, v), gamma = quaternion::vertical<double>(quat(q));
    return {M.squaredNorm(), M.dot(gamma), gamma.squaredNorm()};
  }
};

}  // namespace nhi
