// A method chosen at run time: DLA (alpha or symmetric discretization, any
// alpha), RK4 or the CVODE benchmark, run on any system with any observer.
// The runner and the study executables go through run_method(), so a method
// means the same thing everywhere.
#pragma once

#include <cstdio>
#include <string>

#include "nhi/integrate.hpp"

namespace nhi {

struct MethodSpec {
  std::string kind = "dla";            // "dla", "rk4", "benchmark"
  std::string discretization = "alpha";  // DLA: "alpha" or "symmetric"
  double alpha = 0.5;
  double tolerance = 1e-12;            // DLA residual; CVODE rtol = atol

  // A short label: "dla a=0.5", "sym a=0", "rk4", "cvode 1e-12".
  std::string label() const {
    char buf[64];
    if (kind == "dla")
      std::snprintf(buf, sizeof buf, "%s a=%g", discretization == "alpha" ? "dla" : "sym", alpha);
    else if (kind == "benchmark")
      std::snprintf(buf, sizeof buf, "cvode %g", tolerance);
    else
      std::snprintf(buf, sizeof buf, "%s", kind.c_str());
    return buf;
  }
};

template <class S, class Observer>
RunReport run_method(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0,
                     const Vec<double, S::n>& v0, double h, long steps, Observer&& observe) {
  if (spec.kind == "dla") {
    DlaOptions opt;
    opt.tolerance = spec.tolerance;
    if (spec.discretization == "alpha") {
      const DlaStepper<S, AlphaDiscretization> st(sys, AlphaDiscretization{spec.alpha}, h, opt);
      return integrate_dla(st, q0, v0, steps, observe);
    }
    const DlaStepper<S, SymmetricDiscretization> st(sys, SymmetricDiscretization{spec.alpha}, h, opt);
    return integrate_dla(st, q0, v0, steps, observe);
  }
  if (spec.kind == "rk4") return integrate_rk4(Rk4Stepper<S>(sys, h), q0, v0, steps, observe);
  BenchmarkOptions opt;
  opt.rtol = opt.atol = spec.tolerance;
  return integrate_benchmark(sys, h, q0, v0, steps, opt, observe);
}

}  // namespace nhi
