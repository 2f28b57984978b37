// An energy-preserving nonholonomic scheme from Gonzalez's midpoint discrete
// gradient (O. Gonzalez, "Time integration and discrete Hamiltonian systems",
// J. Nonlinear Sci. 6, 1996, eq. 3.6; the nonholonomic form with the
// codistribution at the midpoint is also odelab's NonHolonomicEnergy).  With
// z = (q, p), zbar = (z0 + z1)/2, dz = z1 - z0 and H from hamiltonian.hpp:
//     gradbar H(z0, z1) = grad H(zbar) + [H(z1) - H(z0) - grad H(zbar) . dz] / |dz|^2  dz
// so that H(z1) - H(z0) = gradbar H . dz exactly; grad H = (-F(q, p), V(q, p)).
// One step solves, for (q1, p1, lambda), with qbar = (q0 + q1)/2:
//     (q1 - q0)/h =  gradbar_p H
//     (p1 - p0)/h = -gradbar_q H + omega(qbar)^T lambda
//     omega(qbar) gradbar_p H = 0
// Then H(z1) - H(z0) = h lambda . omega(qbar) gradbar_p H = 0: the energy is
// preserved to round-off for every h; the velocity constraint holds only in
// the averaged form of the third line.  Symmetric (exchanging z0, z1 and h -> -h
// leaves the equations unchanged) and of order 2.
//
// The endpoint variant (MethodSpec::constraint = "endpoint"; ours, to test
// why the compositions stop at order 4: README "Methods"): the same discrete
// gradient with the constraint at the new grid point.  The constraint force
// then does work, h lambda . omega(qbar) u with u = gradbar_p H, and a step
// along the discrete gradient takes it back:
//     (q1 - q0)/h =  u - kappa g,                 g = gradbar_q H
//     (p1 - p0)/h = -g + omega(qbar)^T lambda - kappa u,
//     omega(q1) V(q1, p1) = 0,                    kappa = lambda . omega(qbar) u / (|g|^2 + |u|^2)
// so that H(z1) - H(z0) = h (lambda . omega(qbar) u - kappa (|g|^2 + |u|^2)) = 0
// exactly, while every grid point lies on the constraint manifold.  On that
// manifold omega(qbar) u = O(h^2), so the correction is O(h^3) and the step of
// order 2; the denominator |gradbar H|^2 vanishes only at equilibria, so the
// map is smooth at the turning points of an oscillation too (turning the force
// instead, omega - (omega u) u^T / |u|^2, divides by |V|^2 and is not: its
// compositions' fitted orders scatter from random states).  Symmetric on the
// manifold as RATTLE is: the first 2n equations are invariant under
// (z0, z1, h) -> (z1, z0, -h), and the reversed step's constraint row holds
// at z0, which is on the manifold.  Its step is plain Newton (a fresh
// Jacobian every iteration) from the midpoint form's step where the
// predictor's passes settle on it (a separable system; O(h^3) from this
// one's), else from the explicit guess, and then one more update from the
// accepted iterate (DiscreteGradientStepper::map_endpoint).
//
// The constraint rows omega(qbar) move with q1, so lambda is one more unknown of
// a plain Newton solve (NewtonSolver with nl = 0, LU of the whole Jacobian).
// On a separable system the midpoint form's step starts from fixed-point
// passes (DiscreteGradientPredictor, discrete_gradient_predictor.hpp), and a
// settled iterate is accepted by a residual check with no derivatives, or
// without it where the check would only confirm it (map_midpoint).
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "nhi/methods/composition.hpp"
#include "nhi/methods/constraint_rows.hpp"
#include "nhi/methods/discrete_gradient/discrete_gradient_predictor.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

template <class S>
struct DiscreteGradientProblem {
  static constexpr int n = S::n, m = S::m;
  static constexpr int ny = 2 * n + m, nl = 0;
  using VecN = Vec<double, n>;

  const S& sys;
  double h;
  VecN q0, p0;
  double H0;
  bool endpoint = false;    // the endpoint variant (above)
  Mat<double, ny, nl> W_t;  // empty: lambda is part of y

  DiscreteGradientProblem(const S& s, double hh, const VecN& q, const VecN& p, bool at_endpoint = false)
      : sys(s), h(hh), q0(q), p0(p), H0(hamiltonian<S, double>(s, q, p)), endpoint(at_endpoint) {}

  const Mat<double, ny, nl>& Wt() const { return W_t; }

  // Root following (solver.hpp): the same step at h2; as h -> 0 the root
  // tends to (q0, p0) with a multiplier of the size of a force.
  DiscreteGradientProblem at_step(double h2) const { return DiscreteGradientProblem(sys, h2, q0, p0, endpoint); }
  void small_step_start(double ratio, Vec<double, ny>* y, Vec<double, nl>*) const {
    y->template head<n>() = q0 + ratio * (y->template head<n>() - q0);
    y->template segment<n>(n) = p0 + ratio * (y->template segment<n>(n) - p0);
  }

  // The endpoint variant's q1 by its move from q0: its constraint row reads
  // q1 through omega(q1), whose change over one ulp of a large |q| (the robot's
  // angles grow without bound) would otherwise set the row's floor far above
  // what the reachable q1 gives (Newton iterates until it stops improving).
  Vec<double, ny> y_scale(const Vec<double, ny>& y) const {
    Vec<double, ny> s;
    if (endpoint)
      s.template head<n>() = (y.template head<n>() - q0).cwiseAbs();
    else
      s.template head<n>() = q0.cwiseAbs() + y.template head<n>().cwiseAbs();
    s.template segment<n>(n) = p0.cwiseAbs() + y.template segment<n>(n).cwiseAbs();
    s.template tail<m>() = y.template tail<m>().cwiseAbs();
    return s;
  }

  // gradbar H(z0, z1) as (gradbar_q, gradbar_p).  With sq, sp (may be null):
  // per component the size of what it adds up, |grad H(zbar)| + |c dz| with c
  // taken at the size of its numerator's terms, |H1| + |H0| + |grad H . dz|
  // (over |dz|^2): the correction's rounding, which sets the floor of every
  // row that contains it (when the velocities in a constraint row vanish
  // together, it is all that is left of that row's size).  *c_out (may be
  // null) gets Gonzalez's coefficient c (0 when dz = 0).
  // Flattened: with T a Jet of the 2n + m unknowns, g++ otherwise stops
  // inlining at its function-growth limit and leaves the Jets' vector updates
  // as calls (on contact_oscillator_nr, whose H is not separable).
  template <class T>
  [[gnu::flatten]] void discrete_gradient(const Vec<T, n>& q1, const Vec<T, n>& p1, Vec<T, n>* Dq, Vec<T, n>* Dp,
                                          VecN* sq = nullptr, VecN* sp = nullptr, T* c_out = nullptr) const {
    const Vec<T, n> qb = cst<T>(0.5) * (q0.template cast<T>() + q1), pb = cst<T>(0.5) * (p0.template cast<T>() + p1);
    const Vec<T, n> gq = -force(sys, qb, pb), gp = velocity(sys, qb, pb);
    const Vec<T, n> dq = q1 - q0.template cast<T>(), dp = p1 - p0.template cast<T>();
    const T den = dq.squaredNorm() + dp.squaredNorm();
    *Dq = gq;
    *Dp = gp;
    if (c_out) *c_out = cst<T>(0.0);
    double cs = 0;
    if (value_of(den) > 0) {  // Gonzalez's correction along dz (eq. 3.6)
      const T H1 = hamiltonian(sys, q1, p1);
      const T c = (H1 - cst<T>(H0) - gq.dot(dq) - gp.dot(dp)) / den;
      *Dq += c * dq;
      *Dp += c * dp;
      if (c_out) *c_out = c;
      double num = std::abs(value_of(H1)) + std::abs(H0);
      for (int i = 0; i < n; ++i)
        num += std::abs(value_of(gq[i]) * value_of(dq[i])) + std::abs(value_of(gp[i]) * value_of(dp[i]));
      cs = num / value_of(den);
    }
    if (sq && sp)
      for (int i = 0; i < n; ++i) {
        (*sq)[i] = std::abs(value_of(gq[i])) + cs * std::abs(value_of(dq[i]));
        (*sp)[i] = std::abs(value_of(gp[i])) + cs * std::abs(value_of(dp[i]));
      }
  }

  template <class T>
  void residual(const Vec<T, ny>& y, const Vec<T, nl>&, Vec<T, ny>* r, Vec<double, ny>* terms) const {
    const Vec<T, n> q1 = y.template head<n>(), p1 = y.template segment<n>(n);
    const Vec<T, m> lambda = y.template tail<m>();
    Vec<T, n> Dq, Dp;
    VecN sq, sp;
    discrete_gradient(q1, p1, &Dq, &Dp, &sq, &sp);
    const Vec<T, n> qb = cst<T>(0.5) * (q0.template cast<T>() + q1);
    const Mat<T, m, n> Wb = sys.template omega<T>(qb);
    const Vec<T, n> fc = Wb.transpose() * lambda;
    // The endpoint variant's correction kappa gradbar H (above; 0 otherwise).
    Vec<T, n> kq = Vec<T, n>::Constant(cst<T>(0.0)), kp = kq;
    double ks = 0;
    if (endpoint) {
      const T gg = Dq.squaredNorm() + Dp.squaredNorm();
      if (value_of(gg) > 0) {
        const T kappa = lambda.dot(Wb * Dp) / gg;
        kq = kappa * Dq;
        kp = kappa * Dp;
        ks = std::abs(value_of(kappa));
      }
    }
    for (int i = 0; i < n; ++i) {
      (*r)[i] = q1[i] - cst<T>(q0[i]) - cst<T>(h) * (Dp[i] - kq[i]);  // (q1 - q0)/h = gradbar_p H
      (*r)[n + i] =
          p1[i] - cst<T>(p0[i]) + cst<T>(h) * (Dq[i] - fc[i] + kp[i]);  // (p1 - p0)/h = -gradbar_q H + omega^T lambda
      if (terms) {
        (*terms)[i] = std::abs(value_of(q1[i])) + std::abs(q0[i]) + std::abs(h) * (sp[i] + ks * sq[i]);
        double fs = 0;
        for (int a = 0; a < m; ++a) fs += std::abs(value_of(Wb(a, i)) * value_of(lambda[a]));
        (*terms)[n + i] = std::abs(value_of(p1[i])) + std::abs(p0[i]) + std::abs(h) * (sq[i] + fs + ks * sp[i]);
      }
    }
    if (endpoint) {  // omega(q1) V(q1, p1) = 0
      const Mat<T, m, n> W1 = sys.template omega<T>(q1);
      velocity_constraint_rows(W1, velocity(sys, q1, p1), 2 * n, r, terms);
      return;
    }
    for (int a = 0; a < m; ++a) {  // omega(qbar) gradbar_p H = 0
      T c = cst<T>(0.0);
      double cs = 0;
      for (int j = 0; j < n; ++j) {
        c += Wb(a, j) * Dp[j];
        cs += std::abs(value_of(Wb(a, j))) * sp[j];
      }
      (*r)[2 * n + a] = c;
      if (terms) (*terms)[2 * n + a] = cs;
    }
  }
};

// The stateful discrete-gradient stepper (stepper.hpp), lag 0: the step
// above, started from the predictor's passes (DiscreteGradientPredictor) or
// the explicit guess.  The bodies of the members that solve or differentiate
// (the constructor, start, map, step, sample, phase) are in
// discrete_gradient_body.hpp.
template <class S>
class DiscreteGradientStepper {
 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, m>;
  using Problem = DiscreteGradientProblem<S>;
  using VecY = Vec<double, Problem::ny>;
  using Predictor = DiscreteGradientPredictor<S>;

  // endpoint: the endpoint variant (above).
  explicit DiscreteGradientStepper(const S& sys, SolverOptions options = {}, bool endpoint = false);
  bool endpoint() const { return endpoint_; }
  const Predictor& predictor() const { return predictor_; }
  // Do the passes see the force exactly (F affine in q; DiscreteGradientPredictor)?
  bool passes_exact_in_force() const { return predictor_.exact_in_force(); }
  // Passes made since construction, those after a Gauss-Seidel first pass
  // included (tests/test_discrete_gradient.cpp counts them).
  long passes_made() const { return predictor_.passes_made(); }
  // Run the residual check on passes that settled by their move too (map();
  // off by default), and count: steps whose passes so settled, and of those,
  // steps the check did not accept unchanged (tests/test_discrete_gradient.cpp;
  // the second count only on a check_settled_passes(true) stepper).
  void check_settled_passes(bool on) { check_settled_ = on; }
  long settled_by_move_steps() const { return settled_by_move_steps_; }
  long settled_checks_failed() const { return settled_checks_failed_; }
  const S& system() const { return sys_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 2;
    t.symmetric = true;
    t.symmetric_in_phase = true;
    t.holds_velocity_constraint = endpoint_;
    t.implicit = true;
    t.preserves_energy = true;
    return t;
  }

  void start(const VecN& q0, const VecN& v0);

  // One step (q0, p0) -> (q1, p1); lambda holds the guess and gets the
  // multiplier.  (Not const: the predictor keeps its caches and counts.)
  StepSummary map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1, VecM* lambda);

  static void unpack(const VecY& y, VecN* q1, VecN* p1, VecM* lambda) {
    *q1 = y.template head<n>();
    *p1 = y.template segment<n>(n);
    *lambda = y.template tail<m>();
  }

  StepSummary step(double h);

  // Point k: q_k, v_k = V(q_k, p_k), p_k, the multiplier and the averaged
  // constraint omega(qbar) gradbar_p H of the step that arrived at k (0 at
  // k = 0; zero to round-off; the endpoint variant's: omega(q_k) v_k).  It is evaluated here, when a point is
  // recorded, not in every step (as the DLA and mp06 do theirs): it costs a
  // second discrete gradient, H(q_k, p_k) and omega.  The same arithmetic
  // either way.
  void sample(Sample<n, m>* s) const;

  Vec<double, 2 * n> phase() const;

 private:
  // An explicit Stoermer-Verlet-like step with the multiplier lambda (second
  // order when lambda is): Newton's start where the passes do not settle.
  VecY explicit_guess(const Problem& prob, const VecM& lambda) const;
  // map() for each form.
  StepSummary map_endpoint(const Problem& prob, VecN* q1, VecN* p1, VecM* lambda);
  StepSummary map_midpoint(const Problem& prob, VecN* q1, VecN* p1, VecM* lambda);
  // map_midpoint's acceptance of passes settled by their move, into *s;
  // false where it leaves the step to the solve.
  bool accept_settled(const Problem& prob, VecY* y, VecN* q1, VecN* p1, VecM* lambda, StepSummary* s);

  S sys_;
  SolverOptions options_;
  bool endpoint_ = false;
  Predictor predictor_;
  VecN q_ = VecN::Zero(), p_ = VecN::Zero();
  VecM lambda_ = VecM::Zero();
  long steps_ = 0;
  // The endpoint variant's multipliers of the last steps of each h (step()).
  struct StepMemory {
    double h = 0;
    VecM last = VecM::Zero(), prev = VecM::Zero();
    int count = 0;
  };
  std::array<StepMemory, 8> memory_{};
  int memory_next_ = 0;
  // The last successful step: its start (q, p) and size (sample()).
  VecN q_prev_ = VecN::Zero(), p_prev_ = VecN::Zero();
  double h_prev_ = 0;
  bool has_step_ = false;
  bool check_settled_ = false;
  long settled_by_move_steps_ = 0, settled_checks_failed_ = 0;
};

// The method table's entry (methods.hpp): "discrete_gradient", symmetric, so composable.
struct DiscreteGradientMethod {
  static constexpr const char* name = "discrete_gradient";
  static constexpr bool adaptive = false;
  // Where the velocity constraint holds: at the midpoint (odelab's) or at every grid point.
  static std::vector<MethodKey> keys() {
    return {MethodKey::choice("constraint", &MethodSpec::constraint, {"midpoint", "endpoint"})};
  }
  static bool symmetric(const MethodSpec&) { return true; }  // so it composes (composition.hpp)
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 15.0;
  static std::string label(const MethodSpec& spec) {
    return spec.constraint == "endpoint" ? std::string(name) + " endpoint" : std::string(name);
  }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    const SolverOptions opt = solver_options(spec);
    if (spec.constraint != "midpoint" && spec.constraint != "endpoint")
      throw std::invalid_argument("unknown constraint \"" + spec.constraint + "\" (midpoint or endpoint)");
    return with_composition(DiscreteGradientStepper<S>(sys, opt, spec.constraint == "endpoint"), spec.composition, f);
  }
  // The endpoint variant is "costly" (a Newton solve in 2n + m unknowns every
  // step): in the studies of short runs, where its compositions' orders are
  // the point (README "Methods").
  static std::vector<StudyEntry> study_entries() {
    MethodSpec e = spec_of(name);
    e.constraint = "endpoint";
    const auto composed = [e](const char* c) {
      MethodSpec s = e;
      s.composition = c;
      return s;
    };
    return {{spec_of(name), "main", 31},
            {spec_of(name, "triple_jump"), "main", 32},
            {spec_of(name, "suzuki5"), "variant", 33},
            {spec_of(name, "order6"), "variant", 34},
            {e, "costly", 35},
            {composed("triple_jump"), "costly", 36},
            {composed("suzuki5"), "costly", 37},
            {composed("order6"), "costly", 38}};
  }
};

}  // namespace nhi
