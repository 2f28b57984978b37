// The bodies of DlaStepper's entry points (dla.hpp): the construction, start,
// step, next_guess and sample that run the step's solve and predictor (whose
// bodies, dla_predictor_body.hpp, come with these).  The library compiles
// them once for every registered system (lib/src/methods/dla_*.cpp); include
// this header only to instantiate DlaStepper for a system outside the
// registry (a test's own system).
#pragma once

#include "nhi/methods/dla/dla.hpp"
#include "nhi/methods/dla/dla_predictor_body.hpp"

namespace nhi {

template <class S, class D>
DlaStepper<S, D>::DlaStepper(const S& sys, const D& disc, DlaOptions options)
    : map_(sys, disc, 0.0, options), predictor_(map_.system(), map_.discretization()), omega_memo_(sys) {}

template <class S, class D>
void DlaStepper<S, D>::start(const VecN& q0, const VecN& v0) {
  q_prev_ = q_curr_ = q_next_ = q0;
  p_curr_ = p_next_ = p0_ ? *p0_ : momentum(map_.system(), q0, v0);
  v0_ = v0;
  lambda_ = lambda_prev_ = VecM::Zero();
  steps_ = 0;
  h_prev_ = h_ = 0;
  accepted_ = false;
}

template <class S, class D>
StepSummary DlaStepper<S, D>::step(double h) {
  // The start: the extrapolation, refined by the predictor's passes where refines(h).
  VecN guess, plain;
  VecM lambda_guess;
  bool settled = false;
  const bool accepted_last = accepted_;
  const bool predicted = start_guess(h, &guess, &lambda_guess);
  if (predicted) {
    predictor_.refine(map_.system(), map_.discretization(), h, q_next_, p_next_,
                      predictor_.passes(accepted_last, steps_), true, &omega_memo_, &guess, &lambda_guess, &settled);
    plain = extrapolation(h);
  }
  const VecM lambda_plain = lambda_;
  if (steps_ > 0) {
    q_prev_ = q_curr_;
    q_curr_ = q_next_;
    p_curr_ = p_next_;
  }
  lambda_prev_ = lambda_;
  lambda_ = lambda_guess;
  h_prev_ = h_;
  h_ = h;
  map_.set_h(h);
  // The solve of eq. (6) from the guess; first a residual check where the
  // passes settled, or where they refined a guess and the last check accepted
  // (the stages of a composition that follow no two steps in their own
  // direction get the plain extrapolation where the passes do not settle, refines()).
  const bool check = settled || (accepted_last && predicted);
  StepSummary st = map_.step(
      q_curr_, p_curr_, guess, &q_next_, &lambda_, &p_next_, check,
      [this, h](const Vec<double, n + Map::mc>& r, VecN* q1, VecM* lambda) { predictor_.polish(h, r, q1, lambda); },
      predicted ? &predictor_.Wt() : nullptr, &omega_memo_);
  accepted_ = st.ok() && st.jacobians == 0;  // the residual check took the guess
  if (!st.ok() && predicted) {
    // A large step can start outside Newton's basin from the predictor
    // (the sleigh at h = 2): retry from the plain start, the linear
    // extrapolation and the last multipliers, before the step fails.
    lambda_ = lambda_plain;
    StepSummary retry = map_.step(q_curr_, p_curr_, plain, &q_next_, &lambda_, &p_next_);
    retry.add_cost(st);
    retry.used_fallback = true;  // counted as a fallback step (RunReport::fallbacks)
    if (!retry.ok()) retry.message = "from the predictor: " + st.message + "; from the extrapolation: " + retry.message;
    st = retry;
  }
  ++steps_;
  step_failed(&st, all_finite(q_next_), "step solve for q_", steps_);
  return st;
}

template <class S, class D>
void DlaStepper<S, D>::sample(Sample<n, m>* s) const {
  s->has_p = true;
  s->q = q_curr_;
  s->v = steps_ == 1 ? v0_ : VecN((q_next_ - q_prev_) / (h_prev_ + h_));
  s->p = p_curr_;
  s->lambda = lambda_.template head<m>();
  s->discrete_constraint =
      discrete_constraint<S, D, double>(map_.system(), map_.discretization(), h_, q_curr_, q_next_);
}

template <class S, class D>
bool DlaStepper<S, D>::start_guess(double h, VecN* q_guess, VecM* lambda_guess) const {
  if (steps_ == 0) {
    *q_guess = q_curr_ + h * v0_;
    lambda_guess->setZero();
    return false;
  }
  *q_guess = extrapolation(h);
  if (!one_direction(h)) {
    *lambda_guess = lambda_;
    return refines(h);
  }
  *lambda_guess = h * (lambda_ / h_ + (h_ / h_prev_) * (lambda_ / h_ - lambda_prev_ / h_prev_));
  return true;
}

template <class S, class D>
void DlaStepper<S, D>::next_guess(double h, VecN* q_guess, VecM* lambda_guess, int passes, bool* settled,
                                  bool extend) const {
  if (settled) *settled = false;
  if (!start_guess(h, q_guess, lambda_guess)) return;
  Predictor predictor = predictor_;  // (copies: the stepper's own state is left as it is)
  typename Map::Problem::Memo memo = omega_memo_;
  predictor.refine(map_.system(), map_.discretization(), h, q_next_, p_next_, passes, extend, &memo, q_guess,
                   lambda_guess, settled);
}

}  // namespace nhi

// The library compiles DlaStepper for every registered system (lib/src/methods/dla_*.cpp):
// where this body is included, those instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::DlaStepper<nhi::S, nhi::AlphaDiscretization>; extern template class nhi::DlaStepper<nhi::S, nhi::SymmetricDiscretization>; extern template class nhi::DlaStepper<nhi::S, nhi::SplitDiscretization>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
