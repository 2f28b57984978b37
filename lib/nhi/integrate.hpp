// The integrate loops: each method hands the *observer* one Sample per time
// point t_k = k h, k = 0..steps, and stops early if a step fails or the
// observer says so.  A loop a user can copy: make the stepper, call step(),
// look at the state.
//
// Diagnostics of the DLA (a sequence q_k with momenta p_k): v_0 is the given
// initial velocity and v_k = (q_{k+1} - q_{k-1}) / (2h) for k >= 1, so the loop
// takes one step past the last point to give v_N.  RK4 and the benchmark carry
// (q, v) and report it directly.
#pragma once

#include <atomic>
#include <cmath>
#include <string>
#include <utility>

#include "nhi/benchmark.hpp"
#include "nhi/dla.hpp"
#include "nhi/rk4.hpp"

namespace nhi {

template <int n, int m>
struct Sample {
  long k = 0;
  double t = 0;
  Vec<double, n> q = Vec<double, n>::Zero(), v = Vec<double, n>::Zero();
  bool has_p = false;  // DLA only: p_k = D2 L_d(q_{k-1}, q_k), lambda_k of the step k -> k+1
  Vec<double, n> p = Vec<double, n>::Zero();
  Vec<double, m> lambda = Vec<double, m>::Zero();
  Vec<double, m> discrete_constraint = Vec<double, m>::Zero();  // DLA: omega_d(q_k, q_{k+1})
};

struct RunReport {
  bool ok = true;
  long failure_step = -1;   // index j of the first time point that could not be computed
  std::string reason;
  long steps_taken = 0;     // completed steps (for the DLA, including the extra one)
  long newton_iterations = 0;
  long residual_evaluations = 0;
  long fallbacks = 0;       // DLA steps that needed the TinySolver fallback
  long rhs_evaluations = 0; // RK4 and benchmark
  long internal_steps = 0;  // benchmark
  void fail(long step, std::string why) {
    ok = false;
    failure_step = step;
    reason = std::move(why);
  }
};

// Set (e.g. from a signal handler) to make every loop stop at its next step.
inline std::atomic<bool>& interrupt_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}

// DLA from (q0, v0): p_0 = dL/dqdot(q_0, v_0), first guess q_0 + h v_0, then
// q_k + (q_k - q_{k-1}).  The observer returns false to stop the run.
// The start p_0 may also be given (integrate_dla_from), e.g. to study how the
// choice of p_0 affects the order.
template <class S, class D, class Observer>
RunReport integrate_dla_from(const DlaStepper<S, D>& stepper, const Vec<double, S::n>& q0,
                             const Vec<double, S::n>& v0, const Vec<double, S::n>& p0,
                             long steps, Observer&& observe) {
  constexpr int n = S::n, m = S::m;
  const double h = stepper.h();
  RunReport rep;
  Vec<double, n> q_prev = q0, q_curr = q0, p_curr = p0;
  Vec<double, n> q_next = q0, p_next = p_curr, guess = q0 + h * v0;
  typename DlaStepper<S, D>::VecM lambda = DlaStepper<S, D>::VecM::Zero();  // (mu, lambda of g)
  Sample<n, m> s;
  s.has_p = true;
  for (long k = 0; k <= steps; ++k) {
    if (interrupt_flag().load(std::memory_order_relaxed)) {
      rep.fail(k + 1, "interrupted");
      return rep;
    }
    const StepSummary st = stepper.step(q_curr, p_curr, guess, &q_next, &lambda, &p_next);
    rep.newton_iterations += st.iterations;
    rep.residual_evaluations += st.evaluations;
    rep.fallbacks += st.used_fallback ? 1 : 0;
    if (st.status != SolveStatus::kConverged || !q_next.allFinite()) {
      rep.fail(k + 1, "step solve for q_" + std::to_string(k + 1) + " did not converge: " +
                          (st.message.empty() ? "non-finite state" : st.message));
      return rep;
    }
    ++rep.steps_taken;
    // Point k is complete now that q_{k+1} is known.
    s.k = k;
    s.t = k * h;
    s.q = q_curr;
    s.v = (k == 0) ? v0 : Vec<double, n>((q_next - q_prev) / (2 * h));
    s.p = p_curr;
    s.lambda = lambda.template head<m>();
    s.discrete_constraint = discrete_constraint<S, D, double>(stepper.system(),
                                                              stepper.discretization(), h, q_curr, q_next);
    if (!observe(static_cast<const Sample<n, m>&>(s))) {
      rep.fail(k, "stopped by observer");
      return rep;
    }
    guess = q_next + (q_next - q_curr);
    q_prev = q_curr;
    q_curr = q_next;
    p_curr = p_next;
  }
  return rep;
}

template <class S, class D, class Observer>
RunReport integrate_dla(const DlaStepper<S, D>& stepper, const Vec<double, S::n>& q0,
                        const Vec<double, S::n>& v0, long steps, Observer&& observe) {
  return integrate_dla_from(stepper, q0, v0, momentum(stepper.system(), q0, v0), steps,
                            std::forward<Observer>(observe));
}

template <class S, class Observer>
RunReport integrate_rk4(const Rk4Stepper<S>& stepper, const Vec<double, S::n>& q0,
                        const Vec<double, S::n>& v0, long steps, Observer&& observe) {
  constexpr int n = S::n, m = S::m;
  RunReport rep;
  Sample<n, m> s;
  s.q = q0;
  s.v = v0;
  for (long k = 0; k <= steps; ++k) {
    s.k = k;
    s.t = k * stepper.h();
    if (!observe(static_cast<const Sample<n, m>&>(s))) {
      rep.fail(k, "stopped by observer");
      return rep;
    }
    if (k == steps) break;
    if (interrupt_flag().load(std::memory_order_relaxed)) {
      rep.fail(k + 1, "interrupted");
      return rep;
    }
    stepper.step(&s.q, &s.v);
    rep.rhs_evaluations += Rk4Stepper<S>::rhs_per_step();
    ++rep.steps_taken;
    if (!s.q.allFinite() || !s.v.allFinite()) {
      rep.fail(k + 1, "state became non-finite at step " + std::to_string(k + 1));
      return rep;
    }
  }
  return rep;
}

template <class S, class Observer>
RunReport integrate_benchmark(const S& sys, double h, const Vec<double, S::n>& q0,
                              const Vec<double, S::n>& v0, long steps, BenchmarkOptions opt,
                              Observer&& observe) {
  constexpr int n = S::n, m = S::m;
  RunReport rep;
  CvodeBenchmark<S> cv(sys, 0.0, q0, v0, opt);
  Sample<n, m> s;
  s.q = q0;
  s.v = v0;
  for (long k = 0; k <= steps; ++k) {
    s.k = k;
    s.t = k * h;
    if (!observe(static_cast<const Sample<n, m>&>(s))) {
      rep.fail(k, "stopped by observer");
      break;
    }
    if (k == steps) break;
    if (interrupt_flag().load(std::memory_order_relaxed)) {
      rep.fail(k + 1, "interrupted");
      break;
    }
    if (!cv.advance((k + 1) * h, &s.q, &s.v)) {
      rep.fail(k + 1, "CVODE failed: " + cv.message());
      break;
    }
    if (!s.q.allFinite() || !s.v.allFinite()) {
      rep.fail(k + 1, "state became non-finite at step " + std::to_string(k + 1));
      break;
    }
    ++rep.steps_taken;
  }
  rep.rhs_evaluations = cv.rhs_evaluations();
  rep.internal_steps = cv.internal_steps();
  return rep;
}

}  // namespace nhi
