// Quaternion coordinates of a rigid body's orientation, shared by the rigid-body
// scenes (suslov.hpp, chaplygin_sphere.hpp).  p = (w, x, y, z) in R^4; on |p| = 1
// it is the rotation R(p) v = p v p-bar (body to space), and the body and space
// angular velocities are
//   Omega = 2 G(p) pdot = 2 vec(p-bar pdot),    omega = 2 E(p) pdot = 2 vec(pdot p-bar),
//   G(p) = [-x  w  z -y]                        E(p) = [-x  w -z  y]
//          [-y -z  w  x]                               [-y  z  w -x]
//          [-z  y -x  w],                              [-z -y  x  w],
// with p . pdot = scal(p-bar pdot) = (1/2) d|p|^2/dt besides.  [p^T; G(p)] is the
// matrix of u -> p-bar u, |p| times an orthogonal one, so (at any |p| = s)
//   G(p) p = 0,   G(p) G(p)^T = s^2 1,   u = (p (p.u) + G(p)^T G(p) u) / s^2,
//   G(p) pdot = -G(pdot) p,   G(pdot) pdot = 0,   G(p) G(pdot)^T = (p.pdot) 1 + (Omega/2)^,
// and on p . pdot = 0, pdot = G(p)^T Omega / (2 s^2): Rdot = R Omega^ on |p| = 1.
// E(p) G(p)^T = R(p) = s^2 R(p/s) is the rotation matrix written as a quadratic
// form in p (exact on |p| = 1); gamma = R(p)^T e_z, the vertical in the body
// frame, has |gamma| = s^2.  (Proofs: Lm(a)^T Lm(a) = |a|^2 1 and Lm(a) Lm(b) =
// Lm(a b) for the left-multiplication matrix Lm; tests/test_rigid.cpp checks
// the formulas against quaternion products.)  G, Gt, E and vertical are generic in
// the scalar (double, Jets, Jets of Jets); the rest is for double.
#pragma once

#include <cmath>

#include "nhi/roles/core.hpp"

namespace nhi::quaternion {

// G(p) u.
template <class T>
Vec<T, 3> G(const Vec<T, 4>& p, const Vec<T, 4>& u) {
  Vec<T, 3> r;
  r[0] = -p[1] * u[0] + p[0] * u[1] + p[3] * u[2] - p[2] * u[3];
  r[1] = -p[2] * u[0] - p[3] * u[1] + p[0] * u[2] + p[1] * u[3];
  r[2] = -p[3] * u[0] + p[2] * u[1] - p[1] * u[2] + p[0] * u[3];
  return r;
}

// The matrix G(p) itself.
template <class T>
Mat<T, 3, 4> matrix(const Vec<T, 4>& p) {
  Mat<T, 3, 4> m;
  m << -p[1], p[0], p[3], -p[2],  //
      -p[2], -p[3], p[0], p[1],   //
      -p[3], p[2], -p[1], p[0];
  return m;
}

// G(p)^T w.
template <class T>
Vec<T, 4> Gt(const Vec<T, 4>& p, const Vec<T, 3>& w) {
  Vec<T, 4> r;
  r[0] = -p[1] * w[0] - p[2] * w[1] - p[3] * w[2];
  r[1] = p[0] * w[0] - p[3] * w[1] + p[2] * w[2];
  r[2] = p[3] * w[0] + p[0] * w[1] - p[1] * w[2];
  r[3] = -p[2] * w[0] + p[1] * w[1] + p[0] * w[2];
  return r;
}

// E(p) u.
template <class T>
Vec<T, 3> E(const Vec<T, 4>& p, const Vec<T, 4>& u) {
  Vec<T, 3> r;
  r[0] = -p[1] * u[0] + p[0] * u[1] - p[3] * u[2] + p[2] * u[3];
  r[1] = -p[2] * u[0] + p[3] * u[1] + p[0] * u[2] - p[1] * u[3];
  r[2] = -p[3] * u[0] - p[2] * u[1] + p[1] * u[2] + p[0] * u[3];
  return r;
}

// gamma = R(p)^T e_z (|gamma| = |p|^2).
template <class T>
Vec<T, 3> vertical(const Vec<T, 4>& p) {
  const T two = cst<T>(2.0);
  Vec<T, 3> g;
  g[0] = two * (p[1] * p[3] - p[0] * p[2]);
  g[1] = two * (p[2] * p[3] + p[0] * p[1]);
  g[2] = p[0] * p[0] - p[1] * p[1] - p[2] * p[2] + p[3] * p[3];
  return g;
}

// The rotational kinetic energy of body inertia diag(I) with the radial term,
//   L_rot = 1/2 Omega^T I Omega + (c/2) sigma^2 = 2 sum_i I_i g_i^2 + (c/2) sigma^2,
//   g = G(p) pdot = Omega / 2,  sigma = p . pdot;  k_i = 2 I_i, hc = c / 2.
template <class T>
T kinetic(const Vec<T, 4>& p, const Vec<T, 4>& u, const double (&k)[3], double hc) {
  const Vec<T, 3> g = G(p, u);
  const T s = p[0] * u[0] + p[1] * u[1] + p[2] * u[2] + p[3] * u[3];
  return cst<T>(k[0]) * g[0] * g[0] + cst<T>(k[1]) * g[1] * g[1] + cst<T>(k[2]) * g[2] * g[2] + cst<T>(hc) * s * s;
}

// Its partials, dL_rot/dp = -2 G(pdot)^T I Omega + c sigma pdot and
// dL_rot/dpdot = 2 G(p)^T I Omega + c sigma p (dg/dpdot = G(p), dg/dp = -G(pdot)),
// accumulated as forward-mode autodiff of kinetic() accumulates them: each
// product (k g_i) g_i differentiated into its two product-rule terms
// (k g_i) dg_i + (k dg_i) g_i, the terms summed in kinetic()'s order.  So they
// are autodiff's numbers bit for bit, for double and for Jets (the typed test
// compares the Jet parts of order-1000 second derivatives to 1e-13).
template <class T>
void kinetic_partials(const Vec<T, 4>& p, const Vec<T, 4>& u, const double (&k)[3], double hc, Vec<T, 4>* dp,
                      Vec<T, 4>* du) {
  const Vec<T, 3> g = G(p, u);
  const T s = p[0] * u[0] + p[1] * u[1] + p[2] * u[2] + p[3] * u[3];
  const T K[3] = {cst<T>(k[0]), cst<T>(k[1]), cst<T>(k[2])}, H = cst<T>(hc);
  const T kg[3] = {K[0] * g[0], K[1] * g[1], K[2] * g[2]}, hs = H * s;
  // Columns of G(p) (= dg/dpdot) and of -G(pdot) (= dg/dp), entry (i, j) as G() multiplies it.
  const Mat<T, 3, 4> Gp = matrix(p), Gu = -matrix(u);
  for (int j = 0; j < 4; ++j) {
    T a = kg[0] * Gp(0, j) + (K[0] * Gp(0, j)) * g[0];
    a = a + (kg[1] * Gp(1, j) + (K[1] * Gp(1, j)) * g[1]);
    a = a + (kg[2] * Gp(2, j) + (K[2] * Gp(2, j)) * g[2]);
    (*du)[j] = a + (hs * p[j] + (H * p[j]) * s);
    T b = kg[0] * Gu(0, j) + (K[0] * Gu(0, j)) * g[0];
    b = b + (kg[1] * Gu(1, j) + (K[1] * Gu(1, j)) * g[1]);
    b = b + (kg[2] * Gu(2, j) + (K[2] * Gu(2, j)) * g[2]);
    (*dp)[j] = b + (hs * u[j] + (H * u[j]) * s);
  }
}

// R(p) v = vec(p (0, v) p-bar) (= |p|^2 R(p/|p|) v).
inline Vec<double, 3> rotate(const Vec<double, 4>& p, const Vec<double, 3>& v) {
  const double w = p[0];
  const Vec<double, 3> u = p.tail<3>();
  return (w * w - u.squaredNorm()) * v + 2.0 * u.dot(v) * u + 2.0 * w * u.cross(v);
}

// The quaternion product a b.
inline Vec<double, 4> product(const Vec<double, 4>& a, const Vec<double, 4>& b) {
  Vec<double, 4> r;
  r[0] = a[0] * b[0] - a.tail<3>().dot(b.tail<3>());
  r.tail<3>() = a[0] * b.tail<3>() + b[0] * a.tail<3>() + a.tail<3>().cross(b.tail<3>());
  return r;
}

// exp of the pure quaternion (0, v / 2): the rotation by |v| about v.
inline Vec<double, 4> half_exp(const Vec<double, 3>& v) {
  const double th = v.norm();
  Vec<double, 4> r;
  r[0] = std::cos(0.5 * th);
  // sin(th/2)/th -> 1/2 as th -> 0 (no division by a vanishing norm)
  const double k = th < 1e-8 ? 0.5 - th * th / 48.0 : std::sin(0.5 * th) / th;
  r.tail<3>() = k * v;
  return r;
}

// --- The group's own maps, generic in the scalar (the methods on the group,
// methods/group/): the product, the conjugate, exp of a rotation vector and its
// inverse log, and the tangent map of right translation.  exp and log switch to
// their Taylor series near zero, where sqrt has no derivative; the series are
// cut where the next term is below 1e-20 relative.

// a b.
template <class T>
Vec<T, 4> mul(const Vec<T, 4>& a, const Vec<T, 4>& b) {
  Vec<T, 4> r;
  r[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  r[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  r[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  r[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
  return r;
}

// a-bar.
template <class T>
Vec<T, 4> conj(const Vec<T, 4>& a) {
  return Vec<T, 4>(a[0], -a[1], -a[2], -a[3]);
}

// exp(xi) = (cos(|xi|/2), sin(|xi|/2) xi/|xi|): the rotation by |xi| about xi
// (half_exp() for any scalar).
template <class T>
Vec<T, 4> exp_map(const Vec<T, 3>& xi) {
  const T s = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2];
  T c, k;  // cos(|xi|/2), sin(|xi|/2)/|xi|
  if (value_of(s) < 1e-4) {
    c = cst<T>(1.0) - s * cst<T>(1.0 / 8) + s * s * cst<T>(1.0 / 384) - s * s * s * cst<T>(1.0 / 46080) +
        s * s * s * s * cst<T>(1.0 / 10321920);
    k = cst<T>(0.5) - s * cst<T>(1.0 / 48) + s * s * cst<T>(1.0 / 3840) - s * s * s * cst<T>(1.0 / 645120) +
        s * s * s * s * cst<T>(1.0 / 185794560);
  } else {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const T th = sqrt(s);
    c = cos(th * cst<T>(0.5));
    k = sin(th * cst<T>(0.5)) / th;
  }
  return Vec<T, 4>(c, k * xi[0], k * xi[1], k * xi[2]);
}

// log(p) for a unit quaternion: the rotation vector of length <= pi (p and -p
// are one rotation).
template <class T>
Vec<T, 3> log_map(const Vec<T, 4>& p0) {
  const Vec<T, 4> p = value_of(p0[0]) < 0 ? Vec<T, 4>(-p0) : p0;
  const T r = p[1] * p[1] + p[2] * p[2] + p[3] * p[3];  // sin^2(|xi|/2)
  T k;                                                  // 2 atan2(sqrt r, w) / sqrt r
  if (value_of(r) < 1e-4 && value_of(p[0]) > 0.5) {
    const T t = r / (p[0] * p[0]);  // atan(x)/x = 1 - x^2/3 + x^4/5 - ..., x^2 = t
    k = cst<T>(2.0) / p[0] *
        (cst<T>(1.0) - t * cst<T>(1.0 / 3) + t * t * cst<T>(1.0 / 5) - t * t * t * cst<T>(1.0 / 7) +
         t * t * t * t * cst<T>(1.0 / 9) - t * t * t * t * t * cst<T>(1.0 / 11));
  } else {
    using std::atan2;
    using std::sqrt;
    const T sr = sqrt(r);
    k = cst<T>(2.0) * atan2(sr, p[0]) / sr;
  }
  return Vec<T, 3>(k * p[1], k * p[2], k * p[3]);
}

// d/de p exp(e eta) at e = 0 = p (0, eta) / 2 = G(p)^T eta / 2: a 4 x 3 matrix.
template <class T>
Mat<T, 4, 3> tangent(const Vec<T, 4>& p) {
  return cst<T>(0.5) * matrix(p).transpose();
}

}  // namespace nhi::quaternion
