// The one integrate loop: it drives any stepper (stepper.hpp) over the grid
// t_k = k h, k = 0..steps, hands the *observer* one Sample per point, and owns
// the interrupt, observer-stop, failure and finiteness handling for every
// method.  A loop a user can copy: make a stepper, start(), step(), sample().
//
// The observer returns false to stop the run (RunReport: failed at that point,
// kind kObserver).  A step that fails (no convergence, a non-finite state) ends
// the run with failure_step = the index of the point that could not be
// computed; every point before it has been observed — except that a lag-1
// stepper (the DLA) reports point k only once q_{k+1} is known, so a failure
// computing q_j leaves points 0 .. j-2 observed.
//
// An optional *guard* (guard.hpp: EnergyGuard) checks every point before the
// observer sees it and may end the run failed there (a blown-up run: its
// energy past a limit, or a non-finite state); without one (NoGuard) the loop
// checks nothing beyond what the stepper reports.
#pragma once

#include <type_traits>
#include <utility>

#include "nhi/roles/guard.hpp"
#include "nhi/roles/stepper.hpp"

namespace nhi {

template <class Stepper, class Observer, class Guard = NoGuard>
RunReport integrate(Stepper& stepper, const Vec<double, Stepper::n>& q0, const Vec<double, Stepper::n>& v0, double h,
                    long steps, Observer&& observe, const Guard& guard = Guard{}) {
  constexpr int n = Stepper::n, m = Stepper::m;
  RunReport rep;
  stepper.start(q0, v0);
  // Compute the point after k (lag 0: k+1 from k; lag 1: q_{k+1}, completing k).
  auto advance = [&](long k) {
    if (interrupt_flag().load(std::memory_order_relaxed)) {
      rep.fail(k + 1, FailureKind::kInterrupted, "interrupted");
      return false;
    }
    const StepSummary st = stepper.step(h);
    rep.add(st);
    if (!st.ok()) {
      rep.fail(k + 1, st.failure, st.message);
      return false;
    }
    ++rep.steps_taken;
    return true;
  };
  Sample<n, m> s;
  for (long k = 0; k <= steps; ++k) {
    if constexpr (Stepper::lag == 1) {
      if (!advance(k)) return rep;
    }
    s.k = k;
    s.t = k * h;
    stepper.sample(&s);
    if constexpr (Guard::active) {
      if (!guard.check(static_cast<const Sample<n, m>&>(s), &rep)) return rep;
    }
    if (!observe(static_cast<const Sample<n, m>&>(s))) {
      rep.fail(k, FailureKind::kObserver, "stopped by observer");
      return rep;
    }
    if constexpr (Stepper::lag == 0) {
      if (k == steps) break;
      if (!advance(k)) return rep;
    }
  }
  return rep;
}

// The same for a temporary stepper: integrate(DlaStepper<S, D>(sys, disc), ...).
template <class Stepper, class Observer, class = std::enable_if_t<!std::is_lvalue_reference_v<Stepper>>>
RunReport integrate(Stepper&& stepper, const Vec<double, std::decay_t<Stepper>::n>& q0,
                    const Vec<double, std::decay_t<Stepper>::n>& v0, double h, long steps, Observer&& observe) {
  return integrate(stepper, q0, v0, h, steps, std::forward<Observer>(observe));
}

}  // namespace nhi
