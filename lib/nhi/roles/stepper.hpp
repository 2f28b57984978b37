// The *stepper* role's shared vocabulary: what one step reports (StepSummary),
// what a method declares about itself (MethodTraits), what a stepper reports of
// a time point (Sample), and what a whole run reports (RunReport).
//
// A stepper is a plain stateful type (no base class) with
//   static constexpr int n, m;          // dim Q, number of constraint forms omega
//   static constexpr int lag;           // 0: the point reported is the newest one;
//                                       // 1: point k is reported once step k+1 is
//                                       //    known (the DLA's central-difference v_k)
//   MethodTraits traits() const;
//   void start(const Vec<double,n>& q0, const Vec<double,n>& v0);
//   StepSummary step(double h);         // advance by h (h < 0 is allowed)
//   void sample(Sample<n,m>* s) const;  // fill q, v (and p, lambda, ...) of the reported point
// and is driven by the one loop in integrate.hpp.  methods.hpp makes steppers by
// name.  See dla.hpp, rk4.hpp and reference.hpp for the three families.
#pragma once

#include <algorithm>
#include <atomic>
#include <string>
#include <utility>

#include "nhi/roles/core.hpp"

namespace nhi {

enum class SolveStatus { kConverged, kFailed };

// Why a step or a run stopped.  Studies classify failures by this, never by
// matching message text.
enum class FailureKind {
  kNone,
  kSolve,        // an implicit solve did not converge (or the step matrix was singular)
  kNonFinite,    // a state, residual or momentum became non-finite
  kInterrupted,  // SIGINT/SIGTERM (interrupt_flag())
  kObserver,     // the observer asked to stop
  kEnergy,       // |E - E0| passed the run's energy limit (guard.hpp)
};

inline const char* to_string(FailureKind k) {
  switch (k) {
    case FailureKind::kNone:
      return "none";
    case FailureKind::kSolve:
      return "solve";
    case FailureKind::kNonFinite:
      return "non-finite";
    case FailureKind::kInterrupted:
      return "interrupted";
    case FailureKind::kObserver:
      return "observer";
    case FailureKind::kEnergy:
      return "energy";
  }
  return "?";
}

// Which root of its implicit equations a step took, when asked
// (SolverOptions::root_check, solver.hpp): the one continued from h -> 0, another
// one, or none could be continued to h (the branch from h -> 0 folded or the
// continuation's solve failed).  Ordered: a step of several solves (a
// composition's stages) reports the largest of theirs.
enum class RootCheck { kUnchecked, kContinued, kOther, kNotFound };

inline const char* to_string(RootCheck r) {
  switch (r) {
    case RootCheck::kUnchecked:
      return "unchecked";
    case RootCheck::kContinued:
      return "continued";
    case RootCheck::kOther:
      return "other";
    case RootCheck::kNotFound:
      return "no continued root";
  }
  return "?";
}

// One step (or one implicit solve): converged or failed and why, and its cost.
struct StepSummary {
  SolveStatus status = SolveStatus::kFailed;
  FailureKind failure = FailureKind::kNone;  // when failed
  int iterations = 0;                        // Newton iterations (plus the fallback's, if it ran)
  int evaluations = 0;                       // residual(+Jacobian) evaluations
  int jacobians = 0;                         // of those, the ones with derivatives (Jets)
  double relative_residual = 0;              // final max_i |r_i| / size of the terms of r_i
  bool used_fallback = false;
  long rhs_evaluations = 0;  // explicit methods and the reference solution
  long internal_steps = 0;   // adaptive methods: accepted steps
  long rejected_steps = 0;   // adaptive methods: steps the error control rejected
  std::string message;       // why it failed, when it did
  RootCheck root = RootCheck::kUnchecked;
  // Merge the root check of another solve of the same step (a stage, a retry).
  void merge_root(RootCheck r) { root = std::max(root, r); }
  bool ok() const { return status == SolveStatus::kConverged; }
  // The one way to count a step's cost: add another solve's counts (a
  // retry's, a fallback's, a predictor's) to this summary's.
  void add_cost(const StepSummary& s) {
    iterations += s.iterations;
    evaluations += s.evaluations;
    jacobians += s.jacobians;
    rhs_evaluations += s.rhs_evaluations;
    internal_steps += s.internal_steps;
    rejected_steps += s.rejected_steps;
  }
  // A stage of this step (a composition's): its counts, its fallback, its
  // root check and the largest residual.
  void add_stage(const StepSummary& s) {
    add_cost(s);
    used_fallback = used_fallback || s.used_fallback;
    merge_root(s.root);
    relative_residual = std::max(relative_residual, s.relative_residual);
  }
};

// The one failed-step wrapper, at the end of every implicit step: a step
// whose solve converged to a non-finite state fails as kNonFinite; a failed
// step's message names the step (what + k: "mp06 step 7") and says which
// failure it was: "... did not converge: <the solver's reason>" or "...:
// non-finite state (the solve converged)".  Returns whether the step failed
// (the message is built only then).
inline bool step_failed(StepSummary* s, bool state_finite, const char* what, long k) {
  if (s->ok() && state_finite) return false;
  const std::string step = what + std::to_string(k);
  if (s->ok()) {
    s->status = SolveStatus::kFailed;
    s->failure = FailureKind::kNonFinite;
    s->message = step + ": non-finite state (the solve converged)";
  } else {
    s->message = step + " did not converge: " + s->message;
  }
  return true;
}

// What a method declares about itself; tests and studies read these instead of
// hard-coding expectations.
struct MethodTraits {
  int order = 0;                           // global order of q on smooth problems
  int velocity_order = 0;                  // ... of the reported v (0: the same as order)
  bool symmetric = false;                  // self-adjoint: a step of h then of -h returns to the start
  bool symmetric_in_phase = true;          // ... in (q, p) or (q, v); false: in q only (the DLA, see dla.hpp)
  bool holds_velocity_constraint = false;  // omega(q_k) v_k = 0 at grid points to round-off
  bool implicit = false;
  bool adaptive = false;          // h is only the output interval
  bool preserves_energy = false;  // E(q_k, v_k) = E(q_0, v_0) to round-off for every h
  int stages = 1;                 // one-step solves per step (a composition's stage count)
};

// One reported time point.
template <int n, int m>
struct Sample {
  long k = 0;
  double t = 0;
  Vec<double, n> q = Vec<double, n>::Zero(), v = Vec<double, n>::Zero();
  bool has_p = false;  // DLA: p_k = D2 L_d(q_{k-1}, q_k) and lambda_k of the step k -> k+1
  Vec<double, n> p = Vec<double, n>::Zero();
  Vec<double, m> lambda = Vec<double, m>::Zero();
  Vec<double, m> discrete_constraint = Vec<double, m>::Zero();  // DLA: omega_d(q_k, q_{k+1})
};

struct RunReport {
  bool ok = true;
  long failure_step = -1;  // index j of the first time point that could not be computed
  FailureKind failure = FailureKind::kNone;
  std::string reason;
  long steps_taken = 0;  // completed steps (for the DLA, including the extra one)
  long newton_iterations = 0;
  long residual_evaluations = 0;
  long fallbacks = 0;        // implicit steps that needed the fallback solver
  long rhs_evaluations = 0;  // explicit methods and the reference solution
  long internal_steps = 0;   // adaptive methods: accepted steps
  long rejected_steps = 0;   // adaptive methods: steps the error control rejected
  // The guard (guard.hpp): the first point past the energy limit (-1: none;
  // set when the limit only records), |E - E0| there or at the point that
  // ended the run, and whether the guard ended it.
  long energy_exceeded_step = -1;
  double energy_error_at_limit = 0;
  bool stopped_by_guard = false;
  // With SolverOptions::root_check: steps whose root was checked, steps that
  // took another root than the one continued from h -> 0, steps with no
  // continued root, and the first step of either kind (-1: none).
  long root_checked_steps = 0, other_root_steps = 0, no_continued_root_steps = 0;
  long first_root_departure = -1;
  void fail(long step, FailureKind kind, std::string why) {
    ok = false;
    failure_step = step;
    failure = kind;
    reason = std::move(why);
  }
  void add(const StepSummary& s) {
    newton_iterations += s.iterations;
    residual_evaluations += s.evaluations;
    fallbacks += s.used_fallback ? 1 : 0;
    rhs_evaluations += s.rhs_evaluations;
    internal_steps += s.internal_steps;
    rejected_steps += s.rejected_steps;
    if (s.root != RootCheck::kUnchecked) ++root_checked_steps;
    if (s.root == RootCheck::kOther) ++other_root_steps;
    if (s.root == RootCheck::kNotFound) ++no_continued_root_steps;
    if (first_root_departure < 0 && s.root >= RootCheck::kOther) first_root_departure = steps_taken;
  }
};

// Set (from the signal handler, see install_interrupt_handlers()) to make every
// loop stop at its next step.
inline std::atomic<bool>& interrupt_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}

}  // namespace nhi
