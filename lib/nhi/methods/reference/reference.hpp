// The reference solution: SUNDIALS CVODE, variable-order variable-step Adams
// (the family of the paper's Matlab ode113 "benchmark") with tight tolerances,
// on the same index-reduced ODE as RK4, reported at the requested output times.
// It stands in for the exact solution.  (The scene value "benchmark" names it
// in the runner's contract; in the code it is the reference solution, so as not
// to be confused with Google Benchmark.)
//   CvodeReference      the CVODE session (advance to t_out)
//   ReferenceStepper    the same as a stateful stepper (stepper.hpp) on the grid t_k = k h
//   reference_solution  q(T), v(T) from (q0, v0): what tests and studies compare against
#pragma once

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "nhi/methods/method_spec.hpp"
#include "nhi/roles/integrate.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

struct ReferenceOptions {
  double rtol = kDefaultTolerance;
  double atol = kDefaultTolerance;
  long max_steps = 2000000000L;  // per output interval (CVODE's default is 500)
};

template <class S>
class CvodeReference {
 public:
  static constexpr int n = S::n;
  using VecN = Vec<double, n>;

  CvodeReference(const S& sys, double t0, const VecN& q0, const VecN& v0, ReferenceOptions opt = {}) : sys_(sys) {
    if (SUNContext_Create(nullptr, &ctx_) != 0) throw std::runtime_error("SUNContext_Create failed");
    y_ = N_VNew_Serial(2 * n, ctx_);
    double* y = N_VGetArrayPointer(y_);
    for (int i = 0; i < n; ++i) {
      y[i] = q0[i];
      y[n + i] = v0[i];
    }
    mem_ = CVodeCreate(CV_ADAMS, ctx_);
    check(CVodeInit(mem_, &CvodeReference::rhs, t0, y_), "CVodeInit");
    check(CVodeSetUserData(mem_, this), "CVodeSetUserData");
    check(CVodeSetErrHandlerFn(mem_, &CvodeReference::on_error, this), "CVodeSetErrHandlerFn");
    check(CVodeSStolerances(mem_, opt.rtol, opt.atol), "CVodeSStolerances");
    nls_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
    check(CVodeSetNonlinearSolver(mem_, nls_), "CVodeSetNonlinearSolver");
    check(CVodeSetMaxNumSteps(mem_, opt.max_steps), "CVodeSetMaxNumSteps");
  }
  CvodeReference(const CvodeReference&) = delete;
  CvodeReference& operator=(const CvodeReference&) = delete;
  ~CvodeReference() {
    if (mem_) CVodeFree(&mem_);
    if (nls_) SUNNonlinSolFree(nls_);
    if (y_) N_VDestroy(y_);
    if (ctx_) SUNContext_Free(&ctx_);
  }

  // Advance to t_out; false (and message()) if CVODE fails.
  bool advance(double t_out, VecN* q, VecN* v) {
    double t = 0;
    const int flag = CVode(mem_, t_out, y_, &t, CV_NORMAL);
    if (flag < 0) {
      if (message_.empty()) message_ = "CVODE flag " + std::to_string(flag);
      return false;
    }
    const double* y = N_VGetArrayPointer(y_);
    for (int i = 0; i < n; ++i) {
      (*q)[i] = y[i];
      (*v)[i] = y[n + i];
    }
    return true;
  }

  long rhs_evaluations() const {
    long k = 0;
    CVodeGetNumRhsEvals(mem_, &k);
    return k;
  }
  long internal_steps() const {
    long k = 0;
    CVodeGetNumSteps(mem_, &k);
    return k;
  }
  const std::string& message() const { return message_; }

 private:
  static int rhs(double, N_Vector y, N_Vector ydot, void* user) {
    const auto* self = static_cast<const CvodeReference*>(user);
    const double* yy = N_VGetArrayPointer(y);
    double* yd = N_VGetArrayPointer(ydot);
    VecN q, v;
    for (int i = 0; i < n; ++i) {
      q[i] = yy[i];
      v[i] = yy[n + i];
    }
    const VecN a = self->sys_.acceleration(q, v);
    for (int i = 0; i < n; ++i) {
      yd[i] = v[i];
      yd[n + i] = a[i];
    }
    return all_finite(a) ? 0 : 1;  // recoverable: CVODE retries with a smaller step
  }
  static void on_error(int code, const char* module, const char* function, char* msg, void* user) {
    auto* self = static_cast<CvodeReference*>(user);
    if (code < 0) self->message_ = std::string(module) + "/" + function + ": " + msg;
  }
  void check(int flag, const char* what) {
    if (flag != 0) throw std::runtime_error(std::string(what) + " failed: " + message_);
  }

  S sys_;
  SUNContext ctx_ = nullptr;
  N_Vector y_ = nullptr;
  void* mem_ = nullptr;
  SUNNonlinearSolver nls_ = nullptr;
  std::string message_;
};

// The reference solution as a stepper: the adaptive CVODE run reports the grid
// t_k = k h (h must stay the same from step to step; it is only the output
// interval).  rhs_evaluations and internal_steps are CVODE's own counts.
template <class S>
class ReferenceStepper {
  static_assert(check_system_ode<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;

  explicit ReferenceStepper(const S& sys, ReferenceOptions opt = {}) : sys_(sys), opt_(opt) {}
  const S& system() const { return sys_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 12;  // maximum Adams order; error set by the tolerance
    t.implicit = true;
    t.adaptive = true;
    return t;
  }

  void start(const VecN& q0, const VecN& v0);

  StepSummary step(double h);

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
  ReferenceOptions opt_;
  std::unique_ptr<CvodeReference<S>> cv_;
  VecN q_ = VecN::Zero(), v_ = VecN::Zero();
  long k_ = 0, rhs_ = 0, steps_ = 0;
};

// q(T) and v(T) of the reference solution from (q0, v0) at rtol = atol = tol.
template <class S>
void reference_solution(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double T, double tol,
                        Vec<double, S::n>* qT, Vec<double, S::n>* vT = nullptr) {
  ReferenceOptions opt;
  opt.rtol = opt.atol = tol;
  *qT = q0;
  if (vT) *vT = v0;
  integrate(ReferenceStepper<S>(sys, opt), q0, v0, T, 1, [&](const Sample<S::n, S::m>& s) {
    *qT = s.q;
    if (vT) *vT = s.v;
    return true;
  });
}

// The reference solution (scene value "benchmark", kept for the runner's contract).
struct ReferenceMethod {
  static constexpr const char* name = "benchmark";
  static constexpr bool adaptive = true;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = false;
  static constexpr double step_cost = 30.0;  // per output interval h
  static std::string label(const MethodSpec&) { return "reference"; }
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    ReferenceOptions opt;
    opt.rtol = opt.atol = spec.tolerance;
    ReferenceStepper<S> st(sys, opt);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", 10}}; }
};

}  // namespace nhi
