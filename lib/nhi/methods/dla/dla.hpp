// The discrete Lagrange-d'Alembert (DLA) method (paper eq. 6) in
// position-momentum form.  Given (q_k, p_k) with p_k = D2 L_d(q_{k-1}, q_k),
// solve the n+m equations
//     p_k + D1 L_d(q_k, q_{k+1}) - omega(q_k)^T lambda_k = 0       (eq. 6, first line)
//     omega_d(q_k, q_{k+1})                            = 0       (eq. 6, second line)
// for (q_{k+1}, lambda_k); then p_{k+1} = D2 L_d(q_k, q_{k+1}).
// A system with l holonomic constraints g (system.hpp) gets the Constrained
// Coordinate Formulation (eq. 17) instead: l more multipliers on the rows Dg(q_k)
// and l more equations g(q_{k+1}) = 0; the multiplier vector is (mu, lambda)
// with mu on omega first.
// The Jacobian of the residual is the matrix (7):
//     [ D2 D1 L_d(q_k, q_{k+1})   -omega(q_k)^T ]
//     [ D2 omega_d(q_k, q_{k+1})        0       ]
// so the step is a saddle-point problem for NewtonSolver (solver.hpp) with
// y = q_{k+1} and Wt = omega(q_k)^T: only the equations live here.
//
// Three layers: DlaStepProblem (the residual), DlaMap (the one-step map
// (q_k, p_k) -> (q_{k+1}, p_{k+1}), stateless), DlaStepper (the stateful stepper
// the integrate loop drives, stepper.hpp), which starts each solve from its
// predictor's guess (DlaPredictor, dla_predictor.hpp).
//
// Symmetry: with a self-adjoint discretization (alpha = 1/2, the symmetric
// family) the *position* sequence is reversible: from (q_{k+1}, p_{k+1}) a step
// of -h returns exactly q_k (with multiplier 0), but the momentum comes back as
// p_k - omega(q_k)^T lambda_k, because the constraint force acts at q_k only.
// So the map on T*Q is not self-adjoint; MethodTraits says symmetric_in_phase = false.
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "nhi/methods/dla/dla_predictor.hpp"
#include "nhi/roles/discretization.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

using DlaOptions = SolverOptions;

// The residual of eq. (6) / (17) at fixed (q_k, p_k), for NewtonSolver.
template <class S, class D>
struct DlaStepProblem {
  static constexpr int n = S::n;
  static constexpr int m = S::m;                       // nonholonomic constraints omega
  static constexpr int l = holonomic_count<S>::value;  // holonomic constraints g (eq. 17)
  static constexpr int mc = m + l;                     // multipliers (mu, lambda)
  static constexpr int ny = n, nl = mc;
  using VecN = Vec<double, n>;

  const S& sys;
  const D& disc;
  double h;
  const VecN& q_curr;
  const VecN& p_curr;
  Mat<double, n, mc> W_t;  // force_forms(q_k)^T: the multiplier columns

  // Wt (may be null): force_forms(q)^T, if the caller has it (the stepper's predictor).
  DlaStepProblem(const S& s, const D& d, double hh, const VecN& q, const VecN& p,
                 const Mat<double, n, mc>* Wt = nullptr)
      : sys(s), disc(d), h(hh), q_curr(q), p_curr(p), W_t(Wt ? *Wt : force_forms(s, q).transpose()) {}

  // The one-forms the multipliers act on at q_k: omega(q_k) and, with holonomic
  // constraints, Dg(q_k) below it (eq. 17, first line).
  static Mat<double, mc, n> force_forms(const S& sys, const VecN& q) {
    Mat<double, mc, n> W;
    W.template topRows<m>() = sys.template omega<double>(q);
    if constexpr (l > 0) W.template bottomRows<l>() = holonomic_jacobian(sys, q);
    return W;
  }

  const Mat<double, n, mc>& Wt() const { return W_t; }

  // Root following (solver.hpp): the same step at h2 (W_t is omega(q_k)^T,
  // independent of h); as h -> 0 the root tends to q_{k+1} = q_k with
  // multipliers 0 (they carry the factor h, as L_d does).
  DlaStepProblem at_step(double h2) const {
    DlaStepProblem c = *this;
    c.h = h2;
    c.last_d2 = nullptr;  // (the kept D2 L_d is for h)
    return c;
  }
  void small_step_start(double ratio, VecN* q1, Vec<double, mc>* lambda) const {
    *q1 = q_curr + ratio * (*q1 - q_curr);
    *lambda *= ratio;
  }

  using Memo = DlaOmegaMemo<S, D>;
  Memo* memo = nullptr;  // omega at the constraint nodes, for the double residual (may be null)
  // D2 L_d(q_k, q1) at the q1 of the last double residual, for
  // p_{k+1} = D2 L_d(q_k, q_{k+1}) (top of this file) without evaluating the
  // partials again; the caller's (DlaMap::step), written by residual().
  struct LastD2 {
    VecN d2, at;
    bool valid = false;
  };
  LastD2* last_d2 = nullptr;  // (may be null)

  // Round-off in (q1 - q0)/h grows with |q_k| + |q_{k+1}| (a coordinate that has travelled far).
  VecN y_scale(const VecN& q1) const { return q_curr.cwiseAbs() + q1.cwiseAbs(); }

  // r = (p_k + D1 L_d(q_k, q1) - W^T lambda, omega_d(q_k, q1) [, g(q1)]);
  // *terms gets, per row, the sum of the magnitudes of the terms r_i adds up.
  template <class T>
  void residual(const Vec<T, n>& q1, const Vec<T, mc>& lambda, Vec<T, n + mc>* r, Vec<double, n + mc>* terms) const {
    const Vec<T, n> q0 = q_curr.template cast<T>();
    Vec<T, n> D1;
    if constexpr (std::is_same_v<T, double>) {
      // D2 L_d(q_k, q1) comes from the same partials at the same nodes: kept
      // for p_{k+1} if q1 is the solution (DlaMap::step).  (Taken always: a
      // null D2 would leave a branch per node in the inlined slots.)
      VecN d2;
      discrete_lagrangian_slots<S, D, T>(sys, disc, h, q0, q1, &D1, &d2);  // eq. 9 / 10
      if (last_d2) {
        last_d2->d2 = d2;
        last_d2->at = q1;
        last_d2->valid = true;
      }
    } else {
      discrete_lagrangian_slots<S, D, T>(sys, disc, h, q0, q1, &D1, nullptr);  // eq. 9 / 10
    }
    Vec<double, m> cscale;
    const auto omega_at = [this](int k, const Vec<T, n>& qc) -> Mat<T, m, n> {
      if constexpr (std::is_same_v<T, double>)
        if (memo) return memo->at(sys, k, qc);
      return sys.template omega<T>(qc);
    };
    const Vec<T, m> wd =
        discrete_constraint_with<S, D, T>(sys, omega_at, disc, h, q0, q1, terms ? &cscale : nullptr);  // eq. 13 / 14
    for (int i = 0; i < n; ++i) {
      T force = cst<T>(0.0);
      for (int a = 0; a < mc; ++a) force += scale(lambda[a], W_t(i, a));
      (*r)[i] = cst<T>(p_curr[i]) + D1[i] - force;  // eq. 6, first line
      if (terms) {
        double fscale = 0;
        for (int a = 0; a < mc; ++a) fscale += std::abs(W_t(i, a) * value_of(lambda[a]));
        (*terms)[i] = std::abs(p_curr[i]) + std::abs(value_of(D1[i])) + fscale;
      }
    }
    for (int a = 0; a < m; ++a) {
      (*r)[n + a] = wd[a];  // eq. 6, second line
      if (terms) (*terms)[n + a] = cscale[a];
    }
    if constexpr (l > 0) {  // g(q_{k+1}) = 0 (eq. 17, second line); its scale comes from Dg
      const Vec<T, l> gv = sys.template g<T>(q1);
      for (int a = 0; a < l; ++a) {
        (*r)[n + m + a] = gv[a];
        if (terms) (*terms)[n + m + a] = 0;
      }
    }
  }
};

// The DLA one-step map (q_k, p_k) -> (q_{k+1}, lambda_k, p_{k+1}) at step h.
template <class S, class D>
class DlaMap {
 public:
  using Problem = DlaStepProblem<S, D>;
  static constexpr int n = S::n, m = S::m, l = Problem::l, mc = Problem::mc, N = n + mc;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, mc>;
  using VecX = Vec<double, N>;

  DlaMap(const S& sys, const D& disc, double h, DlaOptions options = {})
      : sys_(sys), disc_(disc), h_(h), options_(options) {}

  const S& system() const { return sys_; }
  const D& discretization() const { return disc_; }
  double h() const { return h_; }
  void set_h(double h) { h_ = h; }
  const DlaOptions& options() const { return options_; }

  // One DLA step from (q_curr, p_curr).  q_guess and lambda (in) are the
  // starting iterate; on success q_next, lambda and p_next hold the solution.
  // check_guess: the guess may already solve the step, and polish corrects
  // it if it does (NewtonSolver::solve).
  // Wt (may be null): force_forms(q_curr)^T, if the caller has it; memo (may
  // be null): omega at the constraint nodes of earlier evaluations.
  template <class Polish = typename NewtonSolver<Problem>::NoPolish>
  StepSummary step(const VecN& q_curr, const VecN& p_curr, const VecN& q_guess, VecN* q_next, VecM* lambda,
                   VecN* p_next, bool check_guess = false, const Polish& polish = {},
                   const Mat<double, n, mc>* Wt = nullptr, typename Problem::Memo* memo = nullptr) const {
    Problem prob(sys_, disc_, h_, q_curr, p_curr, Wt);
    prob.memo = memo;
    typename Problem::LastD2 last_d2;
    prob.last_d2 = &last_d2;
    VecN q1 = q_guess;
    StepSummary s = NewtonSolver<Problem>(prob, options_).solve(&q1, lambda, check_guess, polish);
    if (s.status == SolveStatus::kConverged) {
      *q_next = q1;
      // p_{k+1} = D2 L_d(q_k, q_{k+1}): the last residual's when it was taken
      // at this q_{k+1} to the bit (the residual check accepted the guess as
      // it was; the same sums in the same order, so the same p_{k+1} as
      // evaluating it here, which is the fallback).  It saves evaluating the
      // partials at every node again (the robot's cos psi).
      if (last_d2.valid && (last_d2.at.array() == q1.array()).all()) {
        *p_next = last_d2.d2;
      } else {
        discrete_lagrangian_slots<S, D, double>(sys_, disc_, h_, q_curr, *q_next, nullptr, p_next);
      }
      if (!all_finite(*p_next)) {
        s.status = SolveStatus::kFailed;
        s.failure = FailureKind::kNonFinite;
        s.message = "non-finite momentum p_{k+1}";
      }
    }
    return s;
  }

  // Relative residual of eq. (6) at (q_next, lambda); *r_out gets the residual.
  double relative_residual(const VecN& q_curr, const VecN& p_curr, const VecN& q_next, const VecM& lambda,
                           VecX* r_out = nullptr) const {
    const Problem prob(sys_, disc_, h_, q_curr, p_curr);
    return NewtonSolver<Problem>(prob, options_).relative_residual(q_next, lambda, r_out);
  }

 private:
  S sys_;
  D disc_;
  double h_;
  DlaOptions options_;
};

// The stateful DLA stepper (stepper.hpp): the map above, started from the
// predictor's guess (dla_predictor.hpp).  Start: p_0 = dL/dqdot(q_0, v_0) (or
// a given p_0, see start_momentum), first guess q_0 + h v_0, then the linear
// extrapolation q_k + (h/h_prev)(q_k - q_{k-1}) refined by the predictor's
// passes.  Reported velocities: v_0 is the given initial velocity and v_k =
// (q_{k+1} - q_{k-1}) / (h_prev + h) for k >= 1 (the central difference), so
// point k is reported once q_{k+1} is known (lag 1).
template <class S, class D>
class DlaStepper {
  static_assert(check_system<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 1;
  using Map = DlaMap<S, D>;
  using Predictor = DlaPredictor<S, D>;
  // Do the passes solve for the multipliers too (DlaPredictor)?
  static constexpr bool kPassesSolveMultipliers = Predictor::kSolvesMultipliers;
  using VecN = Vec<double, n>;
  using VecM = typename Map::VecM;

  DlaStepper(const S& sys, const D& disc, DlaOptions options = {});

  const S& system() const { return map_.system(); }
  const D& discretization() const { return map_.discretization(); }
  const Map& map() const { return map_; }
  const Predictor& predictor() const { return predictor_; }
  // What the predictor's passes do here (DlaPredictor; tests/test_dla.cpp).
  bool passes_exact_in_potential() const { return predictor_.exact_in_potential(); }
  bool passes_newton_in_potential() const { return predictor_.newton_in_potential(); }
  bool first_pass_exact() const { return predictor_.first_pass_exact(); }

  MethodTraits traits() const {
    MethodTraits t;
    // (every alpha rule is of order 2 and symmetric on a rigid body's bilinear
    // kinematics, system.hpp)
    t.order = has_bilinear_kinematics<S>::value ? 2 : map_.discretization().order();
    t.symmetric = has_bilinear_kinematics<S>::value || map_.discretization().symmetric();
    t.symmetric_in_phase = false;  // positions only (see the top of this file)
    t.holds_velocity_constraint = false;
    t.implicit = true;
    return t;
  }

  // Start from this p_0 instead of dL/dqdot(q_0, v_0) (e.g. to study the start's
  // effect on the order).  Applies to the next start().
  void start_momentum(const VecN& p0) { p0_ = p0; }

  void start(const VecN& q0, const VecN& v0);

  StepSummary step(double h);

  // The starting iterate of the next step, of size h, from the newest point
  // (q_{k+1}, p_{k+1}), as step() makes it but with `passes` passes, leaving
  // the stepper as it is.  First step: q_0 + h v_0 and lambda = 0; second
  // step: the linear extrapolation of q and the last multipliers.
  // Otherwise the multipliers, which carry the factor h (L_d does),
  // extrapolate lambda_j / h_j linearly in t from the last two steps (at a
  // change of direction, the stages of a composition: the last multipliers),
  // q starts from the linear extrapolation q_{k+1} + (h / h_k)(q_{k+1} - q_k),
  // and where refines(h) the predictor's passes follow (DlaPredictor::refine;
  // *settled: a pass moved nothing, extend: Newton passes may add passes).
  void next_guess(double h, VecN* q_guess, VecM* lambda_guess, int passes, bool* settled = nullptr,
                  bool extend = false) const;

  // The linear extrapolation q_{k+1} + (h / h_k)(q_{k+1} - q_k) (steps >= 1).
  VecN extrapolation(double h) const { return q_next_ + (h / h_) * (q_next_ - q_curr_); }
  // Are this and the last two steps in one direction?  Only then does
  // next_guess extrapolate the multipliers.  The stages of a composition
  // (dla_composition.hpp) go back and forth.
  bool one_direction(double h) const { return steps_ >= 2 && h * h_ > 0 && h_ * h_prev_ > 0; }
  // Does next_guess refine the guess by its passes?  In one direction, or
  // where the passes settle from any start: the constraint force leaves alone
  // what omega reads (constraint_force_misses_omega), so the multipliers'
  // start does not matter and the passes settle as in one direction.  The
  // triple jump's stages then take no Newton iteration where the passes see
  // the potential (the particle, the robot, the symmetric rule), and fewer
  // elsewhere.  On the sleigh (omega reads theta, the force turns it) the
  // passes at a turn cost more than they save: there the stages keep the
  // plain extrapolation.
  bool refines(double h) const { return one_direction(h) || (predictor_.settle_from_any_start() && steps_ >= 2); }

  // Point k = steps - 1: (q_k, v_k, p_k, lambda_k, omega_d(q_k, q_{k+1})).
  void sample(Sample<n, m>* s) const;

  // The newest point (q_{k+1}, p_{k+1}) and the last multipliers.
  Vec<double, 2 * n> phase() const {
    Vec<double, 2 * n> z;
    z << q_next_, p_next_;
    return z;
  }
  const VecM& lambda() const { return lambda_; }

 private:
  // next_guess's start before the passes; true where they follow (refines(h)).
  bool start_guess(double h, VecN* q_guess, VecM* lambda_guess) const;

  Map map_;
  Predictor predictor_;
  typename Map::Problem::Memo omega_memo_;  // omega at the constraint nodes (OmegaMemo): passes and residuals
  std::optional<VecN> p0_;
  // Set by start(); zero until then (so that an unstarted stepper copies cleanly).
  VecN q_prev_ = VecN::Zero(), q_curr_ = VecN::Zero(), q_next_ = VecN::Zero(), p_curr_ = VecN::Zero(),
       p_next_ = VecN::Zero(), v0_ = VecN::Zero();
  VecM lambda_ = VecM::Zero(), lambda_prev_ = VecM::Zero();
  long steps_ = 0;
  double h_ = 0, h_prev_ = 0;
  bool accepted_ = false;  // did the residual check accept the last step's guess?
};

}  // namespace nhi
