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
#include <array>
#include <optional>
#include <type_traits>
#include <utility>

#include "nhi/roles/system.hpp"

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
                        std::declval<const Vec<T, S::n>&>(), std::declval<const Vec<T, S::n>&>()))>> : std::true_type {
};

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

// M^-1 of a separable system (constant), column j = V(0, e_j).
template <class S>
inline Mat<double, S::n, S::n> inverse_mass_matrix(const S& sys) {
  constexpr int n = S::n;
  Mat<double, n, n> Minv;
  for (int j = 0; j < n; ++j) Minv.col(j) = velocity<S, double>(sys, Vec<double, n>::Zero(), Vec<double, n>::Unit(j));
  return Minv;
}

// V(q, p) = M^-1 p of a separable system, with M^-1 formed once (by
// inverse_mass_matrix) and applied by products; a stepper keeps one for its
// system.  A hand-written V may divide by the masses (the robot, the sleigh),
// and divisions are slow against the rest of an explicit mp06 step.  A
// diagonal M^-1 is applied entry by entry, p_i (M^-1)_ii;
// the products differ from a V that divides at round-off.  Where M^-1 is the
// identity (every scene's default), identity() says so and a stepper uses
// IdentityVelocity below instead: p itself, which is V bit for bit, with no
// test of a flag inside the step (testing one on every V is a noticeable
// share of the particle's cheap mp06 step).
template <class S>
class SeparableVelocity {
 public:
  static constexpr int n = S::n;
  static_assert(is_separable<S>::value, "SeparableVelocity: V must not depend on q (a separable system)");
  explicit SeparableVelocity(const S& sys) : Minv_(inverse_mass_matrix(sys)) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (i != j && !(Minv_(i, j) == 0.0)) diagonal_ = false;
        if (!(Minv_(i, j) == (i == j ? 1.0 : 0.0))) identity_ = false;
      }
  }
  template <class T>
  Vec<T, n> operator()(const Vec<T, n>& p) const {
    Vec<T, n> v;
    if (diagonal_) {
      for (int i = 0; i < n; ++i) v[i] = scale(p[i], Minv_(i, i));
    } else {
      for (int i = 0; i < n; ++i) {
        v[i] = scale(p[0], Minv_(i, 0));
        for (int j = 1; j < n; ++j) v[i] += scale(p[j], Minv_(i, j));
      }
    }
    return v;
  }
  bool identity() const { return identity_; }
  const Mat<double, n, n>& matrix() const { return Minv_; }

 private:
  Mat<double, n, n> Minv_;
  bool diagonal_ = true, identity_ = true;
};

// V(q, p) = p: a separable system whose M^-1 is the identity (SeparableVelocity::identity()).
struct IdentityVelocity {
  template <class P>
  P operator()(const P& p) const {
    return p;
  }
};

// Coordinate i of two unrelated states (probe 0 and 1) at which the structural
// probes look: constant_force_jacobian, force_reads, omega_reads and
// constraint_force_misses_omega below, and Mp06Stepper::explicit_structure
// (mp06.hpp).  A structural zero
// of a derivative is exactly zero at both; a coincidental one is not.
inline double probe_q(int i, int probe) { return 0.31 + 0.17 * i - 0.45 * probe + 0.05 * i * i; }
inline double probe_v(int i, int probe) { return -0.23 + 0.29 * i + 0.37 * probe - 0.07 * i * i; }

// d(dL/dq)/dq at probe state 0 or 1, by autodiff (one Jet evaluation of the
// partials).  The two structural probes below read it.
template <class S>
inline Mat<double, S::n, S::n> force_jacobian_at_probe(const S& sys, int probe) {
  constexpr int n = S::n;
  using J = ceres::Jet<double, n>;
  Vec<J, n> qj, vj, Lq, Lv;
  for (int i = 0; i < n; ++i) {
    qj[i] = J(probe_q(i, probe), i);
    vj[i] = J(probe_v(i, probe));
  }
  lagrangian_partials(sys, qj, vj, &Lq, &Lv);
  Mat<double, n, n> K;
  for (int i = 0; i < n; ++i) K.row(i) = Lq[i].v.transpose();
  return K;
}

// K = d(dL/dq)/dq when it is the same bit for bit at the two unrelated probe
// states: dL/dq affine in q, a quadratic potential (K = 0: a linear one, or
// none).  nullopt otherwise.  On a separable system dL/dq does not depend on
// v, so K is also dF/dq.  The predictor passes of the DLA and the discrete
// gradient are exact in the potential with it (dla.hpp, discrete_gradient.hpp).
template <class S>
inline std::optional<Mat<double, S::n, S::n>> constant_force_jacobian(const S& sys) {
  const auto K0 = force_jacobian_at_probe(sys, 0), K1 = force_jacobian_at_probe(sys, 1);
  if (all_finite(K0) && K0 == K1) return K0;
  return std::nullopt;
}

// Which coordinates does dL/dq read?  Those with a non-zero derivative of some
// component at one of the two probe states (on a separable system
// dL/dq = -grad U(q) does not depend on v).
template <class S>
inline std::array<bool, S::n> force_reads(const S& sys) {
  constexpr int n = S::n;
  std::array<bool, n> reads{};
  for (int probe = 0; probe < 2; ++probe) {
    const auto K = force_jacobian_at_probe(sys, probe);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        if (!(K(i, j) == 0.0)) reads[j] = true;
  }
  return reads;
}

// Which coordinates does omega read?  Those with a non-zero derivative of
// some row at one of two unrelated states (autodiff; a structural zero is
// exactly zero).
template <class S>
inline std::array<bool, S::n> omega_reads(const S& sys) {
  constexpr int n = S::n, m = S::m;
  std::array<bool, n> reads{};
  using J = ceres::Jet<double, n>;
  for (int probe = 0; probe < 2; ++probe) {
    Vec<J, n> qj;
    for (int i = 0; i < n; ++i) qj[i] = J(probe_q(i, probe), i);
    const Mat<J, m, n> W = sys.template omega<J>(qj);
    for (int a = 0; a < m; ++a)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          if (!(W(a, j).v[i] == 0.0)) reads[i] = true;
  }
  return reads;
}

// Does the constraint force leave alone every coordinate omega reads?  On a
// separable system the force omega^T lambda moves the coordinates of the
// non-zero rows of M^-1 omega^T; true when none of them is read by omega (at
// both probe states above).  The particle, the robot and the
// oscillators: yes; the sleigh (omega reads theta, the force turns it): no.
// (It is the structure that makes mp06's step explicit,
// Mp06Stepper::explicit_structure, the DLA's Gauss-Seidel pass exact and the
// discrete gradient's first pass exact in a quadratic potential; false on a
// system that is not separable.)
template <class S>
inline bool constraint_force_misses_omega(const S& sys) {
  if constexpr (!is_separable<S>::value) {
    return false;
  } else {
    constexpr int n = S::n;
    const std::array<bool, n> reads = omega_reads(sys);
    const Mat<double, n, n> Minv = inverse_mass_matrix(sys);
    for (int probe = 0; probe < 2; ++probe) {
      Vec<double, n> q;
      for (int i = 0; i < n; ++i) q[i] = probe_q(i, probe);
      const Mat<double, n, S::m> moved = Minv * sys.template omega<double>(q).transpose();
      for (int j = 0; j < n; ++j)
        if (reads[j] && !(moved.row(j).array() == 0.0).all()) return false;
    }
    return true;
  }
}

}  // namespace nhi
