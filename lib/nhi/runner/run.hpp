// Running a method by its MethodSpec on a registered system, compiled once.
//
// run_spec(), method_traits() and make_stepper() below are declared here and
// compiled in the library for every registered system (systems/registry.hpp):
// they find the method by its name (lib/src/runner/run.cpp) and call its MethodRun,
// which each method's own translation unit instantiates beside its steppers
// (lib/src/methods/*.cpp), so that a study, a test or the runner that runs
// methods by name does not compile every method's stepper and Newton solver
// again, and a change to one method's body recompiles that method only.  The observer is called through a
// std::function (one indirect call per time point; the arithmetic of a run is
// the same as with integrate() on the concrete stepper, bit for bit).
//
// Code that wants the concrete stepper type (a benchmark, a test of one
// method's internals) uses with_stepper() or the stepper classes directly
// (methods.hpp).
#pragma once

#include <functional>
#include <memory>

#include "nhi/methods/method_spec.hpp"
#include "nhi/roles/guard.hpp"
#include "nhi/roles/stepper.hpp"

namespace nhi {

template <int n, int m>
using SampleObserver = std::function<bool(const Sample<n, m>&)>;

// A stepper of any method, behind virtual calls (stepper.hpp describes the role).
template <int n, int m>
class AnyStepper {
 public:
  virtual ~AnyStepper() = default;
  virtual MethodTraits traits() const = 0;
  virtual int lag() const = 0;
  virtual void start(const Vec<double, n>& q0, const Vec<double, n>& v0) = 0;
  virtual StepSummary step(double h) = 0;
  virtual void sample(Sample<n, m>* s) const = 0;
  virtual Vec<double, 2 * n> phase() const = 0;  // (q, p) or (q, v) of the newest point
};

// Run spec on sys from (q0, v0) with step h for `steps` steps (integrate.hpp),
// held to `limit` (guard.hpp: off, or the run fails where it blows up).
template <class S>
RunReport run_spec(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                   double h, long steps, const SampleObserver<S::n, S::m>& observe, const EnergyLimit& limit);

// The method's declared traits (order, symmetry, ...), for tests and studies.
template <class S>
MethodTraits method_traits(const S& sys, const MethodSpec& spec);

// The stepper spec names, type-erased; an unknown name throws.
template <class S>
std::unique_ptr<AnyStepper<S::n, S::m>> make_stepper(const S& sys, const MethodSpec& spec);

// One method M (a type of methods.hpp's Methods) on one system S: what the
// three functions above do once the method is found.  Defined in
// run_body.hpp; instantiated in M's translation unit for every registered system.
template <class M, class S>
struct MethodRun {
  static RunReport run(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0,
                       const Vec<double, S::n>& v0, double h, long steps, const SampleObserver<S::n, S::m>& observe,
                       const EnergyLimit& limit);
  static MethodTraits traits(const S& sys, const MethodSpec& spec);
  static std::unique_ptr<AnyStepper<S::n, S::m>> make(const S& sys, const MethodSpec& spec);
};

// run_spec with any callable observer (held by reference for the call); no
// energy limit unless one is given.
template <class S, class Observer>
RunReport run_method(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                     double h, long steps, Observer&& observe, const EnergyLimit& limit = EnergyLimit::off()) {
  const SampleObserver<S::n, S::m> ref = [&observe](const Sample<S::n, S::m>& s) { return bool(observe(s)); };
  return run_spec<S>(sys, spec, q0, v0, h, steps, ref, limit);
}

}  // namespace nhi
