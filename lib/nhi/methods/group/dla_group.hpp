// The paper's DLA on a Lie group through its varying chart (Remark 4.2): for
// a configuration q = (x, p) with x in a vector space and p a unit quaternion
// (a rigid body's orientation, systems/ that declare `orientation`, its first coordinate), the chart
// at q_k is phi_k(x, p) = (x - x_k, log(p_k^{-1} p)) (Upsilon(g) = L_{g^{-1}},
// phi_0 = exp^{-1}; the paper uses it in section 5.3.3).  A step is the chart
// increment y = phi_k(q_{k+1}) = (dx, xi), q_{k+1} = (x_k + dx, p_k exp(xi)),
// and with the alpha rule (eqs. 9, 13) in that chart
//     L_d(q_k, q_{k+1})      = h L(q_a, v_a)
//     omega_d(q_k, q_{k+1})  = omega(q_a) v_a
//     q_a = (x_k + a dx, p_k exp(a xi)),   v_a = (dx/h, (1/2) p_k exp(a xi) (0, xi/h))
// (the chart's inverse maps the straight line a -> a y to these, and its
// velocity y/h to v_a: exp(a xi) commutes with xi).  The DLA equations
// (eq. 6) are taken in the left trivialization, variations q -> q exp(eta):
//     P_k + D1 L_d(q_k, q_{k+1}) - W(q_k)^T mu_k = 0,    omega_d(q_k, q_{k+1}) = 0,
//     P_{k+1} = D2 L_d(q_k, q_{k+1}),
// with P the trivialized momentum, D1, D2 the trivialized slot derivatives
// and W(q) = omega(q) E(q) the constraint rows on the chart's tangent space
// (E: quaternion.hpp, the identity on x).  The quaternion's norm is no
// constraint here (the step stays on the group), so the system's row for
// p^T pdot = 0 (`norm_row`) is left out of W and omega_d: n - 1 unknowns,
// m - 1 multipliers.  On a system without a quaternion this is the DLA with
// L_d^alpha, omega_d^alpha (eqs. 9, 13), step for step.
//   The map is the DLA's: with alpha = 1/2 self-adjoint in the positions, of
// order 2 (order 1 otherwise), and the chart's midpoint makes L_d exactly the
// Lie-group discrete Lagrangian h l((1/h) log(p_k^{-1} p_{k+1})) of a
// left-invariant l (Moser-Veselov's setting in the exponential chart).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "nhi/groups/quaternion.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

// A x, entry by entry (for a Jet of Jets, see GroupChart::tangent).
template <class T, int r, int c>
inline Vec<T, r> times(const Mat<T, r, c>& A, const Vec<T, c>& x) {
  Vec<T, r> y;
  for (int i = 0; i < r; ++i) {
    y[i] = A(i, 0) * x[0];
    for (int j = 1; j < c; ++j) y[i] += A(i, j) * x[j];
  }
  return y;
}

// The chart of GroupDla: retraction, its inverse and the tangent map.
template <class S>
struct GroupChart {
  static constexpr int n = S::n, m = S::m;
  static constexpr int qi = quaternion_at<S>::value;  // first quaternion coordinate
  static constexpr bool kGroup = qi >= 0;
  static constexpr int ng = kGroup ? n - 1 : n;                      // chart dimension
  static constexpr int nr = norm_row_of<S>::value;                   // the norm's omega row
  static constexpr int mg = kGroup && nr >= 0 ? m - 1 : m;          // multipliers
  static_assert(!kGroup || (qi + 4 <= n), "the quaternion block lies inside q");

  // The chart index j of coordinate block: x coordinates before the
  // quaternion map to j = i, after it to j = i - 1, the quaternion to qi..qi+2.
  template <class T>
  static Vec<T, n> retract(const Vec<T, n>& q, const Vec<T, ng>& y) {
    if constexpr (!kGroup) {
      return q + y;
    } else {
      Vec<T, n> r = q;
      for (int i = 0; i < qi; ++i) r[i] = q[i] + y[i];
      for (int i = qi + 4; i < n; ++i) r[i] = q[i] + y[i - 1];
      const Vec<T, 4> p = q.template segment<4>(qi);
      r.template segment<4>(qi) = quaternion::mul<T>(p, quaternion::exp_map<T>(Vec<T, 3>(y.template segment<3>(qi))));
      return r;
    }
  }
  // The increment from q0 to q1 in q0's chart.
  template <class T>
  static Vec<T, ng> local(const Vec<T, n>& q0, const Vec<T, n>& q1) {
    if constexpr (!kGroup) {
      return q1 - q0;
    } else {
      Vec<T, ng> y;
      for (int i = 0; i < qi; ++i) y[i] = q1[i] - q0[i];
      for (int i = qi + 4; i < n; ++i) y[i - 1] = q1[i] - q0[i];
      const Vec<T, 4> p0 = q0.template segment<4>(qi), p1 = q1.template segment<4>(qi);
      // p0^-1 p1 = p0-bar p1 / |p0|^2: a unit quaternion while |p1| = |p0| (the
      // retraction keeps |p|, so a state off |p| = 1 stays on its own sphere).
      const T s2 = p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2] + p0[3] * p0[3];
      Vec<T, 4> r = quaternion::mul<T>(quaternion::conj<T>(p0), p1);
      for (int i = 0; i < 4; ++i) r[i] = r[i] / s2;
      y.template segment<3>(qi) = quaternion::log_map<T>(r);
      return y;
    }
  }
  // E(q): chart velocities to q's velocities (n x ng).
  // (Written entry by entry: Eigen's Zero(), Identity() and products build a
  // Scalar from an int, which a Jet of Jets does not have.)
  template <class T>
  static Mat<T, n, ng> tangent(const Vec<T, n>& q) {
    Mat<T, n, ng> E;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < ng; ++j) E(i, j) = cst<T>(0.0);
    if constexpr (!kGroup) {
      for (int i = 0; i < n; ++i) E(i, i) = cst<T>(1.0);
    } else {
      for (int i = 0; i < qi; ++i) E(i, i) = cst<T>(1.0);
      for (int i = qi + 4; i < n; ++i) E(i, i - 1) = cst<T>(1.0);
      E.template block<4, 3>(qi, qi) = quaternion::tangent<T>(Vec<T, 4>(q.template segment<4>(qi)));
    }
    return E;
  }
  // omega(q) without the norm's row (mg x n).
  template <class T>
  static Mat<T, mg, n> forms(const S& sys, const Vec<T, n>& q) {
    const Mat<T, m, n> w = sys.template omega<T>(q);
    if constexpr (mg == m) {
      return w;
    } else {
      Mat<T, mg, n> r;
      for (int a = 0, b = 0; a < m; ++a)
        if (a != nr) r.row(b++) = w.row(a);
      return r;
    }
  }
  // The point and velocity at alpha of the step y from q0 (top of this file).
  template <class T>
  static void node(const Vec<T, n>& q0, const Vec<T, ng>& y, double alpha, double h, Vec<T, n>* qa, Vec<T, n>* va) {
    const Vec<T, ng> ya = cst<T>(alpha) * y;
    *qa = retract<T>(q0, ya);
    *va = times<T, n, ng>(tangent<T>(*qa), Vec<T, ng>(y / cst<T>(h)));
  }
};

// L_d and omega_d of the alpha rule in q0's chart, as functions of (q0, y).
template <class S, class T>
inline T group_discrete_lagrangian(const S& sys, double alpha, double h, const Vec<T, S::n>& q0,
                                   const Vec<T, GroupChart<S>::ng>& y) {
  Vec<T, S::n> qa, va;
  GroupChart<S>::template node<T>(q0, y, alpha, h, &qa, &va);
  return cst<T>(h) * sys.template lagrangian<T>(qa, va);
}
template <class S, class T>
inline Vec<T, GroupChart<S>::mg> group_discrete_constraint(const S& sys, double alpha, double h,
                                                             const Vec<T, S::n>& q0,
                                                             const Vec<T, GroupChart<S>::ng>& y) {
  Vec<T, S::n> qa, va;
  GroupChart<S>::template node<T>(q0, y, alpha, h, &qa, &va);
  return times<T, GroupChart<S>::mg, S::n>(GroupChart<S>::template forms<T>(sys, qa), va);
}

// The trivialized slot derivatives at (q0, q0 exp y): D1 varies q0 with q1
// fixed, D2 varies q1 with q0 fixed, each along exp of a chart vector
// (a Jet over the chart's ng directions, at zero).
template <int slot, class S, class T>
inline Vec<T, GroupChart<S>::ng> group_slot(const S& sys, double alpha, double h, const Vec<double, S::n>& q0,
                                            const Vec<T, GroupChart<S>::ng>& y) {
  using C = GroupChart<S>;
  constexpr int n = S::n, ng = C::ng;
  using J = ceres::Jet<T, ng>;
  Vec<J, ng> e, yj;
  for (int i = 0; i < ng; ++i) {
    e[i] = J(cst<T>(0.0), i);
    yj[i] = J(y[i]);
  }
  Vec<J, n> q0j;
  for (int i = 0; i < n; ++i) q0j[i] = cst<J>(q0[i]);
  const Vec<J, n> q1j = C::template retract<J>(q0j, yj);
  J Ld;
  if constexpr (slot == 1) {
    const Vec<J, n> q0e = C::template retract<J>(q0j, e);
    Ld = group_discrete_lagrangian<S, J>(sys, alpha, h, q0e, C::template local<J>(q0e, q1j));
  } else {
    Ld = group_discrete_lagrangian<S, J>(sys, alpha, h, q0j, C::template local<J>(q0j, C::template retract<J>(q1j, e)));
  }
  Vec<T, ng> g;
  for (int i = 0; i < ng; ++i) g[i] = Ld.v[i];
  return g;
}

// The residual of the trivialized eq. (6) at fixed (q_k, P_k), for NewtonSolver:
// y the chart increment, lambda = mu.
template <class S>
struct GroupDlaStepProblem {
  using C = GroupChart<S>;
  static constexpr int n = S::n, ng = C::ng, mg = C::mg;
  static constexpr int ny = ng, nl = mg;

  const S& sys;
  double alpha;
  double h;
  const Vec<double, n>& q_curr;
  const Vec<double, ng>& P_curr;
  Mat<double, ng, mg> W_t;  // W(q_k)^T = (omega(q_k) E(q_k))^T

  GroupDlaStepProblem(const S& s, double a, double hh, const Vec<double, n>& q, const Vec<double, ng>& P)
      : sys(s), alpha(a), h(hh), q_curr(q), P_curr(P),
        W_t((C::template forms<double>(s, q) * C::template tangent<double>(q)).transpose()) {}

  const Mat<double, ng, mg>& Wt() const { return W_t; }
  GroupDlaStepProblem at_step(double h2) const {
    GroupDlaStepProblem c = *this;
    c.h = h2;
    return c;
  }
  // As h -> 0 the root tends to y = 0 and mu = 0 (both carry the factor h).
  void small_step_start(double ratio, Vec<double, ny>* y, Vec<double, nl>* mu) const {
    *y *= ratio;
    *mu *= ratio;
  }
  // A unit relative change of the configuration: |x| for x, 1 for the quaternion.
  Vec<double, ny> y_scale(const Vec<double, ny>& y) const {
    const Vec<double, n> q1 = C::template retract<double>(q_curr, y);
    Vec<double, ny> s;
    for (int i = 0; i < ny; ++i) {
      const bool rot = C::kGroup && i >= C::qi && i < C::qi + 3;
      const int j = C::kGroup && i >= C::qi + 3 ? i + 1 : i;
      s[i] = rot ? 1.0 + std::abs(y[i]) : std::abs(q_curr[j]) + std::abs(q1[j]);
    }
    return s;
  }

  template <class T>
  void residual(const Vec<T, ny>& y, const Vec<T, nl>& mu, Vec<T, ny + nl>* r, Vec<double, ny + nl>* terms) const {
    const Vec<T, ng> D1 = group_slot<1, S, T>(sys, alpha, h, q_curr, y);
    for (int i = 0; i < ng; ++i) {
      T force = cst<T>(0.0);
      for (int a = 0; a < mg; ++a) force += scale(mu[a], W_t(i, a));
      (*r)[i] = cst<T>(P_curr[i]) + D1[i] - force;  // eq. 6, first line (trivialized)
      if (terms) {
        double f = 0;
        for (int a = 0; a < mg; ++a) f += std::abs(W_t(i, a) * value_of(mu[a]));
        (*terms)[i] = std::abs(P_curr[i]) + std::abs(value_of(D1[i])) + f;
      }
    }
    Vec<T, n> qa, va;
    C::template node<T>(q_curr.template cast<T>(), y, alpha, h, &qa, &va);
    const Mat<T, mg, n> W = C::template forms<T>(sys, qa);
    const Vec<T, mg> wd = times<T, mg, n>(W, va);
    for (int a = 0; a < mg; ++a) {
      (*r)[ng + a] = wd[a];  // eq. 6, second line: omega_d in the chart
      if (terms) {
        double s = 0;
        for (int j = 0; j < n; ++j) s += std::abs(value_of(W(a, j))) * std::abs(value_of(va[j]));
        (*terms)[ng + a] = s;
      }
    }
  }
};

// The stateful stepper (stepper.hpp).  Start: P_0 = E(q_0)^T dL/dqdot(q_0, v_0);
// first guess y = h E(q_0)^+ v_0, then the extrapolation (h/h_k) y_k and the
// last multipliers.  The quaternion is renormalized after each step (its
// norm moves by round-off only).  Reported: v_0 given, v_k = E(q_k) (y_{k-1}
// + y_k)/(h_{k-1} + h_k) (the central difference in q_k's chart; y_{k-1} is
// also the increment back from q_k, since exp(xi) fixes xi), lag 1 as the DLA;
// p_k the embedding covector with E^T p = P_k and none along the norm.
template <class S>
class GroupDlaStepper {
  static_assert(check_system<S>());

 public:
  using C = GroupChart<S>;
  static constexpr int n = S::n, m = S::m, ng = C::ng, mg = C::mg;
  static constexpr int lag = 1;
  using VecN = Vec<double, n>;
  using VecG = Vec<double, ng>;
  using VecL = Vec<double, mg>;
  using Problem = GroupDlaStepProblem<S>;

  GroupDlaStepper(const S& sys, double alpha, SolverOptions options = {})
      : sys_(sys), alpha_(alpha), options_(options) {}

  const S& system() const { return sys_; }
  double alpha() const { return alpha_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = alpha_ == 0.5 ? 2 : 1;
    t.symmetric = alpha_ == 0.5;
    t.symmetric_in_phase = false;  // positions only, as the DLA (dla.hpp)
    t.implicit = true;
    return t;
  }

  void start(const VecN& q0, const VecN& v0) {
    q_prev_ = q_curr_ = q_next_ = q0;
    v0_ = v0;
    P_curr_ = P_next_ = C::template tangent<double>(q0).transpose() * momentum(sys_, q0, v0);
    y_prev_ = y_ = VecG::Zero();
    mu_ = VecL::Zero();
    steps_ = 0;
    h_ = h_prev_ = 0;
  }

  // One step: the solve of the trivialized eq. (6) from the extrapolation
  // (dla_group_body.hpp, compiled for the registered systems in the library).
  StepSummary step(double h);

  void sample(Sample<n, m>* s) const {
    s->q = q_curr_;
    s->v = steps_ == 1 ? v0_ : VecN(C::template tangent<double>(q_curr_) * ((y_prev_ + y_) / (h_prev_ + h_)));
    const Mat<double, n, ng> E = C::template tangent<double>(q_curr_);
    s->has_p = true;
    s->p = E * (E.transpose() * E).ldlt().solve(P_curr_);
    const Vec<double, mg> wd = group_discrete_constraint<S, double>(sys_, alpha_, h_, q_curr_, y_);
    s->lambda.setZero();
    s->discrete_constraint.setZero();
    for (int a = 0, b = 0; a < m; ++a) {
      if (a == C::nr && C::kGroup) {  // the norm: (|q_{k+1}|^2 - |q_k|^2) / 2h
        s->discrete_constraint[a] =
            (q_next_.template segment<4>(C::qi).squaredNorm() - q_curr_.template segment<4>(C::qi).squaredNorm()) /
            (2 * h_);
        continue;
      }
      s->lambda[a] = mu_[b];
      s->discrete_constraint[a] = wd[b++];
    }
  }

  Vec<double, 2 * n> phase() const {
    const Mat<double, n, ng> E = C::template tangent<double>(q_next_);
    Vec<double, 2 * n> z;
    z << q_next_, E * (E.transpose() * E).ldlt().solve(P_next_);
    return z;
  }

 private:
  S sys_;
  double alpha_;
  SolverOptions options_;
  VecN q_prev_ = VecN::Zero(), q_curr_ = VecN::Zero(), q_next_ = VecN::Zero(), v0_ = VecN::Zero();
  VecG P_curr_ = VecG::Zero(), P_next_ = VecG::Zero(), y_ = VecG::Zero(), y_prev_ = VecG::Zero();
  VecL mu_ = VecL::Zero();
  long steps_ = 0;
  double h_ = 0, h_prev_ = 0;
};

}  // namespace nhi

namespace nhi {

// The method table's entry (methods.hpp): "dla_group", the paper's DLA in
// Remark 4.2's varying chart.  Its alpha is the DLA's key (the alpha rule in
// the chart); it does not compose yet.  Studied on the systems with a
// quaternion (the rigid bodies): on the others it is the alpha DLA, step for
// step (tests/test_group.cpp), which the studies already run.
struct GroupDlaMethod {
  static constexpr const char* name = "dla_group";
  static constexpr bool adaptive = false;
  static std::vector<MethodKey> keys() { return {MethodKey::range("alpha", &MethodSpec::alpha, 0.0, 1.0)}; }
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 6.0;
  static std::string label(const MethodSpec& spec) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "dla-group a=%g", spec.alpha);
    return buf;
  }
  static bool symmetric(const MethodSpec&) { return false; }  // (no composition yet)
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    GroupDlaStepper<S> st(sys, spec.alpha, solver_options(spec));
    return f(st);
  }
  template <class S>
  static constexpr bool studied_on() {
    return quaternion_at<S>::value >= 0;
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", 81}}; }
};

}  // namespace nhi
