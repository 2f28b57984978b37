// The bodies of ReferenceStepper's start and step (reference.hpp), which run
// CVODE.  The library compiles them once for every registered system
// (lib/src/methods/reference.cpp); include this header only to run the reference
// solution on a system outside the registry (a test's own system).
#pragma once

#include "nhi/methods/reference/reference.hpp"

namespace nhi {

template <class S>
void ReferenceStepper<S>::start(const VecN& q0, const VecN& v0) {
  cv_ = std::make_unique<CvodeReference<S>>(sys_, 0.0, q0, v0, opt_);
  q_ = q0;
  v_ = v0;
  k_ = 0;
  rhs_ = steps_ = 0;
}

template <class S>
StepSummary ReferenceStepper<S>::step(double h) {
  StepSummary s;
  const bool ok = cv_->advance((k_ + 1) * h, &q_, &v_);
  ++k_;
  const long rhs = cv_->rhs_evaluations(), internal = cv_->internal_steps();
  s.rhs_evaluations = rhs - rhs_;
  s.internal_steps = internal - steps_;
  rhs_ = rhs;
  steps_ = internal;
  if (!ok) {
    s.failure = FailureKind::kSolve;
    s.message = "CVODE failed: " + cv_->message();
  } else if (!all_finite(q_) || !all_finite(v_)) {
    s.failure = FailureKind::kNonFinite;
    s.message = "state became non-finite at step " + std::to_string(k_);
  } else {
    s.status = SolveStatus::kConverged;
  }
  return s;
}

}  // namespace nhi

// The library compiles ReferenceStepper for every registered system (lib/src/methods/reference.cpp):
// where this body is included, those instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::ReferenceStepper<nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
