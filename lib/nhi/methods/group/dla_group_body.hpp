// The body of GroupDlaStepper::step (dla_group.hpp): the Newton solve whose
// residual differentiates the discrete Lagrangian through exp and log with
// Jets of Jets, the heaviest code to compile.  The library compiles it once for
// every registered system (lib/src/methods/dla_group.cpp); include this header
// only to step a system outside the registry (a test's own system).
#pragma once

#include "nhi/methods/group/dla_group.hpp"

namespace nhi {

template <class S>
StepSummary GroupDlaStepper<S>::step(double h) {
  VecG y;
  if (steps_ == 0) {
    const Mat<double, n, ng> E = C::template tangent<double>(q_curr_);
    y = h * (E.transpose() * E).ldlt().solve(E.transpose() * v0_);
  } else {
    y = (h / h_) * y_;
  }
  VecL mu = steps_ == 0 ? VecL::Zero() : VecL(mu_);
  if (steps_ > 0) {
    q_prev_ = q_curr_;
    q_curr_ = q_next_;
    P_curr_ = P_next_;
    y_prev_ = y_;
  }
  h_prev_ = h_;
  h_ = h;
  const Problem prob(sys_, alpha_, h, q_curr_, P_curr_);
  StepSummary st = NewtonSolver<Problem>(prob, options_).solve(&y, &mu);
  if (st.ok()) {
    y_ = y;
    mu_ = mu;
    q_next_ = C::template retract<double>(q_curr_, y);
    if constexpr (C::kGroup) q_next_.template segment<4>(C::qi).normalize();
    P_next_ = group_slot<2, S, double>(sys_, alpha_, h, q_curr_, y);
  }
  ++steps_;
  step_failed(&st, all_finite(q_next_) && all_finite(P_next_), "group DLA step ", steps_);
  return st;
}

}  // namespace nhi

// Where this body is included, the registered systems' instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::GroupDlaStepper<nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
