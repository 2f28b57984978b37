// The *guard*: the rule that turns a run that has blown up into a failed run.
//
// A run whose state stops being finite, or whose energy error |E - E0| passes
// a bound, has left anything a method claims; reporting it as a success hands
// a script garbage.  EnergyLimit says the bound and what passing it does;
// EnergyGuard<S> applies it inside the one integrate loop (integrate.hpp), at
// every time point, before the observer sees the point:
//   bound     max(relative |E0|, absolute), E0 = E(q0, v0) of the start
//   kStop     a point with |E - E0| > bound (or a non-finite E, q or v) ends
//             the run failed there (FailureKind::kEnergy or kNonFinite); the
//             observer has seen every point before it
//   kRecord   a non-finite point ends the run; a point past the bound is
//             only recorded (RunReport::energy_exceeded_step, the first one)
//   kOff      no check (a system whose energy is not conserved)
// The runner's default (scene key "energy_limit": "auto") is max(|E0|, 1);
// the studies set theirs (stability: |E0|, recorded; fate map: |E0|, stop;
// work-precision: max(|E0|, 1), stop; long horizon: off, it reads the growth).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

struct EnergyLimit {
  enum class Mode { kOff, kStop, kRecord };
  Mode mode = Mode::kOff;
  double relative = 1.0;  // bound = max(relative |E0|, absolute)
  double absolute = 1.0;

  static EnergyLimit off() { return {}; }
  // max(|E0|, 1): the runner's default and the work-precision study's rule.
  static EnergyLimit runner_default() { return {Mode::kStop, 1.0, 1.0}; }
  // |E0|, stopping or recorded: the stability and fate-map studies' rule.
  static EnergyLimit relative_to_E0(Mode mode) { return {mode, 1.0, 0.0}; }
  // A fixed bound on |E - E0| (scene key "energy_limit": a number).
  static EnergyLimit absolute_bound(double bound) { return {Mode::kStop, 0.0, bound}; }

  bool on() const { return mode != Mode::kOff; }
  double bound(double E0) const { return std::max(relative * std::abs(E0), absolute); }
  // Is dE = |E - E0| past the bound?  A NaN is (it is not within any bound).
  bool exceeded(double dE, double E0) const { return !(dE <= bound(E0)); }
  // The rule in words, for failure reasons: "max(|E0|, 1)", "|E0|", "0.5".
  std::string describe() const {
    char buf[64];
    if (relative == 0) {
      std::snprintf(buf, sizeof buf, "%g", absolute);
    } else if (absolute == 0) {
      std::snprintf(buf, sizeof buf, relative == 1 ? "|E0|" : "%g |E0|", relative);
    } else {
      std::snprintf(buf, sizeof buf, relative == 1 ? "max(|E0|, %g)" : "max(%g |E0|, %g)",
                    relative == 1 ? absolute : relative, absolute);
    }
    return buf;
  }
};

// No check: integrate()'s default, so a loop without a guard is unchanged.
struct NoGuard {
  static constexpr bool active = false;
  template <class Sample>
  bool check(const Sample&, RunReport*) const {
    return true;
  }
};

template <class S>
class EnergyGuard {
 public:
  static constexpr bool active = true;
  EnergyGuard(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, const EnergyLimit& limit)
      : sys_(sys), limit_(limit), E0_(energy(sys, q0, v0)), bound_(limit.bound(E0_)) {}

  // false: the run ends failed at s.k (*rep says why).
  bool check(const Sample<S::n, S::m>& s, RunReport* rep) const {
    if (!limit_.on()) return true;
    const double dE = std::abs(energy(sys_, s.q, s.v) - E0_);
    if (!std::isfinite(dE) || !all_finite(s.q) || !all_finite(s.v)) {
      rep->fail(s.k, FailureKind::kNonFinite, "the state or its energy became non-finite (NaN or infinite)");
      rep->energy_error_at_limit = dE;
      rep->stopped_by_guard = true;
      return false;
    }
    if (dE <= bound_) return true;
    if (limit_.mode == EnergyLimit::Mode::kRecord) {
      if (rep->energy_exceeded_step < 0) {
        rep->energy_exceeded_step = s.k;
        rep->energy_error_at_limit = dE;
      }
      return true;
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, "the run blew up: |E - E0| = %.3g passed the energy limit %.3g (%s)", dE, bound_,
                  limit_.describe().c_str());
    rep->fail(s.k, FailureKind::kEnergy, buf);
    rep->energy_error_at_limit = dE;
    rep->stopped_by_guard = true;
    return false;
  }

  double E0() const { return E0_; }
  double bound() const { return bound_; }

 private:
  const S& sys_;
  EnergyLimit limit_;
  double E0_, bound_;
};

}  // namespace nhi
