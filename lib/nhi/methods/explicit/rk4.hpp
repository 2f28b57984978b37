// RK4: the classical fixed-step fourth-order Runge-Kutta method on the
// index-reduced ODE q'' = a(q, q') of the system (constraint differentiated
// once and the multiplier eliminated, as the paper did in section 6.1).  It
// knows nothing of the constraint, so the constraint drifts: that is the point
// of the comparison in Figures 2 and 4.  A stateful stepper (stepper.hpp).
#pragma once

#include <string>
#include <vector>

#include "nhi/methods/method_spec.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

template <class S>
class Rk4Stepper {
  static_assert(check_system_ode<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;

  explicit Rk4Stepper(const S& sys) : sys_(sys) {}
  const S& system() const { return sys_; }
  static constexpr int rhs_per_step() { return 4; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 4;
    return t;
  }

  void start(const VecN& q0, const VecN& v0) {
    q_ = q0;
    v_ = v0;
    steps_ = 0;
  }

  StepSummary step(double h) {
    step(h, &q_, &v_);
    ++steps_;
    StepSummary s;
    s.rhs_evaluations = rhs_per_step();
    if (all_finite(q_) && all_finite(v_)) {
      s.status = SolveStatus::kConverged;
    } else {
      s.failure = FailureKind::kNonFinite;
      s.message = "state became non-finite at step " + std::to_string(steps_);
    }
    return s;
  }

  // (q, v) <- one RK4 step of (q' = v, v' = a(q, v)).
  void step(double h, VecN* q, VecN* v) const {
    const VecN q1 = *q, v1 = *v, a1 = sys_.acceleration(q1, v1);
    const VecN q2 = q1 + 0.5 * h * v1, v2 = v1 + 0.5 * h * a1, a2 = sys_.acceleration(q2, v2);
    const VecN q3 = q1 + 0.5 * h * v2, v3 = v1 + 0.5 * h * a2, a3 = sys_.acceleration(q3, v3);
    const VecN q4 = q1 + h * v3, v4 = v1 + h * a3, a4 = sys_.acceleration(q4, v4);
    *q = q1 + (h / 6.0) * (v1 + 2.0 * v2 + 2.0 * v3 + v4);
    *v = v1 + (h / 6.0) * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
  }

  void sample(Sample<n, m>* s) const {
    s->q = q_;
    s->v = v_;
  }
  Vec<double, 2 * n> phase() const {
    Vec<double, 2 * n> z;
    z << q_, v_;
    return z;
  }

 private:
  S sys_;
  VecN q_ = VecN::Zero(), v_ = VecN::Zero();
  long steps_ = 0;
};

// The method table's entry (methods.hpp): "rk4".
struct Rk4Method {
  static constexpr const char* name = "rk4";
  static constexpr bool adaptive = false;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = false;
  static constexpr double step_cost = 1.0;
  static std::string label(const MethodSpec&) { return name; }
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec&, F&& f) {
    Rk4Stepper<S> st(sys);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", 51}}; }
};

}  // namespace nhi
