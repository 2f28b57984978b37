// Boost.Odeint interoperability: any stepper of this library (stepper.hpp:
// the DLA, mp06, RK4, SPARK, a composition, ...) where odeint expects a stepper.
//
// OdeintStepper<St, State> models odeint's *Stepper* concept (stepper_category
// stepper_tag; state_type, deriv_type, value_type, time_type, order_type;
// order(); do_step(system, x, t, dt) and do_step(system, in, t, out, dt)), so
// integrate_const and integrate_n_steps drive it with any odeint observer,
// and integrate_times and integrate_adaptive too (for a stepper_tag stepper
// they take steps of dt, shortened to meet the given times; the fixed-step
// methods below refuse a shortened step).  An odeint user changes a line,
//     runge_kutta4<state_type> stepper;
//     nhi::OdeintStepper<nhi::Mp06Stepper<Knife>> stepper{nhi::Mp06Stepper<Knife>(knife)};
// and describes the system by its Lagrangian and constraint one-forms
// (system.hpp) instead of a right-hand side.
//
// The state x is (q, v), 2n numbers, q first: state_type is std::array<double,
// 2n> by default; any type with size() and operator[] (std::vector<double>, an
// Eigen vector) works as State.
//
// What it is not, and what follows:
//  - odeint's `system` argument is ignored (never called): the method owns its
//    system, given to the stepper's constructor.  Pass anything.
//  - No error estimate: not an ErrorStepper, ControlledStepper or
//    DenseOutputStepper, so no adaptive step size control.
//  - The stepper keeps state between calls that x does not hold: the momentum,
//    the multiplier guesses, the DLA's previous point.  A call continues from
//    it when x is, bit for bit, the state the last call wrote; otherwise (the
//    first call, x changed by the caller, after a failure or reset()) the
//    method starts afresh from x.  So the loop of integrate_const is the loop
//    of nhi::integrate() (integrate.hpp): the same trajectory bit for bit
//    (tests/test_odeint.cpp asserts it against `nhi run`), except that the
//    observer sees the first point as given, where `nhi run` reports the
//    method's own v_0 (mp06: V(q_0, p_0), equal to round-off).  odeint
//    copies its stepper argument: pass std::ref(stepper) to keep the state.
//  - Fixed step for the DLA (it reports point k once q_{k+1} is known) and
//    the reference solution (h is its output interval): a dt that differs
//    from the one they started with throws std::invalid_argument.  The other
//    methods take any dt at each call.
//  - integrate_const stops when t + dt exceeds the end time by more than
//    odeint's epsilon: with t = k dt rounded, pass an end time half a step past
//    the last point (or use integrate_n_steps) to get every step.
//  - A step that fails (no convergence, a non-finite state) throws StepFailed,
//    naming the step as `nhi run` does in failure.step; x is left at the last
//    point reached, and the next call starts afresh.
#pragma once

#include <boost/numeric/odeint/stepper/stepper_categories.hpp>

#include <array>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "nhi/roles/stepper.hpp"

namespace nhi {

// A step inside an odeint loop failed.  step: the index j of the first time
// point that could not be computed, counted from the (re)start as `nhi run`
// counts failure.step; time: t_j; reason: the stepper's message.
struct StepFailed : std::runtime_error {
  StepFailed(long step_index, double t, FailureKind k, const std::string& why)
      : std::runtime_error(what_of(step_index, t, why)), step(step_index), time(t), kind(k), reason(why) {}
  long step;
  double time;
  FailureKind kind;
  std::string reason;

 private:
  static std::string what_of(long j, double t, const std::string& why) {
    std::ostringstream os;
    os.precision(17);
    os << "nhi: step " << j << " (to t = " << t << ") failed: " << why;
    return os.str();
  }
};

template <class St, class State = std::array<double, 2 * St::n>>
class OdeintStepper {
 public:
  static constexpr int n = St::n, m = St::m;
  using stepper_category = boost::numeric::odeint::stepper_tag;
  using state_type = State;
  using deriv_type = State;
  using value_type = double;
  using time_type = double;
  using order_type = unsigned short;

  explicit OdeintStepper(St stepper) : st_(std::move(stepper)) {}

  // The method's declared global order (MethodTraits::order).
  order_type order() const { return static_cast<order_type>(st_.traits().order); }

  // x(t) -> x(t + dt) in place.
  template <class System, class StateInOut>
  void do_step(System&&, StateInOut& x, time_type t, time_type dt) {
    step_to(x, t, dt);
  }

  // in(t) -> out(t + dt).
  template <class System, class StateIn, class StateOut>
  void do_step(System&&, const StateIn& in, time_type t, StateOut& out, time_type dt) {
    check_size(in.size(), " input");
    check_size(out.size(), " output");
    for (int i = 0; i < 2 * n; ++i) out[i] = in[i];
    step_to(out, t, dt);
  }

  // Start afresh from the state of the next call.
  void reset() { started_ = false; }

  St& stepper() { return st_; }
  const St& stepper() const { return st_; }
  // The newest point the stepper reported (q, v and, where the method has
  // them, p, lambda and the discrete constraint; k counted from the start).
  const Sample<n, m>& last_sample() const { return s_; }

 private:
  template <class S>
  void check_size(const S& size, const char* which) const {
    if (static_cast<long>(size) != 2 * n)
      throw std::invalid_argument("nhi::OdeintStepper: the" + std::string(which) + " state has " +
                                  std::to_string(static_cast<long>(size)) + " entries, not 2n = " +
                                  std::to_string(2 * n) + " (q, then v)");
  }

  template <class X>
  bool is_last_written(const X& x) const {
    if (!started_) return false;
    for (int i = 0; i < 2 * n; ++i)
      if (!(x[i] == written_[i])) return false;
    return true;
  }

  // Take one step of the stepper; a failure throws StepFailed for point
  // index j at time tj.
  void advance(double dt, long j, double tj) {
    const StepSummary s = st_.step(dt);
    if (!s.ok()) {
      started_ = false;
      throw StepFailed(j, tj, s.failure, s.message);
    }
  }

  template <class X>
  void step_to(X& x, double t, double dt) {
    check_size(x.size(), "");
    const bool fixed = St::lag == 1 || st_.traits().adaptive;
    if (is_last_written(x)) {
      if (fixed && !(dt == h_)) {
        std::ostringstream os;
        os.precision(17);
        os << "nhi::OdeintStepper: this method takes a fixed step: dt = " << dt << " after " << h_
           << " (reset() or a new state restarts it)";
        throw std::invalid_argument(os.str());
      }
    } else {
      Vec<double, n> q, v;
      for (int i = 0; i < n; ++i) q[i] = x[i], v[i] = x[n + i];
      st_.start(q, v);
      k_ = 0;
      h_ = dt;
      started_ = true;
      if constexpr (St::lag == 1) advance(dt, 1, t + dt);  // q_1: point 0 is complete
    }
    // Point k_ + 1 (lag 1: needs q_{k_ + 2}).
    advance(dt, k_ + 1 + St::lag, t + (1 + St::lag) * dt);
    ++k_;
    st_.sample(&s_);
    s_.k = k_;
    s_.t = t + dt;
    for (int i = 0; i < n; ++i) {
      x[i] = s_.q[i];
      x[n + i] = s_.v[i];
      written_[i] = s_.q[i];
      written_[n + i] = s_.v[i];
    }
  }

  St st_;
  Sample<n, m> s_;
  bool started_ = false;
  long k_ = 0;
  double h_ = 0;
  std::array<double, 2 * n> written_{};
};

}  // namespace nhi
