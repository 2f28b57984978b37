// The benchmark *stepper*: SUNDIALS CVODE, variable-order variable-step Adams
// (the family of the paper's Matlab ode113 benchmark) with tight tolerances, on
// the same index-reduced ODE as RK4, reported at the requested output times.
// It stands in for the exact solution.
#pragma once

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <stdexcept>
#include <string>

#include "nhi/system.hpp"

namespace nhi {

struct BenchmarkOptions {
  double rtol = 1e-12;
  double atol = 1e-12;
  long max_steps = 2000000000L;  // per output interval (CVODE's default is 500)
};

template <class S>
class CvodeBenchmark {
 public:
  static constexpr int n = S::n;
  using VecN = Vec<double, n>;

  CvodeBenchmark(const S& sys, double t0, const VecN& q0, const VecN& v0,
                 BenchmarkOptions opt = {})
      : sys_(sys) {
    if (SUNContext_Create(nullptr, &ctx_) != 0) throw std::runtime_error("SUNContext_Create failed");
    y_ = N_VNew_Serial(2 * n, ctx_);
    double* y = N_VGetArrayPointer(y_);
    for (int i = 0; i < n; ++i) {
      y[i] = q0[i];
      y[n + i] = v0[i];
    }
    mem_ = CVodeCreate(CV_ADAMS, ctx_);
    check(CVodeInit(mem_, &CvodeBenchmark::rhs, t0, y_), "CVodeInit");
    check(CVodeSetUserData(mem_, this), "CVodeSetUserData");
    check(CVodeSetErrHandlerFn(mem_, &CvodeBenchmark::on_error, this), "CVodeSetErrHandlerFn");
    check(CVodeSStolerances(mem_, opt.rtol, opt.atol), "CVodeSStolerances");
    nls_ = SUNNonlinSol_FixedPoint(y_, 0, ctx_);
    check(CVodeSetNonlinearSolver(mem_, nls_), "CVodeSetNonlinearSolver");
    check(CVodeSetMaxNumSteps(mem_, opt.max_steps), "CVodeSetMaxNumSteps");
  }
  CvodeBenchmark(const CvodeBenchmark&) = delete;
  CvodeBenchmark& operator=(const CvodeBenchmark&) = delete;
  ~CvodeBenchmark() {
    if (mem_) CVodeFree(&mem_);
    if (nls_) SUNNonlinSolFree(nls_);
    if (y_) N_VDestroy(y_);
    if (ctx_) SUNContext_Free(&ctx_);
  }

  static constexpr int order() { return 12; }  // maximum Adams order
  static constexpr bool symmetric() { return false; }
  static constexpr bool implicit() { return true; }

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
    const auto* self = static_cast<const CvodeBenchmark*>(user);
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
    return a.allFinite() ? 0 : 1;  // recoverable: CVODE retries with a smaller step
  }
  static void on_error(int code, const char* module, const char* function, char* msg,
                       void* user) {
    auto* self = static_cast<CvodeBenchmark*>(user);
    if (code < 0)
      self->message_ = std::string(module) + "/" + function + ": " + msg;
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

}  // namespace nhi
