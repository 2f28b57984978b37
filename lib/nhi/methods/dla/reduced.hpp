// The reduced discrete Lagrange-d'Alembert algorithm (RDLA, paper section 5.3.2,
// Theorem 5.5, eqs. 32-34) for abelian Chaplygin systems.
//
// The system declares its split q = (r, s): `shape` (coordinates of Q/G) and
// `group` (G = R^m acting by translation on s), and its constraint forms must
// read omega = ds + A(r) dr (eq. 29 with an abelian group: the group block of
// omega is the identity and A depends on r only).  Then, with the DLA's
// discretization D,
//   f(r_a, r_b)   = s_b - s_a solved from omega_d = 0:  f = -sum_i w_i A(r_{c_i}) (r_b - r_a)
//   L*_d(r_a, r_b) = L_d((r_a, 0), (r_b, f(r_a, r_b)))                     (reduced L_d)
//   dl/df          = derivative of L_d in s_b at ((r_a, 0), (r_b, f))      (d ell_d / d f)
//   F^-(r_a, r_b)  = dl/df [ df/dr_a - A(r_a) ]                           (section 5.3.2)
//   F^+(r_a, r_b)  = dl/df [ df/dr_b + A(r_b) ]
// and the RDLA is the forced discrete Euler-Lagrange equation (32)
//   D1 L*_d(r_k, r_{k+1}) + D2 L*_d(r_{k-1}, r_k) = F^-(r_k, r_{k+1}) + F^+(r_{k-1}, r_k),
// written here in position-momentum form with the reduced momentum
//   pi_k = D2 L*_d(r_{k-1}, r_k) - F^+(r_{k-1}, r_k),   pi_k + D1 L*_d(r_k, r_{k+1}) - F^-(r_k, r_{k+1}) = 0,
// and the group variables reconstructed as s_{k+1} = s_k + f(r_k, r_{k+1}).
// Everything is computed from L and omega by (nested) Jets: no formula of the
// full DLA step is reused, so agreement with it is a test of Theorem 5.5.
#pragma once

#include <Eigen/LU>
#include <string>

#include "nhi/roles/discretization.hpp"

namespace nhi {

template <class S, class D>
class ReducedDla {
 public:
  static constexpr int n = S::n, m = S::m, k = S::n - S::m;
  using VecR = Vec<double, k>;
  using VecS = Vec<double, m>;

  ReducedDla(const S& sys, const D& disc, double h) : sys_(sys), disc_(disc), h_(h) {}

  // With forces = false the step is the plain variational integrator of L*_d
  // (eq. 32 with F^- = F^+ = 0): what Theorem 5.6 says the RDLA reduces to
  // under its hypotheses.  Used to show where those hypotheses matter.
  bool forces = true;

  // Split q into (r, s) and back.
  static VecR shape_of(const Vec<double, n>& q) {
    VecR r;
    for (int i = 0; i < k; ++i) r[i] = q[S::shape[i]];
    return r;
  }
  static VecS group_of(const Vec<double, n>& q) {
    VecS s;
    for (int a = 0; a < m; ++a) s[a] = q[S::group[a]];
    return s;
  }
  template <class T>
  static Vec<T, n> embed(const Vec<T, k>& r, const Vec<T, m>& s) {
    Vec<T, n> q;
    for (int i = 0; i < k; ++i) q[S::shape[i]] = r[i];
    for (int a = 0; a < m; ++a) q[S::group[a]] = s[a];
    return q;
  }

  // The connection coefficients A(r) (m x k) and the group block of omega,
  // which must be the identity for this reduction to apply.
  template <class T>
  Mat<T, m, k> connection(const Vec<T, k>& r, Mat<double, m, m>* group_block = nullptr) const {
    Vec<T, m> zero;
    zero.setConstant(cst<T>(0.0));
    const Mat<T, m, n> W = sys_.template omega<T>(embed<T>(r, zero));
    Mat<T, m, k> A;
    for (int a = 0; a < m; ++a) {
      for (int i = 0; i < k; ++i) A(a, i) = W(a, S::shape[i]);
      if (group_block)
        for (int b = 0; b < m; ++b) (*group_block)(a, b) = value_of(W(a, S::group[b]));
    }
    return A;
  }

  // f(r_a, r_b): the group displacement on the discrete constraint space.
  template <class T>
  Vec<T, m> displacement(const Vec<T, k>& ra, const Vec<T, k>& rb) const {
    Vec<T, m> f;
    f.setConstant(cst<T>(0.0));
    for (const Node& nd : disc_.constraint_nodes()) {
      const Mat<T, m, k> A = connection<T>(interpolate(ra, rb, nd.c));
      for (int a = 0; a < m; ++a)  // explicit loops: Eigen products need Scalar(0), which a Jet of Jets lacks
        for (int i = 0; i < k; ++i) f[a] -= cst<T>(nd.weight) * A(a, i) * (rb[i] - ra[i]);
    }
    return f;
  }

  // L*_d(r_a, r_b).
  template <class T>
  T reduced_lagrangian(const Vec<T, k>& ra, const Vec<T, k>& rb) const {
    Vec<T, m> zero;
    zero.setConstant(cst<T>(0.0));
    return discrete_lagrangian<S, D, T>(sys_, disc_, h_, embed<T>(ra, zero), embed<T>(rb, displacement<T>(ra, rb)));
  }

  // D_slot L*_d(r_a, r_b) - F^{-/+}(r_a, r_b): slot 1 gives D1 L* - F^-, slot 2
  // gives D2 L* - F^+ (so eq. 32 reads slot1(k, k+1) + slot2(k-1, k) = 0).
  template <int slot, class T>
  Vec<T, k> forced_slot(const Vec<T, k>& ra, const Vec<T, k>& rb) const {
    using J = ceres::Jet<T, k>;
    Vec<J, k> raj, rbj;
    for (int i = 0; i < k; ++i) {
      raj[i] = slot == 1 ? J(ra[i], i) : J(ra[i]);
      rbj[i] = slot == 2 ? J(rb[i], i) : J(rb[i]);
    }
    const J Ls = reduced_lagrangian<J>(raj, rbj);    // D_slot L*_d in Ls.v
    const Vec<J, m> fj = displacement<J>(raj, rbj);  // f and df/dr_slot
    // dl/df: derivative of L_d in s_b at ((r_a, 0), (r_b, f)).
    using K = ceres::Jet<T, m>;
    Vec<K, k> rak, rbk;
    for (int i = 0; i < k; ++i) {
      rak[i] = K(ra[i]);
      rbk[i] = K(rb[i]);
    }
    Vec<K, m> zero, fk;
    for (int a = 0; a < m; ++a) {
      zero[a] = K(cst<T>(0.0));
      fk[a] = K(fj[a].a, a);
    }
    const K Ld = discrete_lagrangian<S, D, K>(sys_, disc_, h_, embed<K>(rak, zero), embed<K>(rbk, fk));
    const Mat<T, m, k> A = connection<T>(slot == 1 ? ra : rb);
    Vec<T, k> out;
    for (int i = 0; i < k; ++i) {
      T force = cst<T>(0.0);  // F^-: dl/df (df/dr_a - A(r_a)); F^+: dl/df (df/dr_b + A(r_b))
      for (int a = 0; a < m; ++a) force += Ld.v[a] * (slot == 1 ? fj[a].v[i] - A(a, i) : fj[a].v[i] + A(a, i));
      out[i] = forces ? Ls.v[i] - force : Ls.v[i];
    }
    return out;
  }

  // The reduced momentum of the full state (q, p): pi = p_r - A(r)^T p_s, which is
  // D2 L*_d - F^+ along a DLA sequence.
  VecR reduced_momentum(const Vec<double, n>& q, const Vec<double, n>& p) const {
    const VecR r = shape_of(q);
    const Mat<double, m, k> A = connection<double>(r);
    VecR pr;
    VecS ps;
    for (int i = 0; i < k; ++i) pr[i] = p[S::shape[i]];
    for (int a = 0; a < m; ++a) ps[a] = p[S::group[a]];
    return pr - A.transpose() * ps;
  }

  struct Result {
    bool converged = false;
    int iterations = 0;
    double residual = 0;  // max |pi_k + D1 L* - F^-| at the solution
  };

  // One RDLA step: given (r_k, pi_k) and a guess, solve for r_{k+1}; then
  // pi_{k+1} = D2 L*_d(r_k, r_{k+1}) - F^+(r_k, r_{k+1}).
  Result step(const VecR& r, const VecR& pi, const VecR& guess, VecR* r_next, VecR* pi_next) const {
    using J = ceres::Jet<double, k>;
    Result res;
    VecR x = guess;
    for (res.iterations = 0; res.iterations < 50; ++res.iterations) {
      Vec<J, k> xj;
      for (int i = 0; i < k; ++i) xj[i] = J(x[i], i);
      const Vec<J, k> rj = r.template cast<J>();
      const Vec<J, k> g = forced_slot<1, J>(rj, xj);
      VecR val;
      Mat<double, k, k> Jm;
      for (int i = 0; i < k; ++i) {
        val[i] = pi[i] + g[i].a;
        for (int j = 0; j < k; ++j) Jm(i, j) = g[i].v[j];
      }
      const VecR dx = Jm.partialPivLu().solve(val);
      if (!all_finite(dx)) break;
      x -= dx;
      if (dx.cwiseAbs().maxCoeff() <= 4e-16 * (1.0 + x.cwiseAbs().maxCoeff())) {
        res.converged = true;
        break;
      }
    }
    *r_next = x;
    res.residual = (pi + forced_slot<1, double>(r, x)).cwiseAbs().maxCoeff();
    *pi_next = forced_slot<2, double>(r, x);
    return res;
  }

 private:
  S sys_;
  D disc_;
  double h_;
};

}  // namespace nhi
