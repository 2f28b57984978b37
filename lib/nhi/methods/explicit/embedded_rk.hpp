// Adaptive explicit Runge-Kutta pairs on the index-reduced ODE (the same
// q'' = a(q, q') as RK4 and the reference solution): Boost.Odeint's
// runge_kutta_fehlberg78 ("rkf78", Fehlberg's 7(8) pair, the order-8 solution
// propagated) and runge_kutta_dopri5 ("dopri5", Dormand-Prince 5(4), FSAL),
// each under odeint's error control with atol = rtol = tolerance.  They know
// nothing of the constraint, like RK4; the decision tables recommend them
// where no geometric property is asked for.
//
// As a stepper (stepper.hpp) h is the output interval: step(h) takes
// controlled steps from t_k to t_{k+1} = (k+1) h, the last one shortened to
// land on t_{k+1} exactly, as odeint's integrate_adaptive does at its end
// (its loop, Boost 1.74 integrate/detail/integrate_adaptive.hpp, reproduced
// step for step: one output interval h = T is integrate_adaptive over [0, T],
// bit for bit, with the first trial step 0.01 of the work-precision study).
// The proposed step carries over from one interval to the next.  A step is
// failed when the error control rejects 500 trial steps in a row (odeint's
// failed_step_checker), when an output interval needs more than max_steps
// accepted steps, or when the state stops being finite.
#pragma once

#include <boost/numeric/odeint/integrate/max_step_checker.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#include <boost/numeric/odeint/util/detail/less_with_sign.hpp>

#include <array>
#include <string>
#include <vector>

#include "nhi/methods/method_spec.hpp"
#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

// The pairs, by tag.
struct Rkf78Pair {
  static constexpr const char* name = "rkf78";
  static constexpr int order = 8;
  static constexpr int style = 61;  // its line style in the figures (StudyEntry)
  template <class State>
  using stepper = boost::numeric::odeint::runge_kutta_fehlberg78<State>;
};
struct Dopri5Pair {
  static constexpr const char* name = "dopri5";
  static constexpr int order = 5;
  static constexpr int style = 62;
  template <class State>
  using stepper = boost::numeric::odeint::runge_kutta_dopri5<State>;
};

// The state (q, v) as odeint holds it, and the right-hand side (q', v') = (v,
// a(q, v)), counting its evaluations.
template <class S>
using OdeState = std::array<double, 2 * S::n>;

template <class S>
struct OdeRhs {
  const S* sys;
  long* count;
  void operator()(const OdeState<S>& y, OdeState<S>& dy, double) const {
    constexpr int n = S::n;
    ++*count;
    const Vec<double, n> q = Eigen::Map<const Vec<double, n>>(y.data());
    const Vec<double, n> v = Eigen::Map<const Vec<double, n>>(y.data() + n);
    const Vec<double, n> a = sys->acceleration(q, v);
    for (int i = 0; i < n; ++i) {
      dy[i] = v[i];
      dy[n + i] = a[i];
    }
  }
};

struct EmbeddedRkOptions {
  double atol = kDefaultTolerance, rtol = kDefaultTolerance;
  double first_step = 0.01;     // the first trial step (the work-precision study's)
  long max_steps = 100000000L;  // accepted steps per output interval
};

template <class S, class Pair>
class EmbeddedRkStepper {
  static_assert(check_system_ode<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;
  using State = OdeState<S>;
  using Controlled =
      decltype(boost::numeric::odeint::make_controlled<typename Pair::template stepper<State>>(1.0, 1.0));

  explicit EmbeddedRkStepper(const S& sys, EmbeddedRkOptions opt = {})
      : sys_(sys),
        opt_(opt),
        ctl_(boost::numeric::odeint::make_controlled<typename Pair::template stepper<State>>(opt.atol, opt.rtol)) {}
  const S& system() const { return sys_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = Pair::order;
    t.adaptive = true;
    return t;
  }

  void start(const VecN& q0, const VecN& v0) {
    for (int i = 0; i < n; ++i) {
      x_[i] = q0[i];
      x_[n + i] = v0[i];
    }
    ctl_ = boost::numeric::odeint::make_controlled<typename Pair::template stepper<State>>(opt_.atol, opt_.rtol);
    t_ = 0;
    dt_ = opt_.first_step;
    k_ = 0;
  }

  // From t_k to t_{k+1} = (k+1) h (integrate_adaptive's loop, see above).
  StepSummary step(double h) {
    namespace odeint = boost::numeric::odeint;
    StepSummary s;
    long rhs = 0;
    const OdeRhs<S> f{&sys_, &rhs};
    const double end = double(k_ + 1) * h;
    if (!odeint::detail::less_with_sign(0.0, dt_, h)) dt_ = -dt_;  // a step backwards in time
    odeint::failed_step_checker fail_checker;
    try {
      while (odeint::detail::less_with_sign(t_, end, dt_)) {
        if (odeint::detail::less_with_sign(end, static_cast<double>(t_ + dt_), dt_)) dt_ = end - t_;
        odeint::controlled_step_result res;
        do {
          res = ctl_.try_step(f, x_, t_, dt_);
          if (res == odeint::fail) ++s.rejected_steps;
          fail_checker();
        } while (res == odeint::fail);
        fail_checker.reset();
        if (++s.internal_steps > opt_.max_steps) {
          s.failure = FailureKind::kSolve;
          s.message = "more than " + std::to_string(opt_.max_steps) + " accepted steps in one output interval";
          s.rhs_evaluations = rhs;
          return s;
        }
      }
    } catch (const odeint::step_adjustment_error&) {
      s.failure = FailureKind::kSolve;
      s.message = "the error control rejected 500 trial steps in a row (step size " + std::to_string(dt_) + ")";
      s.rhs_evaluations = rhs;
      return s;
    }
    s.rhs_evaluations = rhs;
    ++k_;
    bool finite = std::isfinite(t_) && std::isfinite(dt_);
    for (double xi : x_) finite &= std::isfinite(xi);
    if (finite) {
      s.status = SolveStatus::kConverged;
    } else {
      s.failure = FailureKind::kNonFinite;
      s.message = "state became non-finite at output point " + std::to_string(k_);
    }
    return s;
  }

  void sample(Sample<n, m>* s) const {
    s->q = Eigen::Map<const VecN>(x_.data());
    s->v = Eigen::Map<const VecN>(x_.data() + n);
  }
  Vec<double, 2 * n> phase() const { return Eigen::Map<const Vec<double, 2 * n>>(x_.data()); }

 private:
  S sys_;
  EmbeddedRkOptions opt_;
  Controlled ctl_;
  State x_{};
  double t_ = 0, dt_ = 0.01;
  long k_ = 0;
};

// The adaptive explicit pairs rkf78 and dopri5 (embedded_rk.hpp): the
// scene's tolerance is atol = rtol, h the output interval.  Only the
// work-precision study runs them (study_methods() lists them there).
template <class P>
struct EmbeddedRkMethod {
  using Pair = P;
  static constexpr const char* name = Pair::name;
  static constexpr bool adaptive = true;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = false;
  static constexpr double step_cost = 10.0;  // per output interval h
  static std::string label(const MethodSpec&) { return name; }
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    EmbeddedRkOptions opt;
    opt.atol = opt.rtol = spec.tolerance;
    EmbeddedRkStepper<S, Pair> st(sys, opt);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", Pair::style, true}}; }
};
template <class M>
struct is_embedded_rk : std::false_type {};
template <class P>
struct is_embedded_rk<EmbeddedRkMethod<P>> : std::true_type {};
using Rkf78Method = EmbeddedRkMethod<Rkf78Pair>;
using Dopri5Method = EmbeddedRkMethod<Dopri5Pair>;

}  // namespace nhi
