// The *discretization* role: discrete Lagrangian L_d and discrete constraints
// omega_d on Q x Q (paper section 4, generalized coordinate formulation).
//
// Both families are quadratures in the interpolation point:
//   alpha      (eq. 9, 13):  L_d = h L(q_a, (q1-q0)/h),          q_a = (1-a) q0 + a q1
//                            omega_d = omega(q_a) (q1-q0)/h
//   symmetric  (eq. 10, 14): L_d = (h/2) [L(q_a, .) + L(q_{1-a}, .)]
//                            omega_d = (1/2)[omega(q_a) + omega(q_{1-a})] (q1-q0)/h
// The printed eq. (14) repeats its first term twice; the form above is its
// evident intent and agrees with eq. (16).  L_d carries the factor h, so the
// multipliers lambda of the DLA step carry it too.
//
// So a discretization is a list of nodes (weight w_i, interpolation c_i) and
//   L_d     = h sum_i w_i L(q_{c_i}, (q1-q0)/h)
//   omega_d = sum_i w_i omega(q_{c_i}) (q1-q0)/h
// constraint_nodes() gives the nodes of omega_d: the same as nodes(), as Remark
// 3.1 asks; a study may pair them differently to see which half sets the order.
#pragma once

#include <array>
#include <string>

#include "nhi/roles/system.hpp"

namespace nhi {

struct Node {
  double weight;
  double c;  // interpolation: q_c = (1-c) q0 + c q1
};

// L_d^alpha, omega_d^alpha (eqs. 9, 13).
struct AlphaDiscretization {
  static constexpr int kNodes = 1;
  static constexpr const char* kind = "alpha";
  double alpha = 0.5;
  std::array<Node, 1> nodes() const { return {{{1.0, alpha}}}; }
  std::array<Node, 1> constraint_nodes() const { return nodes(); }  // Remark 3.1: same discretization
  // Order of the DLA built on it for the nonholonomic problem (section 4:
  // second order guaranteed only for alpha = 1/2; tests/test_convergence.cpp
  // measures the others).
  int order() const { return alpha == 0.5 ? 2 : 1; }
  bool symmetric() const { return alpha == 0.5; }
  std::string name() const { return "alpha=" + std::to_string(alpha); }
};

// L_d^{sym,alpha}, omega_d^{sym,alpha} (eqs. 10, 14 as corrected).
struct SymmetricDiscretization {
  static constexpr int kNodes = 2;
  static constexpr const char* kind = "symmetric";
  double alpha = 0.0;
  std::array<Node, 2> nodes() const { return {{{0.5, alpha}, {0.5, 1.0 - alpha}}}; }
  std::array<Node, 2> constraint_nodes() const { return nodes(); }
  int order() const { return 2; }
  bool symmetric() const { return true; }
  std::string name() const { return "symmetric alpha=" + std::to_string(alpha); }
};

// For studies of what sets the order: L_d^{alpha_L} paired with
// omega_d^{alpha_omega} (Remark 3.1 asks for alpha_L = alpha_omega).
struct SplitDiscretization {
  static constexpr int kNodes = 1;
  static constexpr const char* kind = "split";
  double alpha_L = 0.5, alpha_omega = 0.5;
  std::array<Node, 1> nodes() const { return {{{1.0, alpha_L}}}; }
  std::array<Node, 1> constraint_nodes() const { return {{{1.0, alpha_omega}}}; }
  int order() const { return alpha_L == 0.5 && alpha_omega == 0.5 ? 2 : 1; }
  bool symmetric() const { return alpha_L == 0.5 && alpha_omega == 0.5; }
};

template <class T, int N>
inline Vec<T, N> interpolate(const Vec<T, N>& q0, const Vec<T, N>& q1, double c) {
  Vec<T, N> r;
  for (int i = 0; i < N; ++i) r[i] = scale(q0[i], 1.0 - c) + scale(q1[i], c);
  return r;
}

// L_d(q0, q1) (eq. 9 / 10).
template <class S, class D, class T>
inline T discrete_lagrangian(const S& sys, const D& disc, double h, const Vec<T, S::n>& q0, const Vec<T, S::n>& q1) {
  const Vec<T, S::n> v = (q1 - q0) / cst<T>(h);
  T Ld = cst<T>(0.0);
  for (const Node& nd : disc.nodes())
    Ld += cst<T>(h * nd.weight) * sys.template lagrangian<T>(interpolate(q0, q1, nd.c), v);
  return Ld;
}

// D1 L_d(q0, q1) and D2 L_d(q0, q1) from the partials of L at the nodes:
//   D1 L_d = sum_i w_i [ h (1-c_i) dL/dq - dL/dqdot ](q_{c_i}, (q1-q0)/h)
//   D2 L_d = sum_i w_i [ h c_i     dL/dq + dL/dqdot ](q_{c_i}, (q1-q0)/h)
// Either pointer may be null.  This is the hot path of the DLA step; the tests
// check it against discrete_lagrangian_slot() below (autodiff of L_d itself).
template <class S, class D, class T>
inline void discrete_lagrangian_slots(const S& sys, const D& disc, double h, const Vec<T, S::n>& q0,
                                      const Vec<T, S::n>& q1, Vec<T, S::n>* D1, Vec<T, S::n>* D2) {
  constexpr int n = S::n;
  Vec<T, n> v;
  for (int i = 0; i < n; ++i) v[i] = divide(T(q1[i] - q0[i]), h);
  if (D1) D1->setConstant(cst<T>(0.0));
  if (D2) D2->setConstant(cst<T>(0.0));
  for (const Node& nd : disc.nodes()) {
    Vec<T, n> Lq, Lv;
    lagrangian_partials(sys, interpolate(q0, q1, nd.c), v, &Lq, &Lv);
    for (int i = 0; i < n; ++i) {
      if (D1) (*D1)[i] += scale(Lq[i], nd.weight * h * (1.0 - nd.c)) - scale(Lv[i], nd.weight);
      if (D2) (*D2)[i] += scale(Lq[i], nd.weight * h * nd.c) + scale(Lv[i], nd.weight);
    }
  }
}

// D1 L_d(q0, q1) (slot = 1) or D2 L_d(q0, q1) (slot = 2): the gradient of L_d
// in one of its arguments, by a Jet over that argument's n coordinates.  With
// T = Jet<double, n> over q1 (as in the DLA step) this is a Jet of Jets and
// gives D2 D1 L_d, the top-left block of the matrix (7), exactly.
template <int slot, class S, class D, class T>
inline Vec<T, S::n> discrete_lagrangian_slot(const S& sys, const D& disc, double h, const Vec<T, S::n>& q0,
                                             const Vec<T, S::n>& q1) {
  static_assert(slot == 1 || slot == 2, "slot is 1 or 2");
  constexpr int n = S::n;
  using J = ceres::Jet<T, n>;
  Vec<J, n> q0j, q1j;
  for (int i = 0; i < n; ++i) {
    q0j[i] = slot == 1 ? J(q0[i], i) : J(q0[i]);
    q1j[i] = slot == 2 ? J(q1[i], i) : J(q1[i]);
  }
  const J Ld = discrete_lagrangian<S, D, J>(sys, disc, h, q0j, q1j);
  Vec<T, n> g;
  for (int i = 0; i < n; ++i) g[i] = Ld.v[i];
  return g;
}

// omega_d(q0, q1) (eq. 13 / 14); *scale (optional) gets sum_i w_i |omega(q_c)| |q1-q0|/h,
// the size of the terms, against which round-off in omega_d is judged.
// omega_at(k, q_c) gives omega(q_c) at the k-th constraint node (a caller
// may have it at hand: DlaStepper's passes).
template <class S, class D, class T, class OmegaAt>
inline Vec<T, S::m> discrete_constraint_with(const S& sys, const OmegaAt& omega_at, const D& disc, double h,
                                             const Vec<T, S::n>& q0, const Vec<T, S::n>& q1,
                                             Vec<double, S::m>* scale = nullptr) {
  Vec<T, S::n> v;
  for (int i = 0; i < S::n; ++i) v[i] = divide(T(q1[i] - q0[i]), h);
  Vec<T, S::m> w;
  w.setConstant(cst<T>(0.0));
  if (scale) scale->setZero();
  int k = 0;
  for (const Node& nd : disc.constraint_nodes()) {
    const Mat<T, S::m, S::n> W = omega_at(k++, interpolate(q0, q1, nd.c));
    w += cst<T>(nd.weight) * (W * v);
    if (scale) {
      for (int a = 0; a < S::m; ++a)
        for (int j = 0; j < S::n; ++j)
          (*scale)[a] += nd.weight * std::abs(value_of(W(a, j))) * std::abs(value_of(v[j]));
    }
  }
  // A unit quaternion's norm row p^T pdot = 0 is the velocity form of the
  // holonomic g(q) = |p|^2 / 2 (norm_increment, system.hpp): it is held as
  // g(q_{k+1}) = g(q_k) (eq. 17 on the level set of g through q_0; divided by h,
  // the row's scale), for the quaternion the midpoint's row (p0 + p1)^T (p1 - p0) / 2h
  // at every alpha.  The alpha rule's own row, p_alpha^T (p1 - p0) / h, gives
  // |p1|^2 - |p0|^2 = (1 - 2 alpha)|p1 - p0|^2: off the midpoint it moves |p|
  // every step and, for alpha > 1/2, drives the solve to failure (the Suslov
  // problem at h = 0.2: at step 46 for alpha = 0.75).
  constexpr int nr = norm_row_of<S>::value;
  if constexpr (nr >= 0) {
    double s = 0;
    w[nr] = divide(norm_increment<S, T>(sys, q0, q1, &s), h);
    if (scale) (*scale)[nr] = s / std::abs(h);
  }
  return w;
}

template <class S, class D, class T>
inline Vec<T, S::m> discrete_constraint(const S& sys, const D& disc, double h, const Vec<T, S::n>& q0,
                                        const Vec<T, S::n>& q1, Vec<double, S::m>* scale = nullptr) {
  return discrete_constraint_with<S, D, T>(
      sys, [&](int, const Vec<T, S::n>& q) { return sys.template omega<T>(q); }, disc, h, q0, q1, scale);
}

}  // namespace nhi
