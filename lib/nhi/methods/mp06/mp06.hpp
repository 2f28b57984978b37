// McLachlan & Perlmutter's reversible nonholonomic integrator ("Integrators for
// nonholonomic mechanical systems", J. Nonlinear Sci. 16, 2006, eq. 4.18): a
// RATTLE-type method on (q, p) that holds the velocity constraint exactly at
// the grid points.  One step (q0, p0) -> (q1, p1) with multipliers lambda:
//     q_half = q0 + (h/2) V(q0, p0)
//     p1     = p0 + (h/2) [F(q_half, p0) + F(q_half, p1)] + h omega(q_half)^T lambda
//     q1     = q_half + (h/2) V(q1, p1)
//     omega(q1) V(q1, p1) = 0
// with V, F from hamiltonian.hpp.  Symmetric (the step of -h from (q1, p1)
// returns to (q0, p0): the adjoint exchanges the two half steps, and the
// multiplier of the reverse step is the same lambda) and of order 2.
//
// The same equations in three forms (NewtonSolver, solver.hpp):
//  - phase form (Mp06PhaseProblem): unknowns y = (q1, p1), multipliers lambda;
//    the constraint force h omega(q_half)^T lambda has fixed rows during the step
//    (q_half is explicit), which is the saddle-point form the solver exploits;
//  - velocity form (Mp06Problem, what the stepper solves in general): unknowns
//    v1 = V(q1, p1) and lambda, with q1 = q_half + (h/2) v1 and
//    p1 = dL/dqdot(q1, v1) explicit, half the unknowns of the phase form;
//  - separable systems (L = 1/2 v^T M v - U(q), M constant): F does not depend
//    on p and V not on q, so p1 and q1 are explicit, affine in lambda, and the
//    step is m equations omega(q1(lambda)) V(p1(lambda)) = 0 in lambda alone.
// tests/test_mp06.cpp checks that the three forms give the same step,
// and the separable one against a closed-form step of the particle.
#pragma once

#include <array>
#include <string>
#include <type_traits>

#include "nhi/methods/composition.hpp"
#include "nhi/methods/constraint_rows.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

// Phase form, the equations as stated: y = (q1, p1), lambda; rows (q
// equation, p equation, constraint).  The stepper solves the velocity form
// below; tests/test_mp06.cpp checks that the two give the same step.
template <class S>
struct Mp06PhaseProblem {
  static constexpr int n = S::n, m = S::m;
  static constexpr int ny = 2 * n, nl = m;
  using VecN = Vec<double, n>;

  const S& sys;
  double h;
  VecN p0, q_half, F0;      // F0 = F(q_half, p0)
  Mat<double, ny, nl> W_t;  // [0; h omega(q_half)^T]

  Mp06PhaseProblem(const S& s, double hh, const VecN& q0, const VecN& p) : sys(s), h(hh), p0(p) {
    q_half = q0 + 0.5 * h * velocity<S, double>(sys, q0, p0);
    F0 = force<S, double>(sys, q_half, p0);
    W_t.setZero();
    W_t.template bottomRows<n>() = h * sys.template omega<double>(q_half).transpose();
  }

  const Mat<double, ny, nl>& Wt() const { return W_t; }

  Vec<double, ny> y_scale(const Vec<double, ny>& y) const {
    Vec<double, ny> s;
    s << q_half.cwiseAbs() + y.template head<n>().cwiseAbs(), p0.cwiseAbs() + y.template tail<n>().cwiseAbs();
    return s;
  }

  template <class T>
  void residual(const Vec<T, ny>& y, const Vec<T, nl>& lambda, Vec<T, ny + nl>* r, Vec<double, ny + nl>* terms) const {
    const Vec<T, n> q1 = y.template head<n>(), p1 = y.template tail<n>();
    const Vec<T, n> v1 = velocity(sys, q1, p1);
    const Vec<T, n> F1 = force(sys, Vec<T, n>(q_half.template cast<T>()), p1);
    const Mat<T, m, n> W1 = sys.template omega<T>(q1);
    for (int i = 0; i < n; ++i) {
      (*r)[i] = q1[i] - cst<T>(q_half[i]) - cst<T>(0.5 * h) * v1[i];  // q1 = q_half + (h/2) V(q1, p1)
      T fc = cst<T>(0.0);
      double fscale = 0;
      for (int a = 0; a < m; ++a) {
        fc += cst<T>(W_t(n + i, a)) * lambda[a];
        fscale += std::abs(W_t(n + i, a) * value_of(lambda[a]));
      }
      // p1 = p0 + (h/2)(F(q_half, p0) + F(q_half, p1)) + h omega(q_half)^T lambda
      (*r)[n + i] = p1[i] - cst<T>(p0[i]) - cst<T>(0.5 * h) * (cst<T>(F0[i]) + F1[i]) - fc;
      if (terms) {
        (*terms)[i] = std::abs(value_of(q1[i])) + std::abs(q_half[i]) + std::abs(0.5 * h * value_of(v1[i]));
        (*terms)[n + i] = std::abs(value_of(p1[i])) + std::abs(p0[i]) +
                          std::abs(0.5 * h) * (std::abs(F0[i]) + std::abs(value_of(F1[i]))) + fscale;
      }
    }
    velocity_constraint_rows(W1, v1, ny, r, terms);  // omega(q1) V(q1, p1) = 0
  }

  // q1, p1 from the solution.
  void finish(const Vec<double, ny>& y, const Vec<double, nl>&, VecN* q1, VecN* p1) const {
    *q1 = y.template head<n>();
    *p1 = y.template tail<n>();
  }
  Vec<double, ny> guess(const VecN& q0, const Vec<double, nl>& lambda) const {
    Vec<double, ny> y;
    const VecN p1 = p0 + h * F0 + W_t.template bottomRows<n>() * lambda;
    y << q_half + 0.5 * h * velocity<S, double>(sys, q_half, p1), p1;
    (void)q0;
    return y;
  }
};

// General form in the velocity (what the stepper solves for a system that is
// not separable).  Take y = v1 = V(q1, p1) as the unknown: the q equation is
// then q1 = q_half + (h/2) v1, and since V inverts the Legendre map,
// p1 = dL/dqdot(q1, v1); both explicit, so the step is n + m equations in v1
// and lambda:
//     dL/dqdot(q1, v1) - p0 - (h/2) [F(q_half, p0) + F(q_half, p1)] - h omega(q_half)^T lambda = 0
//     omega(q1) v1 = 0,      q1 = q_half + (h/2) v1,  p1 = dL/dqdot(q1, v1)
// the saddle-point form of NewtonSolver with the fixed Wt = h omega(q_half)^T,
// as the DLA's (dla.hpp).  n unknowns y instead of the phase form's 2n, so Jets of n
// derivatives instead of 2n and, for n, m <= 4, the closed-form Schur solve
// instead of pivoted LU of the whole matrix (on contact_oscillator_nr that
// LU and the Jet evaluation are most of the phase form's step).  The
// unknown is v1, not q1: with q1, v1 = 2 (q1 - q_half) / h
// would carry the round-off of q1 times 2/h into p1 and lambda at small h.
template <class S>
struct Mp06Problem {
  static constexpr int n = S::n, m = S::m;
  static constexpr int ny = n, nl = m;
  using VecN = Vec<double, n>;

  const S& sys;
  double h;
  VecN q0, p0, q_half, F0;  // F0 = F(q_half, p0)
  Mat<double, ny, nl> W_t;  // h omega(q_half)^T

  Mp06Problem(const S& s, double hh, const VecN& q, const VecN& p) : sys(s), h(hh), q0(q), p0(p) {
    q_half = q0 + 0.5 * h * velocity<S, double>(sys, q0, p0);
    F0 = force<S, double>(sys, q_half, p0);
    W_t = h * sys.template omega<double>(q_half).transpose();
  }

  const Mat<double, ny, nl>& Wt() const { return W_t; }

  // Root following (solver.hpp): the same step at h2; as h -> 0 the root
  // tends to v1 = V(q0, p0), with a multiplier of the size of a force.
  Mp06Problem at_step(double h2) const { return Mp06Problem(sys, h2, q0, p0); }
  void small_step_start(double ratio, Vec<double, ny>* v1, Vec<double, nl>*) const {
    const VecN v0 = velocity<S, double>(sys, q0, p0);
    *v1 = v0 + ratio * (*v1 - v0);
  }

  Vec<double, ny> y_scale(const Vec<double, ny>& v1) const { return v1.cwiseAbs(); }

  template <class T>
  void residual(const Vec<T, ny>& v1, const Vec<T, nl>& lambda, Vec<T, ny + nl>* r, Vec<double, ny + nl>* terms) const {
    Vec<T, n> q1;
    for (int i = 0; i < n; ++i) q1[i] = cst<T>(q_half[i]) + scale(v1[i], 0.5 * h);
    Vec<T, n> Lq, p1;
    lagrangian_partials(sys, q1, v1, &Lq, &p1);  // p1 = dL/dqdot(q1, v1)
    const Vec<T, n> F1 = force(sys, Vec<T, n>(q_half.template cast<T>()), p1);
    const Mat<T, m, n> W1 = sys.template omega<T>(q1);
    for (int i = 0; i < n; ++i) {
      T fc = cst<T>(0.0);
      double fscale = 0;
      for (int a = 0; a < m; ++a) {
        fc += cst<T>(W_t(i, a)) * lambda[a];
        fscale += std::abs(W_t(i, a) * value_of(lambda[a]));
      }
      // p1 = p0 + (h/2)(F(q_half, p0) + F(q_half, p1)) + h omega(q_half)^T lambda
      (*r)[i] = p1[i] - cst<T>(p0[i]) - cst<T>(0.5 * h) * (cst<T>(F0[i]) + F1[i]) - fc;
      if (terms)
        (*terms)[i] = std::abs(value_of(p1[i])) + std::abs(p0[i]) +
                      std::abs(0.5 * h) * (std::abs(F0[i]) + std::abs(value_of(F1[i]))) + fscale;
    }
    velocity_constraint_rows(W1, v1, ny, r, terms);  // omega(q1) V(q1, p1) = 0
  }

  // (q1, p1) from the solution by the phase form's own equations, one
  // explicit pass: p1 from the momentum equation, with F at the Legendre
  // momentum dL/dqdot(qv, v1), then q1 = q_half + (h/2) V(qv, p1), where
  // qv = q_half + (h/2) v1 is the velocity form's q1.  Changes
  // of round-off size, but taking p1 = dL/dqdot(q1, v1) itself biases the
  // energy (contact_oscillator_nr, mp06 + order 6 at small h); with this pass
  // the energy drifts no more than with the phase form's solve
  // (tests/test_mp06.cpp, Mp06.VelocityFormKeepsThePhaseFormEnergyRoundOff).
  void finish(const Vec<double, ny>& v1, const Vec<double, nl>& lambda, VecN* q1, VecN* p1) const {
    const VecN qv = q_half + 0.5 * h * v1;
    *p1 = p0 + 0.5 * h * (F0 + force<S, double>(sys, q_half, momentum(sys, qv, v1))) + W_t * lambda;
    *q1 = q_half + 0.5 * h * velocity<S, double>(sys, qv, *p1);
  }
  // The phase form's start: p1 by an explicit step with the last multipliers,
  // v1 = V(q_half, p1).
  Vec<double, ny> guess(const VecN&, const Vec<double, nl>& lambda) const {
    return velocity<S, double>(sys, q_half, VecN(p0 + h * F0 + W_t * lambda));
  }
};

// Separable form: y = lambda (m unknowns), no saddle part.  V = M^-1 p by
// the stepper's SeparableVelocity, or IdentityVelocity where M^-1 is the
// identity (hamiltonian.hpp).
template <class S, class Velocity = SeparableVelocity<S>>
struct Mp06SeparableProblem {
  static constexpr int n = S::n, m = S::m;
  static constexpr int ny = m, nl = 0;
  using VecN = Vec<double, n>;

  const S& sys;
  const Velocity& V;
  double h;
  VecN q0, p0;
  VecN q_half, p_base;      // p1 = p_base + h omega(q_half)^T lambda, p_base = p0 + h F(q_half)
  Mat<double, n, m> hWt;    // h omega(q_half)^T
  Mat<double, ny, nl> W_t;  // empty

  Mp06SeparableProblem(const S& s, const Velocity& vel, double hh, const VecN& q, const VecN& p)
      : sys(s), V(vel), h(hh), q0(q), p0(p) {
    q_half = q0 + 0.5 * h * V(p0);
    // F(q_half, p) does not depend on p here, so (h/2)(F(q_half, p0) + F(q_half, p1)) = h F(q_half, p0).
    p_base = p0 + h * force<S, double>(sys, q_half, p0);
    hWt = h * sys.template omega<double>(q_half).transpose();
  }

  const Mat<double, ny, nl>& Wt() const { return W_t; }
  Vec<double, ny> y_scale(const Vec<double, ny>& lambda) const { return lambda.cwiseAbs(); }

  // Root following (solver.hpp): the same step at h2; the unknown, the
  // multiplier, has the size of a force and a finite limit as h -> 0.
  Mp06SeparableProblem at_step(double h2) const { return Mp06SeparableProblem(sys, V, h2, q0, p0); }
  void small_step_start(double, Vec<double, ny>*, Vec<double, nl>*) const {}

  template <class T>
  void state(const Vec<T, m>& lambda, Vec<T, n>* q1, Vec<T, n>* p1, Vec<T, n>* v1) const {
    *p1 = p_base.template cast<T>() + hWt.template cast<T>() * lambda;
    *v1 = V(*p1);  // V does not depend on q
    *q1 = q_half.template cast<T>() + cst<T>(0.5 * h) * *v1;
  }

  template <class T>
  void residual(const Vec<T, ny>& lambda, const Vec<T, nl>&, Vec<T, ny + nl>* r, Vec<double, ny + nl>* terms) const {
    Vec<T, n> q1, p1, v1;
    state(lambda, &q1, &p1, &v1);
    const Mat<T, m, n> W1 = sys.template omega<T>(q1);
    velocity_constraint_rows(W1, v1, 0, r, terms);  // omega(q1) V(q1, p1) = 0
  }

  // The rounding of q1 (NewtonSolver's rounding_terms, solver.hpp): row a
  // gets sum_k |d(omega_a(q1) v1)/dq1_k| |q1_k|, by one Jet evaluation of
  // omega.  q1 = q_half + (h/2) V(p1) carries a relative eps of its own that
  // its derivative in lambda, of size h^2 |M^-1 omega^T|, does not show: on
  // the sleigh running straight at theta ~ 3.09, sin(theta) ~ 0.05 takes
  // theta's last bit (~4e-16) as a relative error of ~1e-14 while the row's
  // two terms (0.087 each) cancel, so a start from the last multiplier can
  // sit at ~20 eps of the terms, above newton()'s 16 eps, and without these
  // terms would cost an iteration a stage that cannot improve it (Suzuki 5's
  // stages 4 and 5; tests/test_mp06.cpp, Mp06.SleighResidualFloorIsTheRoundingOfQ1).
  //   Only the coordinates the multiplier moves count (V(h omega(q_half)^T
  // e_a)_k != 0 for some a): one it does not move is a fixed input of the
  // solve, like q_half, whose rounding Newton can solve around, and counting
  // it would accept residuals far from round-off (where omega reads such a
  // coordinate and it is large).  Where the step is explicit none counts.
  //   The rounding of p1 is left out: V is linear in p, so with a diagonal
  // M^-1 it is that of v1, which the terms |omega_aj v1_j| already are
  // (with a non-diagonal one it is not covered: the test is then stricter,
  // not looser).
  void rounding_terms(const Vec<double, ny>& lambda, const Vec<double, nl>&, Vec<double, ny + nl>* extra) const {
    extra->setZero();
    std::array<bool, n> moved{};
    bool any = false;
    for (int a = 0; a < m; ++a) {
      const VecN d = V(VecN(hWt.col(a)));
      for (int k = 0; k < n; ++k)
        if (d[k] != 0) moved[k] = any = true;
    }
    if (!any) return;
    VecN q1, p1, v1;
    state<double>(lambda, &q1, &p1, &v1);
    using J = ceres::Jet<double, n>;
    Vec<J, n> qj;
    for (int k = 0; k < n; ++k) qj[k] = J(q1[k], k);
    const Mat<J, m, n> W1 = sys.template omega<J>(qj);
    for (int a = 0; a < m; ++a) {
      J c = J(0.0);
      for (int j = 0; j < n; ++j) c += W1(a, j) * v1[j];
      double e = 0;
      for (int k = 0; k < n; ++k)
        if (moved[k]) e += std::abs(c.v[k]) * std::abs(q1[k]);
      (*extra)[a] = e;
    }
  }
};

// The stateful mp06 stepper (stepper.hpp), lag 0.  kSeparableForm asks for
// the reduced solve (default: when the system declares it separable); it
// applies only where the system is separable (kSeparable), so that both forms
// exist for every system and the library compiles both.  The bodies of the
// members that solve or differentiate (the constructor, explicit_structure,
// start, map, step, sample, phase) are in mp06_body.hpp.
template <class S, bool kSeparableForm = is_separable<S>::value>
class Mp06Stepper {
  static_assert(check_system<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr bool kSeparable = kSeparableForm && is_separable<S>::value;
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, m>;

  // allow_explicit = false always solves by Newton (tests compare the two).
  explicit Mp06Stepper(const S& sys, SolverOptions options = {}, bool allow_explicit = true);
  const S& system() const { return sys_; }

  // Is the step explicit (one m x m solve in lambda)?  Found by autodiff at two
  // states; the reasoning is at the definition (mp06_body.hpp).
  static bool explicit_structure(const S& sys);
  bool is_explicit() const { return explicit_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 2;
    t.symmetric = true;
    t.symmetric_in_phase = true;
    t.holds_velocity_constraint = true;
    t.implicit = true;
    return t;
  }

  // Start from p0 = dL/dqdot(q0, v0).
  void start(const VecN& q0, const VecN& v0);

  // On a separable system Newton's only unknown is the multiplier (the
  // explicit step, where it applies, needs no start at all), so the
  // multiplier the next step starts from is its whole starting iterate: a
  // composition sets it per stage (Composed, composition.hpp).
  static constexpr bool starts_from_multiplier = kSeparable;
  void guess_lambda(const VecM& l) { lambda_ = l; }

  // One step (q0, p0) -> (q1, p1) of size h; lambda holds the starting guess and gets the multiplier.
  StepSummary map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1, VecM* lambda) const;

  // map()'s separable form and its explicit solve, called only from map():
  // member templates, which an explicit instantiation of the class does not
  // compile, so they stay defined here and are compiled where map() is.
  template <class Velocity>
  StepSummary map_separable(const Velocity& V, double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1,
                            VecM* lambda) const {
    StepSummary s;
    const Mp06SeparableProblem<S, Velocity> prob(sys_, V, h, q0, p0);
    if (explicit_ && explicit_map(prob, q1, p1, lambda, &s)) {
      // Linear equations in the multiplier: their one root is the continued one.
      if (options_.follows_roots()) s.root = RootCheck::kContinued;
      return s;
    }
    VecM y = *lambda;
    Vec<double, 0> none;
    s = NewtonSolver<Mp06SeparableProblem<S, Velocity>>(prob, options_).solve(&y, &none);
    if (s.ok()) {
      VecN v1;
      prob.state(y, q1, p1, &v1);
      *lambda = y;
    }
    return s;
  }

  // The explicit step (see explicit_structure()): with lambda = 0, q1* and
  // v1* = V(p_base); omega(q1*) = omega(q1) for every lambda, and V is linear in
  // p, so omega(q1*) [v1* + sum_a lambda_a V(h omega(q_half)^T e_a)] = 0 is an
  // m x m linear system.  The result is checked by one evaluation of the
  // residual; if it is not within tolerance the caller falls back to Newton.
  template <class Velocity>
  bool explicit_map(const Mp06SeparableProblem<S, Velocity>& prob, VecN* q1, VecN* p1, VecM* lambda,
                    StepSummary* s) const {
    VecN qs, ps, vs;
    prob.template state<double>(VecM::Zero(), &qs, &ps, &vs);
    const Mat<double, m, n> W1 = sys_.template omega<double>(qs);
    Mat<double, m, m> A;
    for (int a = 0; a < m; ++a) A.col(a) = W1 * prob.V(VecN(prob.hWt.col(a)));
    // Closed-form m x m inverse (m <= 4); a nearly singular A goes to Newton.
    const double det = A.determinant();
    double amax = A.cwiseAbs().maxCoeff(), scale = 1;
    for (int a = 0; a < m; ++a) scale *= amax;
    if (!(std::abs(det) > 1e-12 * scale)) return false;
    const VecM l = A.inverse() * VecM(-W1 * vs);
    VecN qn, pn, vn;
    prob.template state<double>(l, &qn, &pn, &vn);
    // The residual omega(q1) V(p1).  With a hand-written V, omega(q1) is W1
    // bit for bit: the coordinates omega reads get exact zeros from the
    // constraint force, p_i + 0, and the same products with M^-1 (that is
    // what the structural probe found).  A system without one is not relied
    // on to that: there omega(q1) is evaluated.
    Mat<double, m, n> W;
    if constexpr (has_velocity<S, double>::value) {
      W = W1;
    } else {
      W = sys_.template omega<double>(qn);
    }
    VecM r, terms;
    velocity_constraint_rows(W, vn, 0, &r, &terms);
    double rel = 0;
    for (int a = 0; a < m; ++a) {
      if (!std::isfinite(r[a])) return false;
      rel = std::max(rel, r[a] == 0 ? 0.0 : std::abs(r[a]) / std::max(terms[a], std::numeric_limits<double>::min()));
    }
    if (!(rel <= options_.tolerance)) return false;
    *q1 = qn;
    *p1 = pn;
    *lambda = l;
    s->status = SolveStatus::kConverged;
    s->iterations = 0;   // a direct solve
    s->evaluations = 1;  // the residual check
    s->relative_residual = rel;
    return true;
  }

  StepSummary step(double h);

  // Point k: q_k, v_k = V(q_k, p_k) (omega(q_k) v_k = 0 to round-off), p_k, the
  // multiplier of the step that arrived at k (0 at k = 0), and omega(q_k) v_k
  // as the constraint the method holds.
  void sample(Sample<n, m>* s) const;

  Vec<double, 2 * n> phase() const;
  const VecM& lambda() const { return lambda_; }

 private:
  S sys_;
  // V = M^-1 p for the separable forms (nothing otherwise).
  struct NoVelocity {
    explicit NoVelocity(const S&) {}
  };
  std::conditional_t<kSeparable, SeparableVelocity<S>, NoVelocity> vel_;
  SolverOptions options_;
  bool explicit_ = false;
  VecN q_ = VecN::Zero(), p_ = VecN::Zero();
  VecM lambda_ = VecM::Zero();
  long steps_ = 0;
};

// The method table's entry (methods.hpp): "mp06", symmetric, so composable.
struct Mp06Method {
  static constexpr const char* name = "mp06";
  static constexpr bool adaptive = false;
  static std::vector<MethodKey> keys() { return {}; }
  static bool symmetric(const MethodSpec&) { return true; }  // so it composes (composition.hpp)
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 1.5;
  static std::string label(const MethodSpec&) { return name; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    const SolverOptions opt = solver_options(spec);
    return with_composition(Mp06Stepper<S>(sys, opt), spec.composition, f);
  }
  static std::vector<StudyEntry> study_entries() {
    return {{spec_of(name), "main", 21},
            {spec_of(name, "triple_jump"), "main", 22},
            {spec_of(name, "suzuki5"), "main", 23},
            {spec_of(name, "order6"), "main", 24}};
  }
};

}  // namespace nhi
