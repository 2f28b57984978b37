// Scene: the Suslov problem, a rigid body with one body-fixed component of its
// angular velocity held at zero (Suslov 1902; Bloch, "Nonholonomic Mechanics and
// Control"; Fedorov & Zenkov, Nonlinearity 18, 2005).
//   Body inertia I = diag(I1, I2, I3), body angular velocity Omega, and the
//   constraint <a, Omega> = 0 for a body-fixed vector a = (a1, a2, a3) (only its
//   direction matters: a need not be a unit vector, but must not be zero).
// On the unit-quaternion embedding (quaternion.hpp), so that every method runs it
// as it runs any other scene:
//   Q = R^4, q = p = (w, x, y, z), Omega = 2 G(p) pdot, sigma = p . pdot,
//   L = 1/2 Omega^T I Omega + (c/2) sigma^2,   c = 4 (I1 + I2 + I3) / 3,
//   omega = [ p^T        ]   sigma = 0: |p| is constant (held as a velocity
//           [ 2 a^T G(p) ]   constraint, so no method needs holonomic ones),
//                            <a, Omega> = 0.
// The radial term (c/2) sigma^2 makes L regular (mp06 and the discrete gradient
// invert the Legendre map): the mass matrix M(p) = 4 G^T I G + c p p^T has the
// eigenvalues 4 I_i |p|^2 along the sphere and c |p|^2 across it, and c, the
// mean of the 4 I_i, puts the radial one among the others.  The motion does not
// depend on c; the discrete maps do, slightly, and so do the Newton iterations
// (at h = 0.2 from the default states, c = 4 mean(I) takes at most 4 a solve for
// every implicit method on the Chaplygin sphere; c = mean(I) 5 for mp06).  On
// sigma = 0 the term, its partials c sigma p and c sigma pdot, and its force
// c sigmadot p (along the row p^T, and zero on a motion) vanish: the motion is
// the rigid body's.
//
// Index-reduced ODE (paper eq. 3 and eq. 4 differentiated; at any (q, v), s = |p|):
// G(p) applied to d/dt dL/dpdot - dL/dp = 4 G(pdot)^T Pi + 2 G(p)^T Pidot + c sigmadot p
// (Pi = I Omega) gives, with G(p) G(pdot)^T = sigma 1 + (Omega/2)^,
//   s^2 I Omegadot = Pi x Omega - 2 sigma Pi + s^2 lambda_1 a,    a . Omegadot = 0,
//   lambda_1 = -a . (I^-1 (Pi x Omega) - 2 sigma Omega) / (s^2 a . I^-1 a),
// and p^T pddot = -|pdot|^2 with G(p) pddot = Omegadot / 2 give
//   pddot = (-|pdot|^2 p + G(p)^T Omegadot / 2) / s^2.
// On |p| = 1 this is the Euler-Poincare-Suslov equation I Omegadot = I Omega x
// Omega + lambda a with pdot = p (0, Omega) / 2 (tests/test_rigid.cpp checks it,
// written with quaternion products, against generic_acceleration()).
//
// Exact solution (exact_solution() below) where a is a principal axis (one of
// a1, a2, a3 non-zero): Omega _|_ e_k makes Pi x Omega parallel to e_k, so
// Omegadot = 0 for every motion, a steady rotation about a fixed body axis,
//   R(t) = R0 exp(t Omega0^),  p(t) = p0 (cos(th/2), sin(th/2) Omega0/|Omega0|), th = |Omega0| t,
// pdot(t) = p(t) (0, Omega0) / 2; for |p0| = s != 1 the same with Omega0 =
// 2 G(p0) pdot0 / s^2 (|p| = s is kept).  States on the constraints (as motions are).
// Elsewhere none (false).  Reversible (L even in v).
//
// Default run (experiments/scenes/suslov.json): I = diag(1, 2, 6) and
// a = (0, 0.6, 0.8), not a principal axis, as in Fedorov & Zenkov's example
// (their numbers were not found; these are this project's choice), with a
// generic orientation p0 = (0.9, 0.3, 0.3, 0.1) (|p0| = 1).  There Omega = u e1 + w b,
// b = (0, 0.8, -0.6), and the reduced equations are
//   I1 u' = k w^2,  J w' = -k u w,   k = 0.48 (I3 - I2) = 1.92,  J = b^T I b = 3.44,
// the Chaplygin sleigh's (sleigh.hpp): u = c tanh(kappa (t - t*)), w = w* sech(...),
// c = sqrt(2E / I1), kappa = k c / J.  From Omega0 = (-0.6, 0.24, -0.18)
// (u0 = -0.6, w0 = 0.3), pdot0 = p0 (0, Omega0) / 2 = (0.063, -0.309, 0.105, 0.045),
// the body is on its way from the steady rotation -c e1 to the opposite one,
// +c e1 (c = 0.818): it turns over near t* = 2.05 (kappa = 0.457) and settles on
// +c e1, at constant energy E = 0.3348; h = 0.01, 1800 steps (T = 18).  (A body of
// inertia ratio 100, as below, turns over at a rate that h = 0.2, the typed
// tests' step, leaves to 4-5 Newton iterations a step.)  As the sleigh, it is
// reversible but not integrable in the KAM sense (not declared `integrable`).
// experiments/scenes/suslov_steady.json: the same body and p0 with a = e3, a
// principal axis, Pi0 = I Omega0 = (1, 1, 0) (Omega0 = (1, 0.1, 0)), pdot0 =
// (-0.165, 0.445, 0.095, -0.135): the steady rotation at |Omega0| = 1.005, 2.9
// turns over T = 18, E = 0.55 (the setting of the retraction preprint, García-Naranjo
// & Jiménez, arXiv 2604.04962), exact_solution()'s case.
#pragma once

#include <array>
#include <cmath>

#include "nhi/roles/system.hpp"
#include "nhi/groups/quaternion.hpp"

namespace nhi {

struct Suslov {
  static constexpr int n = 4;
  static constexpr int m = 2;
  static constexpr const char* name = "suslov";
  // L and omega are invariant under (q, v) -> (q, -v).
  static constexpr bool reversible = true;
  // Not integrable in the KAM sense for a not a principal axis (the default; above).
  static constexpr bool integrable = false;
  // The orientation is q itself (a unit quaternion, coordinates 0..3) and row 0
  // of omega is p . pdot = 0 (methods/group/ step on the group instead).
  static constexpr int orientation = 0;
  static constexpr int norm_row = 0;
  // L and omega read p only through 2 G(p) pdot and p . pdot (no potential):
  // the DLA's alpha rules are all of order 2 here (system.hpp).
  static constexpr bool bilinear_kinematics = true;

  double I1 = 1.0, I2 = 2.0, I3 = 6.0;     // body inertia diag(I1, I2, I3)
  double a1 = 0.0, a2 = 0.6, a3 = 0.8;     // <a, Omega> = 0

  // A free rigid body with a left-invariant constraint on Omega: what
  // methods/group/eps_cayley.hpp (which steps such a body on SO(3) itself)
  // reads, and the trait by which it is studied on this scene only.
  static constexpr bool left_invariant_constraint = true;
  Vec<double, 3> inertia() const { return Vec<double, 3>(I1, I2, I3); }
  Vec<double, 3> suslov_axis() const { return Vec<double, 3>(a1, a2, a3); }

  static auto parameters() {
    using P = Param<Suslov>;
    return std::array{P{"I1", &Suslov::I1, ParamCheck::kPositive},
                      P{"I2", &Suslov::I2, ParamCheck::kPositive},
                      P{"I3", &Suslov::I3, ParamCheck::kPositive},
                      P{"a1", &Suslov::a1},
                      P{"a2", &Suslov::a2},
                      P{"a3", &Suslov::a3}};
  }
  // Default initial state (experiments/scenes/suslov.json has the same numbers).
  static Vec<double, 4> default_q0() { return {0.9, 0.3, 0.3, 0.1}; }
  static Vec<double, 4> default_v0() { return {0.063, -0.309, 0.105, 0.045}; }

  // The radial term's coefficient c: the mean of the 4 I_i.
  double radial() const { return 4.0 * (I1 + I2 + I3) / 3.0; }

  template <class T>
  T lagrangian(const Vec<T, 4>& q, const Vec<T, 4>& v) const {
    const double k[3] = {2.0 * I1, 2.0 * I2, 2.0 * I3};
    return quaternion::kinetic<T>(q, v, k, 0.5 * radial());
  }

  // Hand-written dL/dq, dL/dqdot (the DLA's fast path; autodiff's numbers, quaternion.hpp).
  template <class T>
  void partials(const Vec<T, 4>& q, const Vec<T, 4>& v, Vec<T, 4>* dLdq, Vec<T, 4>* dLdv) const {
    const double k[3] = {2.0 * I1, 2.0 * I2, 2.0 * I3};
    quaternion::kinetic_partials<T>(q, v, k, 0.5 * radial(), dLdq, dLdv);
  }

  // The inverse Legendre map (fast path): for P = dL/dpdot, G(p) P = 2 s^2 I Omega
  // and p . P = c sigma s^2, so pdot = (sigma p + G(p)^T Omega / 2) / s^2.
  template <class T>
  Vec<T, 4> velocity(const Vec<T, 4>& q, const Vec<T, 4>& P) const {
    const T s2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    const Vec<T, 3> g = quaternion::G(q, P);  // 2 s^2 I Omega
    Vec<T, 3> half_omega;                     // Omega / 2 = I^-1 G(p) P / (4 s^2)
    half_omega << g[0] / (cst<T>(4.0 * I1) * s2), g[1] / (cst<T>(4.0 * I2) * s2), g[2] / (cst<T>(4.0 * I3) * s2);
    const T sigma = (q[0] * P[0] + q[1] * P[1] + q[2] * P[2] + q[3] * P[3]) / (cst<T>(radial()) * s2);
    const Vec<T, 4> gt = quaternion::Gt(q, half_omega);
    Vec<T, 4> v;
    for (int i = 0; i < 4; ++i) v[i] = (sigma * q[i] + gt[i]) / s2;
    return v;
  }

  template <class T>
  Mat<T, 2, 4> omega(const Vec<T, 4>& q) const {
    Vec<T, 3> a2v;  // 2 a
    a2v << cst<T>(2.0 * a1), cst<T>(2.0 * a2), cst<T>(2.0 * a3);
    const Vec<T, 4> row = quaternion::Gt(q, a2v);  // 2 G(p)^T a
    Mat<T, 2, 4> w;
    w << q[0], q[1], q[2], q[3],  //
        row[0], row[1], row[2], row[3];
    return w;
  }

  Vec<double, 4> acceleration(const Vec<double, 4>& q, const Vec<double, 4>& v) const {
    const Vec<double, 3> I(I1, I2, I3), a(a1, a2, a3);
    const double s2 = q.squaredNorm(), sigma = q.dot(v);
    const Vec<double, 3> Om = 2.0 * quaternion::G<double>(q, v), Pi = I.cwiseProduct(Om);
    const Vec<double, 3> f = Pi.cross(Om).cwiseQuotient(I) - 2.0 * sigma * Om;  // I^-1 (Pi x Omega - 2 sigma Pi)
    const Vec<double, 3> Ia = a.cwiseQuotient(I);                               // I^-1 a
    const double lambda = -a.dot(f) / a.dot(Ia);                                // s^2 lambda_1
    const Vec<double, 3> Omdot = (f + lambda * Ia) / s2;
    return (-v.squaredNorm() * q + quaternion::Gt<double>(q, Vec<double, 3>(0.5 * Omdot))) / s2;
  }

  // Is a a principal axis (exactly one of a1, a2, a3 non-zero)?
  bool principal_axis() const { return (a1 != 0.0) + (a2 != 0.0) + (a3 != 0.0) == 1; }

  // The steady rotation (see the top of this file) where a is a principal axis; false otherwise.
  bool exact_solution(const Vec<double, 4>& q0, const Vec<double, 4>& v0, double t, Vec<double, 4>* q,
                      Vec<double, 4>* v) const {
    if (!principal_axis()) return false;
    const Vec<double, 3> w = 2.0 * quaternion::G<double>(q0, v0) / q0.squaredNorm();  // the unit quaternion's rate
    *q = quaternion::product(q0, quaternion::half_exp(Vec<double, 3>(t * w)));
    Vec<double, 4> pure;
    pure << 0.0, 0.5 * w;
    *v = quaternion::product(*q, pure);
    return true;
  }

  // Conserved besides the energy: |p|^2 (sigma = 0), which a method may not keep.
  static std::array<const char*, 1> first_integral_names() { return {"p_norm2"}; }
  std::array<double, 1> first_integrals(const Vec<double, 4>& q, const Vec<double, 4>&) const {
    return {q.squaredNorm()};
  }
};

}  // namespace nhi
