// The discrete Euler-Poincare-Suslov step with the Cayley retraction: a free
// rigid body with a left-invariant constraint <a, Omega> = 0 (the Suslov
// problem, systems/suslov.hpp) stepped on SO(3) itself, in the body frame.
//
// The scheme is the paper's DLA (eq. 6) on the group G = SO(3) with a
// left-invariant discrete Lagrangian and discrete constraint space, as
// Fedorov & Zenkov write the discrete Euler-Poincare-Suslov equations
// ("Discrete nonholonomic LL systems on Lie groups", Nonlinearity 18, 2005:
// R_{k+1} = R_k F_k, L_d = l_d(F_k), F_k in a submanifold S of G) and as
// Garcia-Naranjo & Jimenez discretize the Suslov problem with the Cayley map
// (arXiv 1605.02666, "The geometric discretisation of the Suslov problem: a
// case study of consistency for nonholonomic integrators").  Neither paper's
// text was readable here (only their abstracts), so the equations below are
// derived, not copied, and tests/test_eps.cpp checks them:
//   R_{k+1} = R_k cay(y_k),  cay(y) = (1 - y^/2)^{-1} (1 + y^/2)
//       (on quaternions u_{k+1} = u_k (1, y_k/2) / sqrt(1 + |y_k|^2/4)),
//   L_d(R_k, R_{k+1}) = h l(y_k / h),  l(Omega) = 1/2 Omega^T J Omega,  J = diag(I1, I2, I3),
//   S = { cay(y) : <a, y> = 0 }   (the discrete constraint),
// varied along R_k -> R_k exp(eta_k), eta_k in the constraint space a^perp.
// With dcay^{-1}_y = 1 - y^/2 + y y^T/4 (right-trivialized; Iserles, Munthe-Kaas,
// Norsett & Zanna, Acta Numerica 2000, and Kobilarov & Marsden, IEEE T-RO 2011,
// for so(3)), the trivialized slot derivatives of L_d are
//   D1 L_d = -(1 + y^/2 + y y^T/4) J y / h,    D2 L_d = (1 - y^/2 + y y^T/4) J y / h
// (checked against finite differences on SO(3) when written), and the DLA
// D2 L_d(k-1, k) + D1 L_d(k, k+1) in (a^perp)^0 = span(a) reads
//   (1 + y_k^/2 + y_k y_k^T/4) J y_k / h = M_k + lambda_k a,   <a, y_k> = 0,     (DEPS)
//   M_{k+1} = (1 - y_k^/2 + y_k y_k^T/4) J y_k / h,
// the discrete Euler-Poincare-Suslov equations in the Cayley retraction
// (Bou-Rabee & Marsden's discrete Euler-Poincare equations with retraction,
// Found. Comput. Math. 9, 2009, with the constraint force lambda_k a).
//   Which discrete constraint.  The constraint is on the Cayley parameter y_k
// of the increment F_k = R_k^T R_{k+1}.  For F_k = cay(y) = exp(xi) the
// rotation vector xi, the Cayley parameter y = 2 tan(|xi|/2) xi/|xi| and the
// axial vector of the skew part (F - F^T)/2 are all parallel, so <a, y> = 0,
// <a, xi> = 0 and "the discrete body angular velocity is orthogonal to a"
// name one set S: Fedorov & Zenkov's, and also the one dla_group (exp chart,
// omega_d at the midpoint) holds on this scene.  The other natural choice,
// the constraint on the node velocity J^{-1} M_{k+1} (which makes y_k depend
// on the next step), is not implemented.
//   The state and the velocity.  M_k matters only modulo a (lambda_k absorbs
// that component), so the state is (R_k, Omega_k) with Omega_k in a^perp, the
// nonholonomic Legendre transform of M_k:
//   Omega_k = J^{-1} (M_k + mu_k a),  mu_k = -<a, J^{-1} M_k> / <a, J^{-1} a>,
// and each step starts from M_k = J Omega_k (Omega_0 from the given velocity).
// So <a, Omega_k> = 0 at every point (to round-off) and the one-step map
// (R_k, Omega_k) -> (R_{k+1}, Omega_{k+1}) is self-adjoint in phase: a step
// of h then one of -h gives y' = -y_k, lambda' = 0, M = J Omega_k + lambda_k a
// and so Omega_k again; and it commutes with Omega -> -Omega (rho-reversible).
// L_d and S are symmetric (cay(-y) = cay(y)^{-1}, l even), so the order is
// even: 2 (cay^{-1}(exp(h Omega^)) = h Omega + O(h^3)).
//   On the repository's embedding (suslov.hpp): q = p = s u with s = |p_0|
// kept and u a unit quaternion, v = pdot = G(p)^T Omega / 2, Omega = 2 G(p) v
// / s^2 (the unit quaternion's body rate; with |p| = s the embedded motion is
// s times the unit one with this Omega).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

#include "nhi/groups/quaternion.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

// A free rigid body with a left-invariant linear constraint on Omega: a
// system that declares `left_invariant_constraint` and provides inertia() and
// suslov_axis(), on the unit-quaternion embedding (q = p, omega row 0 = p^T).
template <class S, class = void>
struct is_suslov_body : std::false_type {};
template <class S>
struct is_suslov_body<S, std::enable_if_t<S::left_invariant_constraint>>
    : std::bool_constant<S::n == 4 && S::m == 2 && quaternion_at<S>::value == 0 && norm_row_of<S>::value == 0> {};

// The residual of (DEPS) for NewtonSolver: y = y_k, lambda = lambda_k,
//   r = ( (1 + y^/2 + y y^T/4) J y / h - M  - a lambda ,  <a, y> / h ),
// with its closed-form y-Jacobian (the map is a cubic in y):
//   d/dy = ( J + (y^ J - (J y)^)/2 + (y (2 J y)^T + (y^T J y) 1)/4 ) / h.
struct EpsCayleyStepProblem {
  static constexpr int ny = 3, nl = 1;
  Vec<double, 3> J, a, M;  // inertia, constraint vector, M_k
  double h;
  Mat<double, 3, 1> W_t;  // a

  EpsCayleyStepProblem(const Vec<double, 3>& inertia, const Vec<double, 3>& axis, const Vec<double, 3>& m, double hh)
      : J(inertia), a(axis), M(m), h(hh), W_t(axis) {}

  const Mat<double, 3, 1>& Wt() const { return W_t; }
  EpsCayleyStepProblem at_step(double h2) const {
    EpsCayleyStepProblem c = *this;
    c.h = h2;
    return c;
  }
  // As h -> 0, y -> 0 and lambda -> 0 (M = J Omega_k with <a, Omega_k> = 0).
  void small_step_start(double ratio, Vec<double, 3>* y, Vec<double, 1>* lambda) const {
    *y *= ratio;
    *lambda *= ratio;
  }
  // A unit relative change of the rotation: 1 + |y_i|, as dla_group's chart.
  Vec<double, 3> y_scale(const Vec<double, 3>& y) const { return (1.0 + y.array().abs()).matrix(); }

  template <class T>
  void residual(const Vec<T, 3>& y, const Vec<T, 1>& lambda, Vec<T, 4>* r, Vec<double, 4>* terms) const {
    static_assert(std::is_same_v<T, double>, "closed-form Jacobian: residual in double only");
    const Vec<double, 3> Jy = J.cwiseProduct(y), c = 0.5 * y.cross(Jy), d = (0.25 * y.dot(Jy)) * y;
    const Vec<double, 3> f = (Jy + c + d) / h;                     // (1 + y^/2 + y y^T/4) J y / h
    r->template head<3>() = f - M - a * lambda[0];                 // (DEPS), first line
    (*r)[3] = a.dot(y) / h;                                        // <a, y_k> = 0
    if (terms) {
      terms->template head<3>() = ((Jy.cwiseAbs() + c.cwiseAbs() + d.cwiseAbs()) / std::abs(h) + M.cwiseAbs() +
                                   (a * lambda[0]).cwiseAbs());
      (*terms)[3] = a.cwiseProduct(y).cwiseAbs().sum() / std::abs(h);
    }
  }
  void jacobian(const Vec<double, 3>& y, const Vec<double, 1>&, Mat<double, 4, 3>* Jy) const {
    const Vec<double, 3> Jv = J.cwiseProduct(y);
    const double yJy = y.dot(Jv);
    Mat<double, 3, 3> D;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) D(i, j) = 0.5 * y[i] * Jv[j] + (i == j ? J[i] + 0.25 * yJy : 0.0);
    // + (y^ J - (J y)^) / 2
    const Mat<double, 3, 3> yh = hat(y), Jyh = hat(Jv);
    for (int j = 0; j < 3; ++j) D.col(j) += 0.5 * (yh.col(j) * J[j] - Jyh.col(j));
    Jy->template topRows<3>() = D / h;
    Jy->row(3) = a.transpose() / h;
  }
  static Mat<double, 3, 3> hat(const Vec<double, 3>& x) {
    Mat<double, 3, 3> m;
    m << 0, -x[2], x[1], x[2], 0, -x[0], -x[1], x[0], 0;
    return m;
  }
};

// The stepper (stepper.hpp), lag 0: each step reports its end point.  On a
// system that is not a Suslov body (is_suslov_body) it compiles, so that the
// method table can name it for every scene (and `nhi list` read its traits),
// and every step fails (kSolve) saying why.
// Reported: q_k = s u_k, v_k = G(q_k)^T Omega_k / 2 (v_0 as given), p_k =
// dL/dqdot(q_k, v_k) (the embedding's momentum of that velocity; phase() is
// (q_k, p_k)), lambda row 1 the impulse lambda_k of the step that reached k,
// discrete_constraint row 1 <a, y_k>/h of that step and row 0 (|q_k|^2 -
// |q_{k-1}|^2)/2h.
template <class S>
class EpsCayleyStepper {
 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  static constexpr bool kApplies = is_suslov_body<S>::value;
  using VecN = Vec<double, n>;
  using Vec3 = Vec<double, 3>;
  using Problem = EpsCayleyStepProblem;

  EpsCayleyStepper(const S& sys, SolverOptions options = {}) : sys_(sys), options_(options) {
    if constexpr (kApplies) {
      J_ = sys.inertia();
      a_ = sys.suslov_axis();
    }
  }

  const S& system() const { return sys_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 2;
    t.symmetric = true;
    t.symmetric_in_phase = true;  // in (R, Omega): see the top of this file
    t.holds_velocity_constraint = true;
    t.implicit = true;
    return t;
  }

  void start(const VecN& q0, const VecN& v0) {
    q0_ = q0;
    v0_ = v0;
    if constexpr (kApplies) {
      s_ = q0.norm();
      u_ = q0 / s_;
      Omega_ = project(Vec3(2.0 * quaternion::G<double>(q0, v0) / (s_ * s_)));
    }
    y_ = y_prev_ = Vec3::Zero();
    lambda_ = 0;
    steps_ = 0;
    h_ = h_prev_ = 0;
    norm_rate_ = 0;
  }

  // One step: (DEPS) solved for (y_k, lambda_k) (eps_cayley_body.hpp).
  StepSummary step(double h);

  void sample(Sample<n, m>* s) const {
    s->q = q();
    s->v = v();
    s->has_p = true;
    s->p = momentum(sys_, s->q, s->v);
    s->lambda.setZero();
    s->discrete_constraint.setZero();
    if constexpr (kApplies) {
      if (steps_ > 0) {
        s->lambda[1] = lambda_;
        s->discrete_constraint[0] = norm_rate_;
        s->discrete_constraint[1] = a_.dot(y_) / h_;
      }
    }
  }

  Vec<double, 2 * n> phase() const {
    Vec<double, 2 * n> z;
    z << q(), momentum(sys_, q(), v());
    return z;
  }

  // The body angular velocity Omega_k (the unit quaternion's) and the last increment y_k.
  const Vec3& body_rate() const { return Omega_; }
  const Vec3& increment() const { return y_; }

 private:
  VecN q() const {
    if constexpr (kApplies) {
      return steps_ == 0 ? q0_ : VecN(s_ * u_);
    } else {
      return q0_;
    }
  }
  VecN v() const {
    if constexpr (kApplies) {
      if (steps_ == 0) return v0_;
      return quaternion::Gt<double>(q(), Vec3(0.5 * Omega_));
    } else {
      return v0_;
    }
  }
  // The nonholonomic Legendre transform: J^{-1}(M + mu a) in a^perp.
  Vec3 project(const Vec3& Om) const {  // Om = J^{-1} M
    const Vec3 Ia = a_.cwiseQuotient(J_);
    return Om - (a_.dot(Om) / a_.dot(Ia)) * Ia;
  }

  S sys_;
  SolverOptions options_;
  Vec3 J_ = Vec3::Ones(), a_ = Vec3::UnitZ();
  VecN q0_ = VecN::Zero(), v0_ = VecN::Zero();
  Vec<double, 4> u_ = Vec<double, 4>(1, 0, 0, 0);
  double s_ = 1;
  Vec3 Omega_ = Vec3::Zero(), y_ = Vec3::Zero(), y_prev_ = Vec3::Zero();
  double lambda_ = 0, h_ = 0, h_prev_ = 0, norm_rate_ = 0;
  long steps_ = 0;
};

// The method table's entry (methods.hpp): "eps_cayley".  No keys of its own;
// it does not compose yet.  Studied on the Suslov bodies only (is_suslov_body).
struct EpsCayleyMethod {
  static constexpr const char* name = "eps_cayley";
  static constexpr bool adaptive = false;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 1.0;
  static std::string label(const MethodSpec&) { return "eps-cayley"; }
  static bool symmetric(const MethodSpec&) { return false; }  // (self-adjoint, but no composition yet)
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    EpsCayleyStepper<S> st(sys, solver_options(spec));
    return f(st);
  }
  template <class S>
  static constexpr bool studied_on() {
    return is_suslov_body<S>::value;
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", 85}}; }
};

}  // namespace nhi
