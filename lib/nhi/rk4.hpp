// The RK4 *stepper*: the classical fixed-step fourth-order Runge-Kutta method on
// the index-reduced ODE q'' = a(q, q') of the system (constraint differentiated
// once and the multiplier eliminated, as the paper did in section 6.1).  It
// knows nothing of the constraint, so the constraint drifts: that is the point
// of the comparison in Figures 2 and 4.
#pragma once

#include "nhi/system.hpp"

namespace nhi {

template <class S>
class Rk4Stepper {
 public:
  static constexpr int n = S::n;
  using VecN = Vec<double, n>;

  Rk4Stepper(const S& sys, double h) : sys_(sys), h_(h) {}
  const S& system() const { return sys_; }
  double h() const { return h_; }
  static constexpr int order() { return 4; }
  static constexpr bool symmetric() { return false; }
  static constexpr bool implicit() { return false; }
  static constexpr int rhs_per_step() { return 4; }

  // (q, v) <- one RK4 step of (q' = v, v' = a(q, v)).
  void step(VecN* q, VecN* v) const {
    const double h = h_;
    const VecN q1 = *q, v1 = *v, a1 = sys_.acceleration(q1, v1);
    const VecN q2 = q1 + 0.5 * h * v1, v2 = v1 + 0.5 * h * a1, a2 = sys_.acceleration(q2, v2);
    const VecN q3 = q1 + 0.5 * h * v2, v3 = v1 + 0.5 * h * a2, a3 = sys_.acceleration(q3, v3);
    const VecN q4 = q1 + h * v3, v4 = v1 + h * a3, a4 = sys_.acceleration(q4, v4);
    *q = q1 + (h / 6.0) * (v1 + 2.0 * v2 + 2.0 * v3 + v4);
    *v = v1 + (h / 6.0) * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
  }

 private:
  S sys_;
  double h_;
};

}  // namespace nhi
