// The bodies of DiscreteGradientStepper's members (discrete_gradient.hpp):
// the construction, start, map, step, sample and phase, which run the step's
// predictor (its bodies, discrete_gradient_predictor_body.hpp, come with
// these), solve and autodiff.  Included by the library's explicit
// instantiations (lib/src/methods/discrete_gradient.cpp), which compile them once for every
// registered system, and by code that instantiates DiscreteGradientStepper
// for a system outside the registry (a test's own system); code that
// includes only discrete_gradient.hpp links to the library's instances.
#pragma once

#include "nhi/methods/discrete_gradient/discrete_gradient.hpp"
#include "nhi/methods/discrete_gradient/discrete_gradient_predictor_body.hpp"

namespace nhi {

template <class S>
DiscreteGradientStepper<S>::DiscreteGradientStepper(const S& sys, SolverOptions options, bool endpoint)
    : sys_(sys), options_(options), endpoint_(endpoint), predictor_(sys_) {}

template <class S>
void DiscreteGradientStepper<S>::start(const VecN& q0, const VecN& v0) {
  q_ = q0;
  p_ = momentum(sys_, q0, v0);
  lambda_ = VecM::Zero();
  has_step_ = false;
  steps_ = 0;
  memory_ = {};
  memory_next_ = 0;
}

template <class S>
auto DiscreteGradientStepper<S>::explicit_guess(const Problem& prob, const VecM& lambda) const -> VecY {
  const double h = prob.h;
  const VecN& q0 = prob.q0;
  const VecN& p0 = prob.p0;
  const VecN qh = q0 + 0.5 * h * velocity<S, double>(sys_, q0, p0);
  const VecN pg = p0 + h * (force<S, double>(sys_, qh, p0) + sys_.template omega<double>(qh).transpose() * lambda);
  VecY y;
  y << qh + 0.5 * h * velocity<S, double>(sys_, qh, pg), pg, lambda;
  return y;
}

template <class S>
StepSummary DiscreteGradientStepper<S>::map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1,
                                            VecM* lambda) {
  const Problem prob(sys_, h, q0, p0, endpoint_);
  return endpoint_ ? map_endpoint(prob, q1, p1, lambda) : map_midpoint(prob, q1, p1, lambda);
}

template <class S>
StepSummary DiscreteGradientStepper<S>::map_endpoint(const Problem& prob, VecN* q1, VecN* p1, VecM* lambda) {
  // Newton from the midpoint form's step where its passes settle (a
  // separable system), which is O(h^3) from this one's: about one Newton
  // iteration fewer than from the explicit guess.  Else (the passes did not
  // settle, or there are none) from the explicit guess.
  VecY y = explicit_guess(prob, *lambda);
  if constexpr (is_separable<S>::value) {
    VecY z = y;
    if (predictor_.passes(Problem(sys_, prob.h, prob.q0, prob.p0), &z)) y = z;
  }
  // Plain Newton (a fresh Jacobian every iteration), not the chord steps;
  // then one more update from the accepted iterate (a second solve() from
  // it takes that update with no iteration counted; not when following
  // roots, where solve() would continue again): the energy identity holds
  // only as well as the rows are solved, and Newton accepts them at 16 eps
  // of their scale, which leaves several eps of the energy's terms a step.
  SolverOptions newton = options_;
  newton.refresh_ratio = 0;
  const NewtonSolver<Problem> solver(prob, newton);
  Vec<double, 0> none;
  StepSummary s = solver.solve(&y, &none);
  if (s.ok() && !newton.follows_roots()) {
    VecY polished = y;
    const StepSummary p = solver.solve(&polished, &none);
    s.add_cost(p);
    if (p.ok()) y = polished;
  }
  if (s.ok()) unpack(y, q1, p1, lambda);
  return s;
}

template <class S>
StepSummary DiscreteGradientStepper<S>::map_midpoint(const Problem& prob, VecN* q1, VecN* p1, VecM* lambda) {
  // Where the first pass is exact whatever its input
  // (DiscreteGradientPredictor::first_pass_exact) the passes start from z1 =
  // z0, where Gonzalez's correction is 0 with no energy to evaluate, and the
  // explicit guess is made only if they do not settle, for Newton (on the
  // particle, at h = 0.4 to 10, they settle or stall at round-off).
  bool trivial_start = false;
  if constexpr (is_separable<S>::value) trivial_start = predictor_.first_pass_exact(prob.h);
  VecY y;
  if (trivial_start)
    y << prob.q0, prob.p0, *lambda;
  else
    y = explicit_guess(prob, *lambda);
  // The passes' iterate is used only when they settle: an iterate they did
  // not settle is often already within newton()'s first test (16 eps of
  // the full scale), which it would accept without an iteration, leaving
  // a larger energy error than Newton's own iterations, which end far
  // below that test (the robot's triple jump).
  bool settled = false;
  if constexpr (is_separable<S>::value) {
    // The passes work on y itself, and a step they do not settle makes
    // the explicit guess again for Newton (the same values: a function of
    // q0, p0 and *lambda alone).  A copy of y for them, kept in case they
    // failed, would be a sizeable share of the particle's step: the copy and
    // the unpacking after it load 16 bytes from y just written by 8-byte
    // stores (a store-to-load forwarding stall, as in particle.hpp's omega).
    settled = predictor_.passes(prob, &y);
    if (!settled) y = explicit_guess(prob, *lambda);
    StepSummary s;
    if (settled && predictor_.settled_by_move() && !options_.continuation &&
        accept_settled(prob, &y, q1, p1, lambda, &s))
      return s;
  }
  Vec<double, 0> none;
  StepSummary s = NewtonSolver<Problem>(prob, options_).solve(&y, &none, settled);
  if (s.ok()) unpack(y, q1, p1, lambda);
  return s;
}

// Passes that ended on a plain pass settled by its move (no component moved
// by more than 4 eps of the terms of its residual row) are a fixed point of
// the step's equations to their rounding: the plain pass solves them exactly
// with c, omega and F frozen at its input, and its output is that input to 4
// eps.  The residual check would only confirm it, accepting it unchanged, so
// it is skipped (a check_settled_passes(true) stepper still runs it:
// tests/test_discrete_gradient.cpp,
// DiscreteGradientTest.DiscreteGradientSettledPassesNeedNoCheck).  Not on
// every step everywhere: over the 10^6 composed steps of the long-horizon
// study the check would move the contact oscillator's discrete gradient +
// triple jump and + order 6 by round-off.  A step so accepted reports no
// evaluation and relative_residual 0 (not evaluated).  Passes that settled by
// stalling at round-off still go to the check, as does every step when the
// tolerance asked for is below the check's own round-off test (16 eps: the
// check, not the passes, knows whether a residual meets it).  The test's
// bookkeeping (a copy of the iterate, a comparison) runs only on a
// check_settled_passes(true) stepper, off the common path.
template <class S>
bool DiscreteGradientStepper<S>::accept_settled(const Problem& prob, VecY* y, VecN* q1, VecN* p1, VecM* lambda,
                                                StepSummary* s) {
  ++settled_by_move_steps_;
  Vec<double, 0> none;
  if (check_settled_) {
    const VecY y_settled = *y;
    *s = NewtonSolver<Problem>(prob, options_).solve(y, &none, true);
    if (!s->ok() || s->jacobians > 0 || !(y->array() == y_settled.array()).all()) ++settled_checks_failed_;
    if (s->ok()) unpack(*y, q1, p1, lambda);
    return true;
  }
  if (!(options_.tolerance >= 16 * std::numeric_limits<double>::epsilon())) return false;
  s->status = SolveStatus::kConverged;
  if (options_.root_check)  // continued from the explicit guess, Newton's start (before unpack sets *lambda)
    s->root = NewtonSolver<Problem>(prob, options_).check_root(*y, none, explicit_guess(prob, *lambda), none);
  unpack(*y, q1, p1, lambda);
  return true;
}

template <class S>
StepSummary DiscreteGradientStepper<S>::step(double h) {
  VecN q1, p1;
  VecM lambda = lambda_;
  // The endpoint variant starts from the multiplier of the last steps of the
  // same h (a composition's stages each have their own), extrapolated from
  // the last two: second order in the explicit guess's momentum.
  StepMemory* mem = nullptr;
  if (endpoint_) {
    for (StepMemory& e : memory_)
      if (e.count > 0 && e.h == h) mem = &e;
    if (mem) lambda = mem->count >= 2 ? VecM(2.0 * mem->last - mem->prev) : mem->last;
  }
  StepSummary s = map(h, q_, p_, &q1, &p1, &lambda);
  ++steps_;
  if (step_failed(&s, all_finite(q1) && all_finite(p1), "discrete_gradient step ", steps_)) return s;
  if (endpoint_) {
    if (!mem) {
      mem = &memory_[memory_next_];
      memory_next_ = (memory_next_ + 1) % int(memory_.size());
      *mem = StepMemory{h, lambda, lambda, 0};
    }
    mem->prev = mem->last;
    mem->last = lambda;
    ++mem->count;
  }
  // The step's start and size, for its averaged constraint in sample().
  q_prev_ = q_;
  p_prev_ = p_;
  h_prev_ = h;
  has_step_ = true;
  q_ = q1;
  p_ = p1;
  lambda_ = lambda;
  return s;
}

template <class S>
void DiscreteGradientStepper<S>::sample(Sample<n, m>* s) const {
  s->has_p = true;
  s->q = q_;
  s->v = velocity<S, double>(sys_, q_, p_);
  s->p = p_;
  s->lambda = lambda_;
  s->discrete_constraint = VecM::Zero();
  if (endpoint_) {
    s->discrete_constraint = sys_.template omega<double>(q_) * s->v;
  } else if (has_step_) {
    const Problem prob(sys_, h_prev_, q_prev_, p_prev_);
    VecN Dq, Dp;
    prob.template discrete_gradient<double>(q_, p_, &Dq, &Dp);
    s->discrete_constraint = sys_.template omega<double>(VecN(0.5 * (q_prev_ + q_))) * Dp;
  }
}

template <class S>
auto DiscreteGradientStepper<S>::phase() const -> Vec<double, 2 * n> {
  Vec<double, 2 * n> z;
  z << q_, p_;
  return z;
}

}  // namespace nhi

// The library compiles DiscreteGradientStepper for every registered system (lib/src/methods/discrete_gradient.cpp):
// where this body is included, those instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::DiscreteGradientStepper<nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
