// A method of one's own, as a throwaway example: explicit Euler on the
// index-reduced ODE.  The stepper (stepper.hpp's role) runs out of tree like
// the library's, through nhi::integrate (user_system.cpp); with the method
// struct, its line in `Methods` (methods.hpp) and a file in lib/src/methods/
// compiling its MethodRun, the same file as lib/nhi/methods/explicit/euler.hpp adds
// "method": "euler" to the library (README, "Adding a method"; the branch
// throwaway-euler does it with a scene key of its own).
#pragma once
#include "nhi/methods/method_spec.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"
namespace nhi {
template <class S>
class EulerStepper {
  static_assert(check_system_ode<S>());  // a clear message for a type that is not a system

 public:
  static constexpr int n = S::n, m = S::m, lag = 0;
  explicit EulerStepper(const S& sys) : sys_(sys) {}
  MethodTraits traits() const { MethodTraits t; t.order = 1; return t; }
  void start(const Vec<double, n>& q0, const Vec<double, n>& v0) { q_ = q0; v_ = v0; }
  StepSummary step(double h) {  // (a real method reports a failed solve in its summary)
    const Vec<double, n> a = sys_.acceleration(q_, v_);
    q_ += h * v_, v_ += h * a;
    StepSummary s;
    s.status = SolveStatus::kConverged;
    return s;
  }
  void sample(Sample<n, m>* s) const { s->q = q_; s->v = v_; }
  Vec<double, 2 * n> phase() const { Vec<double, 2 * n> z; z << q_, v_; return z; }
 private:
  S sys_;
  Vec<double, n> q_, v_;
};
struct EulerMethod {
  static constexpr const char* name = "euler";
  static constexpr bool adaptive = false, reports_p = false;
  static std::vector<MethodKey> keys() { return {}; }  // its own scene keys, none
  static constexpr double step_cost = 1.0;  // in RK4 steps, for scheduling the studies
  static std::string label(const MethodSpec&) { return name; }  // its plot style's key
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec&, F&& f) { EulerStepper<S> st(sys); return f(st); }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name)}}; }
};
}  // namespace nhi
