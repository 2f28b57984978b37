// The position-momentum side of a system, for the methods that step (q, p)
// rather than positions (mp06.hpp, discrete_gradient.hpp):
//   the Legendre map        p = dL/dqdot(q, v)                 (system.hpp: momentum)
//   its inverse             v = V(q, p)
//   the force               F(q, p) = dL/dq(q, V(q, p))
//   the energy              H(q, p) = p . V - L(q, V)
// Every scene here has L = 1/2 v^T M(q) v + a(q) . v - U(q), quadratic in v, so
// dL/dqdot(q, v) = M(q) v + a(q) and V(q, p) = M(q)^-1 (p - a(q)) exactly.  The
// generic velocity() below reads a(q) = dL/dqdot(q, 0) and the columns of M(q)
// from dL/dqdot(q, e_j) - a(q) (n + 1 evaluations of the partials, no nested
// Jets) and solves; a system may hand-write
//   template <class T> Vec<T,n> velocity(const Vec<T,n>& q, const Vec<T,n>& p) const;
// as the fast path (tests/test_systems.cpp checks it against the generic one).
//
// A system that declares
//   static constexpr bool separable = true;   // M constant, a = 0: L = 1/2 v^T M v - U(q)
// has V independent of q and linear in p, and F independent of p; mp06 uses
// that to reduce its step to the m multipliers (mp06.hpp).
#pragma once

#include <Eigen/LU>
#include <type_traits>
#include <utility>

#include "nhi/system.hpp"

namespace nhi {

template <class S, class = void>
struct is_separable : std::false_type {};
template <class S>
struct is_separable<S, std::enable_if_t<S::separable>> : std::true_type {};

template <class S, class T, class = void>
struct has_velocity : std::false_type {};
template <class S, class T>
struct has_velocity<S, T,
                    std::void_t<decltype(std::declval<const S&>().template velocity<T>(
                        std::declval<const Vec<T, S::n>&>(), std::declval<const Vec<T, S::n>&>()))>>
    : std::true_type {};

// V(q, p) for L quadratic in v, from the partials alone (see the top of this file).
template <class S, class T>
inline Vec<T, S::n> generic_velocity(const S& sys, const Vec<T, S::n>& q, const Vec<T, S::n>& p) {
  constexpr int n = S::n;
  Vec<T, n> v = Vec<T, n>::Constant(cst<T>(0.0)), dq, a, col;
  lagrangian_partials(sys, q, v, &dq, &a);
  Mat<T, n, n> M;
  for (int j = 0; j < n; ++j) {
    v[j] = cst<T>(1.0);
    lagrangian_partials(sys, q, v, &dq, &col);
    M.col(j) = col - a;
    v[j] = cst<T>(0.0);
  }
  return M.partialPivLu().solve(Vec<T, n>(p - a));
}

// V(q, p): the inverse Legendre map.
template <class S, class T>
inline Vec<T, S::n> velocity(const S& sys, const Vec<T, S::n>& q, const Vec<T, S::n>& p) {
  if constexpr (has_velocity<S, T>::value) {
    return sys.template velocity<T>(q, p);
  } else {
    return generic_velocity(sys, q, p);
  }
}

// F(q, p) = dL/dq(q, V(q, p)).
template <class S, class T>
inline Vec<T, S::n> force(const S& sys, const Vec<T, S::n>& q, const Vec<T, S::n>& p) {
  const Vec<T, S::n> v = velocity(sys, q, p);
  Vec<T, S::n> dq, dv;
  lagrangian_partials(sys, q, v, &dq, &dv);
  return dq;
}

// H(q, p) = p . V - L(q, V): the energy as a function of (q, p).
template <class S, class T>
inline T hamiltonian(const S& sys, const Vec<T, S::n>& q, const Vec<T, S::n>& p) {
  const Vec<T, S::n> v = velocity(sys, q, p);
  return p.dot(v) - sys.template lagrangian<T>(q, v);
}

}  // namespace nhi
