// The *system* role: a Lagrangian L(q, qdot) and m constraint one-forms omega(q)
// (motions satisfy omega(q) qdot = 0, paper eq. 4), and what follows from them
// generically by automatic differentiation.
//
// A system is a plain type with
//   static constexpr int n, m;                       // dim Q, number of constraints
//   template <class T> T lagrangian(const Vec<T,n>& q, const Vec<T,n>& v) const;
//   template <class T> Mat<T,m,n> omega(const Vec<T,n>& q) const;
// (checked at compile time: check_system() below) and, for RK4 and the
// reference solution (check_system_ode()),
//   Vec<double,n> acceleration(const Vec<double,n>& q, const Vec<double,n>& v) const;
// That is all a system of one's own needs (examples/knife_edge.hpp).  A system
// that is a *scene* (listed in systems/registry.hpp, runnable by `nhi` and
// every study) has acceleration() and also
//   static constexpr const char* name;
//   static auto parameters();          // std::array of Param<S>: name, member, check
//   static Vec<double,n> default_q0(), default_v0();   // its default initial state
// and optionally
//   template <class T> void partials(q, v, Vec<T,n>* dLdq, Vec<T,n>* dLdv) const;
//   static constexpr bool separable = true;  // and velocity(q, p): hamiltonian.hpp
//   static constexpr int l;  template <class T> Vec<T,l> g(const Vec<T,n>& q) const;
// and capability declarations the tests and studies select on (traits below):
//   static constexpr bool reversible = true;  // L, omega invariant under (q, v) -> (q, -v)
//   static constexpr bool integrable = true;  // ... and integrable: reversible KAM theory
//                                             // bounds a reversible method's energy error
//   static constexpr bool reversible_flow = true;  // the flow is reversible though L is
//                                             // not (a gauge term): every q(t) is, the
//                                             // methods' maps are not (default: `reversible`)
//   static constexpr const char* behaviour = "chaotic";  // the long-time motion where
//                                             // reversible but not integrable
//   first_integral_names(), first_integrals(q, v)  // conserved quantities besides the energy
//   exact_solution(q0, v0, t, &q, &v)          // a closed form (returns false where it has none)
//   section_states(count), section_coordinate  // initial states for Poincare sections
//   shape, group                              // a Chaplygin split (reduced.hpp)
//   nonholonomic_momentum, momentum_equation_rhs   // a symmetry for eq. (24)
//   reduced_flow                               // an independent exact reduced description
//   paper_section                              // one of the paper's scenes (section 6.x)
//   orientation, norm_row                      // a rigid body: q holds a unit quaternion
//                                              // (quaternion_at, norm_row_of below)
// reversible, integrable, reversible_flow and behaviour (orientation: "rigid body") make a scene's "class" in
// `nhi list --json` (catalog() in lib/src/runner/scene.cpp), by which experiments/tools/summarize.sh
// groups the scenes of its decision table.
// The pair (l, g) adds l holonomic constraints g(q) = 0: the Constrained Coordinate
// Formulation (paper eq. 17), where Q is a submanifold g = 0 of a vector space V
// and the configuration is a point of V (e.g. an angle as a unit vector).
// acceleration() is the index-reduced ODE (constraint differentiated once, multiplier
// eliminated, paper section 6.1) written out by hand for speed, for RK4 and the
// reference solution; the tests check it against generic_acceleration() below,
// which derives it from L and omega.  (Test-only systems such as CircleHolonomic
// need not have it.)
// partials() is the same kind of fast path for the DLA step: without it the
// step's Jacobian needs a Jet of Jets, about ten times slower.
#pragma once

#include <Eigen/Dense>
#include <type_traits>
#include <utility>

#include "nhi/roles/core.hpp"

namespace nhi {

// A scene parameter: its name in the scene's `params`, the member it sets, and
// what the validator requires of it (every number must also be finite).
enum class ParamCheck { kFinite, kPositive, kNonNegative };
template <class S>
struct Param {
  const char* name;
  double S::*member;
  ParamCheck check = ParamCheck::kFinite;
};

// Capabilities a system may declare (see the top of this file).
template <class S, class = void>
struct is_reversible : std::false_type {};
template <class S>
struct is_reversible<S, std::enable_if_t<S::reversible>> : std::true_type {};

template <class S, class = void>
struct is_integrable : std::false_type {};
template <class S>
struct is_integrable<S, std::enable_if_t<S::integrable>> : std::true_type {};

// A reversible flow: declared, or implied by `reversible`.
template <class S, class = void>
struct has_reversible_flow : is_reversible<S> {};
template <class S>
struct has_reversible_flow<S, std::enable_if_t<S::reversible_flow>> : std::true_type {};

// The long-time behaviour a scene declares (nullptr if none).
template <class S, class = void>
struct behaviour_of {
  static constexpr const char* value = nullptr;
};
template <class S>
struct behaviour_of<S, std::void_t<decltype(S::behaviour)>> {
  static constexpr const char* value = S::behaviour;
};

// Reversible and integrable: the class on which Modin & Verdier (Numer. Math.
// 145, 2020) show by reversible KAM theory that reversible methods keep the
// energy bounded; the tests assert that only there.
template <class S, class = void>
struct is_reversible_integrable : std::false_type {};
template <class S>
struct is_reversible_integrable<S, std::enable_if_t<S::reversible && S::integrable>> : std::true_type {};

// First integrals besides the energy: names and values at (q, v).
template <class S, class = void>
struct has_first_integrals : std::false_type {};
template <class S>
struct has_first_integrals<S, std::void_t<decltype(S::first_integral_names())>> : std::true_type {};

// A closed-form solution: bool exact_solution(q0, v0, t, &q, &v) const.
template <class S, class = void>
struct has_exact_solution : std::false_type {};
template <class S>
struct has_exact_solution<S, std::void_t<decltype(&S::exact_solution)>> : std::true_type {};

// A family of initial states for Poincare sections (study_poincare).
template <class S, class = void>
struct has_section_states : std::false_type {};
template <class S>
struct has_section_states<
    S, std::void_t<decltype(std::declval<const S&>().section_states(1)), decltype(S::section_coordinate)>>
    : std::true_type {};

// One of the paper's own scenes (section 6), where its claims are asserted as stated.
template <class S, class = void>
struct is_paper_scene : std::false_type {};
template <class S>
struct is_paper_scene<S, std::void_t<decltype(S::paper_section)>> : std::true_type {};

template <class S, class = void>
struct has_chaplygin_split : std::false_type {};
template <class S>
struct has_chaplygin_split<S, std::void_t<decltype(S::shape), decltype(S::group)>> : std::true_type {};

template <class S, class = void>
struct has_momentum_equation : std::false_type {};
template <class S>
struct has_momentum_equation<S, std::void_t<decltype(&S::nonholonomic_momentum), decltype(&S::momentum_equation_rhs)>>
    : std::true_type {};

template <class S, class = void>
struct has_reduced_flow : std::false_type {};
template <class S>
struct has_reduced_flow<S, std::void_t<decltype(&S::reduced_flow)>> : std::true_type {};

// The concept's required part, checked at compile time: every stepper opens
// with static_assert(check_system<S>()) (RK4 and the reference solution with
// check_system_ode<S>()), so that a type which is not a system fails with one
// of the messages below before any error from inside a method.
template <class S, class = void>
struct has_dimensions : std::false_type {};
template <class S>
struct has_dimensions<S, std::enable_if_t<std::is_same_v<decltype(S::n), const int> &&
                                          std::is_same_v<decltype(S::m), const int> && (S::n > 0) && (S::m >= 0)>>
    : std::true_type {};

template <class S, class T, class = void>
struct has_lagrangian : std::false_type {};
template <class S, class T>
struct has_lagrangian<S, T,
                      std::enable_if_t<std::is_same_v<decltype(std::declval<const S&>().template lagrangian<T>(
                                                          std::declval<const Vec<T, S::n>&>(),
                                                          std::declval<const Vec<T, S::n>&>())),
                                                      T>>> : std::true_type {};

template <class S, class T, class = void>
struct has_omega : std::false_type {};
template <class S, class T>
struct has_omega<S, T,
                 std::enable_if_t<std::is_same_v<
                     std::decay_t<decltype(std::declval<const S&>().template omega<T>(std::declval<const Vec<T, S::n>&>()))>,
                     Mat<T, S::m, S::n>>>> : std::true_type {};

template <class S, class = void>
struct has_acceleration : std::false_type {};
template <class S>
struct has_acceleration<S, std::enable_if_t<std::is_same_v<
                               std::decay_t<decltype(std::declval<const S&>().acceleration(
                                   std::declval<const Vec<double, S::n>&>(), std::declval<const Vec<double, S::n>&>()))>,
                               Vec<double, S::n>>>> : std::true_type {};

template <class S>
constexpr bool check_system() {
  static_assert(has_dimensions<S>::value,
                "nhi system concept: the system type needs `static constexpr int n` (dim Q, > 0) and "
                "`static constexpr int m` (the number of constraint one-forms)");
  if constexpr (has_dimensions<S>::value) {
    static_assert(has_lagrangian<S, double>::value && has_lagrangian<S, ceres::Jet<double, S::n>>::value,
                  "nhi system concept: the system type needs `template <class T> T lagrangian(const Vec<T, n>& q, "
                  "const Vec<T, n>& v) const`, generic in the scalar T (double and ceres::Jet)");
    static_assert(has_omega<S, double>::value && has_omega<S, ceres::Jet<double, S::n>>::value,
                  "nhi system concept: the system type needs `template <class T> Mat<T, m, n> omega(const Vec<T, n>& "
                  "q) const`, the constraint one-forms as the rows of an m x n matrix, generic in the scalar T");
  }
  return true;
}

// What RK4 and the reference solution need besides: the index-reduced ODE.
template <class S>
constexpr bool check_system_ode() {
  check_system<S>();
  if constexpr (has_dimensions<S>::value)
    static_assert(has_acceleration<S>::value,
                  "nhi system concept: RK4 and the reference solution need `Vec<double, n> acceleration(const "
                  "Vec<double, n>& q, const Vec<double, n>& v) const`, the index-reduced ODE (nhi::"
                  "generic_acceleration(*this, q, v) derives it from L and omega)");
  return true;
}

// Does the system hand-write its partials (the optional fast path)?
template <class S, class T, class = void>
struct has_partials : std::false_type {};
template <class S, class T>
struct has_partials<S, T,
                    std::void_t<decltype(std::declval<const S&>().template partials<T>(
                        std::declval<const Vec<T, S::n>&>(), std::declval<const Vec<T, S::n>&>(),
                        std::declval<Vec<T, S::n>*>(), std::declval<Vec<T, S::n>*>()))>> : std::true_type {};

// Number of holonomic constraints g(q) = 0 the system declares (0 if none).
template <class S, class = void>
struct holonomic_count : std::integral_constant<int, 0> {};
template <class S>
struct holonomic_count<S, std::void_t<decltype(S::l)>> : std::integral_constant<int, S::l> {};

// A rigid body's orientation as a unit quaternion p in q (systems/suslov.hpp,
// chaplygin_sphere.hpp): where its four coordinates start (-1: none), and which
// omega row is p^T pdot = 0, the velocity form of |p|^2 = 1 (-1: none).  The DLA
// holds that row holonomically (eq. 17; roles/discretization.hpp), the methods
// on the group (methods/group/) drop it.
template <class S, class = void>
struct quaternion_at : std::integral_constant<int, -1> {};
template <class S>
struct quaternion_at<S, std::void_t<decltype(S::orientation)>> : std::integral_constant<int, S::orientation> {};
template <class S, class = void>
struct norm_row_of : std::integral_constant<int, -1> {};
template <class S>
struct norm_row_of<S, std::void_t<decltype(S::norm_row)>> : std::integral_constant<int, S::norm_row> {};

// A rigid body whose L and omega read its quaternion p only through the
// bilinear forms G(p) pdot, E(p) pdot (quaternion.hpp) and p . pdot, and its
// other coordinates only through their velocities (`bilinear_kinematics`).  G
// and E are antisymmetric in the sense G(p) u = -G(u) p, so on a step
// G(p_alpha)(p1 - p0) = G(p0) p1 for every alpha: omega_d^alpha (eq. 13) does not
// depend on alpha, and L_d^alpha (eq. 9) only through the radial term's
// sigma_alpha = sigma_1/2 + (alpha - 1/2)|p1 - p0|^2.  sigma_alpha^2 and
// sigma_{1-alpha}^2 differ by 4 (alpha - 1/2) sigma_1/2 |p1 - p0|^2, whose
// derivatives on the level set of |p| (sigma_1/2 = 0) lie along p, the norm row's
// force: the alpha and 1 - alpha rules are one map in q, which is therefore
// self-adjoint (symmetric) and of order 2 for every alpha (tests/test_methods.cpp
// and test_convergence.cpp measure both).
template <class S, class = void>
struct has_bilinear_kinematics : std::false_type {};
template <class S>
struct has_bilinear_kinematics<S, std::enable_if_t<S::bilinear_kinematics>> : std::true_type {};

// The function g whose level set the norm row's discrete form holds (the DLA:
// g(q_{k+1}) = g(q_k), roles/discretization.hpp): the system's own
// norm_invariant(q) if it has one (a system in other coordinates, as
// tests/test_embedding.cpp's), else |p|^2 / 2 of its quaternion.
template <class S, class T, class = void>
struct has_norm_invariant : std::false_type {};
template <class S, class T>
struct has_norm_invariant<S, T,
                          std::void_t<decltype(std::declval<const S&>().template norm_invariant<T>(
                              std::declval<const Vec<T, S::n>&>()))>> : std::true_type {};
// g(q1) - g(q0) for that g, and in *scale the size of the terms its round-off
// is judged against: for the quaternion, (p1 - p0) . (p1 + p0) / 2, accurate to
// eps |p1 - p0| |p1 + p0| where the difference of |p|^2 would lose eps |p|^2.
template <class S, class T>
inline T norm_increment(const S& sys, const Vec<T, S::n>& q0, const Vec<T, S::n>& q1, double* scale) {
  if constexpr (has_norm_invariant<S, T>::value) {
    const T g1 = sys.template norm_invariant<T>(q1), g0 = sys.template norm_invariant<T>(q0);
    *scale = std::abs(value_of(g1)) + std::abs(value_of(g0));
    return g1 - g0;
  } else {
    constexpr int qi = quaternion_at<S>::value;
    static_assert(qi >= 0, "a norm row needs a quaternion or the system's norm_invariant()");
    T d = cst<T>(0.0);
    *scale = 0;
    for (int i = qi; i < qi + 4; ++i) {
      d += (q1[i] - q0[i]) * (q1[i] + q0[i]);
      *scale += std::abs(value_of(q1[i] - q0[i])) * std::abs(value_of(q1[i] + q0[i]));
    }
    *scale *= 0.5;
    return cst<T>(0.5) * d;
  }
}

// g(q) and its derivative Dg(q) (an l x n matrix) by one Jet.
template <class S>
inline Mat<double, holonomic_count<S>::value, S::n> holonomic_jacobian(const S& sys, const Vec<double, S::n>& q) {
  constexpr int n = S::n, l = holonomic_count<S>::value;
  Mat<double, l, n> G;
  if constexpr (l > 0) {
    using J = ceres::Jet<double, n>;
    Vec<J, n> qj;
    for (int i = 0; i < n; ++i) qj[i] = J(q[i], i);
    const Vec<J, l> gj = sys.template g<J>(qj);
    for (int a = 0; a < l; ++a)
      for (int i = 0; i < n; ++i) G(a, i) = gj[a].v[i];
  }
  return G;
}

// dL/dq and dL/dqdot at (q, v) by autodiff of L: one forward-mode Jet over the
// 2n inputs.  T may itself be a Jet (then this is a Jet of Jets: exact, slow).
template <class S, class T>
inline void autodiff_partials(const S& sys, const Vec<T, S::n>& q, const Vec<T, S::n>& v, Vec<T, S::n>* dLdq,
                              Vec<T, S::n>* dLdv) {
  constexpr int n = S::n;
  using J = ceres::Jet<T, 2 * n>;
  Vec<J, n> qj, vj;
  for (int i = 0; i < n; ++i) {
    qj[i] = J(q[i], i);
    vj[i] = J(v[i], n + i);
  }
  const J L = sys.template lagrangian<J>(qj, vj);
  for (int i = 0; i < n; ++i) {
    (*dLdq)[i] = L.v[i];
    (*dLdv)[i] = L.v[n + i];
  }
}

// dL/dq and dL/dqdot at (q, v): the system's hand-written partials<T>() if it
// has them (the fast path; tests/test_systems.cpp checks them against
// autodiff_partials to round-off, for double and for Jet), else autodiff.
template <class S, class T>
inline void lagrangian_partials(const S& sys, const Vec<T, S::n>& q, const Vec<T, S::n>& v, Vec<T, S::n>* dLdq,
                                Vec<T, S::n>* dLdv) {
  if constexpr (has_partials<S, T>::value) {
    sys.template partials<T>(q, v, dLdq, dLdv);
  } else {
    autodiff_partials(sys, q, v, dLdq, dLdv);
  }
}

// Momentum p = dL/dqdot.
template <class S>
inline Vec<double, S::n> momentum(const S& sys, const Vec<double, S::n>& q, const Vec<double, S::n>& v) {
  Vec<double, S::n> dq, dv;
  lagrangian_partials(sys, q, v, &dq, &dv);
  return dv;
}

// Energy E = dL/dqdot . v - L.
template <class S>
inline double energy(const S& sys, const Vec<double, S::n>& q, const Vec<double, S::n>& v) {
  Vec<double, S::n> dq, dv;
  lagrangian_partials(sys, q, v, &dq, &dv);
  return dv.dot(v) - sys.template lagrangian<double>(q, v);
}

// Constraint values omega(q) v (zero along motions).
template <class S>
inline Vec<double, S::m> constraint_values(const S& sys, const Vec<double, S::n>& q, const Vec<double, S::n>& v) {
  return sys.template omega<double>(q) * v;
}

// The index-reduced ODE derived from L and omega alone:
//   M a + C v - dL/dq = omega^T lambda              (paper eq. 3)
//   omega a + d(omega(q) v)/dq v = 0                (eq. 4 differentiated)
// with M = d2L/dqdot2, C = d2L/dqdot dq.  Returns a; *lambda gets the multiplier.
// Used to check each scene's hand-written acceleration(), not on the hot path.
template <class S>
inline Vec<double, S::n> generic_acceleration(const S& sys, const Vec<double, S::n>& q, const Vec<double, S::n>& v,
                                              Vec<double, S::m>* lambda = nullptr) {
  constexpr int n = S::n, m = S::m;
  using J = ceres::Jet<double, 2 * n>;
  Vec<J, n> qj, vj;
  for (int i = 0; i < n; ++i) {
    qj[i] = J(q[i], i);
    vj[i] = J(v[i], n + i);
  }
  Vec<J, n> dq, dv;
  autodiff_partials(sys, qj, vj, &dq, &dv);
  Mat<double, n, n> M, C;
  Vec<double, n> f;
  for (int i = 0; i < n; ++i) {
    f[i] = dq[i].a;
    for (int j = 0; j < n; ++j) {
      C(i, j) = dv[i].v[j];
      M(i, j) = dv[i].v[n + j];
    }
  }
  const Mat<J, m, n> Wj = sys.template omega<J>(qj);
  Mat<double, m, n> W;
  Vec<double, m> wdot = Vec<double, m>::Zero();  // d(omega(q) v)/dq . v
  for (int a = 0; a < m; ++a) {
    for (int j = 0; j < n; ++j) W(a, j) = Wj(a, j).a;
    for (int k = 0; k < n; ++k) {
      double dk = 0;
      for (int j = 0; j < n; ++j) dk += Wj(a, j).v[k] * v[j];
      wdot[a] += dk * v[k];
    }
  }
  Mat<double, n + m, n + m> K = Mat<double, n + m, n + m>::Zero();
  K.template topLeftCorner<n, n>() = M;
  K.template topRightCorner<n, m>() = -W.transpose();
  K.template bottomLeftCorner<m, n>() = W;
  Vec<double, n + m> b;
  b.template head<n>() = f - C * v;
  b.template tail<m>() = -wdot;
  const Vec<double, n + m> x = K.fullPivLu().solve(b);
  if (lambda) *lambda = x.template tail<m>();
  return x.template head<n>();
}

}  // namespace nhi
