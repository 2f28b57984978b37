// The bodies of DlaStepper's entry points (dla.hpp): the construction, start,
// step, next_guess and sample that run the step's solve and predictor.  The
// library compiles them once for every registered system (lib/src/methods/dla_*.cpp);
// include this header only to instantiate DlaStepper for a system outside the
// registry (a test's own system).
#pragma once

#include "nhi/dla.hpp"

namespace nhi {

template <class S, class D>
DlaStepper<S, D>::DlaStepper(const S& sys, const D& disc, DlaOptions options)
    : map_(sys, disc, 0.0, options), omega_memo_(sys) {
  if constexpr (kPassesSolveMultipliers) {
    // M^-1 (constant on a separable system) and kappa = sum_c w_c c (1 - c)
    // for the curvature of the passes (next_guess).
    Minv_ = inverse_mass_matrix(map_.system());
    passes_settle_ = constraint_force_misses_omega(map_.system());
    for (const Node& nd : map_.discretization().nodes()) kappa_ += nd.weight * nd.c * (1.0 - nd.c);
    // With kappa = 0 and passes that settle, the Gauss-Seidel pass
    // (run_passes) is exact in its first pass: one pass, then the check.
    gs_ = passes_settle_ && kappa_ == 0;
    if (kappa_ != 0) {
      // The curvature of the passes is used only where K is constant (a
      // quadratic potential) and not zero (K = 0: nothing to add).
      if (const auto K = constant_force_jacobian(map_.system())) {
        affine_potential_force_ = true;
        if ((K->array() != 0.0).any()) K_ = *K;
      } else {
        // A potential of one coordinate r (the robot's V0 sin psi): the
        // passes take its curvature at every pass (next_guess).
        const std::array<bool, n> reads = force_reads(map_.system());
        int count = 0;
        for (int j = 0; j < n; ++j)
          if (reads[j]) {
            ++count;
            curvature_coordinate_ = j;
          }
        if (count != 1) curvature_coordinate_ = -1;
      }
    }
  }
}

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
  VecN guess, plain;
  VecM lambda_guess;
  bool settled = false;
  const bool accepted_last = accepted_;
  predict(h, &guess, &lambda_guess,
          curvature_coordinate_ >= 0         ? kNewtonPasses
          : gs_ && accepted_last             ? 1
          : accepted_last || steps_ % 8 != 0 ? kMinPasses
                                             : kMaxPasses,
          &settled, true);
  const bool predicted = refines(h);  // next_guess refined q
  if (predicted) plain = extrapolation(h);
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
  // (Only a guess the passes refined is worth the check: where the passes
  // do not settle, the stages of a composition, none of which follows two
  // steps in its own direction, get the plain extrapolation, refines().)
  const bool check = settled || (accepted_last && predicted);
  StepSummary st = map_.step(
      q_curr_, p_curr_, guess, &q_next_, &lambda_, &p_next_, check,
      [this, h](const Vec<double, n + Map::mc>& r, VecN* q1, VecM* lambda) { polish(h, r, q1, lambda); },
      predicted ? &guess_Wt_ : nullptr, &omega_memo_);
  accepted_ = st.ok() && st.jacobians == 0;  // the residual check took the guess
  if (!st.ok() && predicted) {
    // A large step can start outside Newton's basin from the predictor
    // (the sleigh at h = 2): retry from the plain start, the linear
    // extrapolation and the last multipliers, before the step fails.
    lambda_ = lambda_plain;
    StepSummary retry = map_.step(q_curr_, p_curr_, plain, &q_next_, &lambda_, &p_next_);
    retry.iterations += st.iterations;
    retry.evaluations += st.evaluations;
    retry.jacobians += st.jacobians;
    retry.used_fallback = true;  // counted as a fallback step (RunReport::fallbacks)
    if (!retry.ok()) retry.message = "from the predictor: " + st.message + "; from the extrapolation: " + retry.message;
    st = retry;
  }
  ++steps_;
  if (st.status != SolveStatus::kConverged || !all_finite(q_next_)) {
    if (st.status == SolveStatus::kConverged) st.failure = FailureKind::kNonFinite;
    st.status = SolveStatus::kFailed;
    st.message = "step solve for q_" + std::to_string(steps_) +
                 " did not converge: " + (st.message.empty() ? "non-finite state" : st.message);
  }
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
void DlaStepper<S, D>::next_guess(double h, VecN* q_guess, VecM* lambda_guess, int passes, bool* settled,
                                  bool extend) const {
  predict(h, q_guess, lambda_guess, passes, settled, extend);
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
