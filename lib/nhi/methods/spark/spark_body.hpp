// The bodies of SparkStepper's members (spark.hpp): start, map, step, sample
// and phase, which run the step's solve and its autodiff.  Included by the
// library's explicit instantiations (lib/src/methods/spark*.cpp), which compile
// them once for every registered system, and by code that instantiates
// SparkStepper for a system outside the registry; code that includes only
// spark.hpp links to the library's instances.
#pragma once

#include "nhi/methods/spark/spark.hpp"

namespace nhi {

template <class S, int s>
void SparkStepper<S, s>::start(const VecN& q0, const VecN& v0) {
  q_ = q0;
  p_ = momentum(sys_, q0, v0);
  lambda_ = VecML::Zero();
  steps_ = 0;
}

template <class S, int s>
StepSummary SparkStepper<S, s>::map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1, VecML* lambda) const {
  const Problem prob(sys_, h, q0, p0);
  // Newton starts from the explicit step with the last step's multipliers.
  Vec<double, Problem::ny> y = prob.guess(*lambda);
  Vec<double, 0> none;
  StepSummary st = NewtonSolver<Problem>(prob, options_).solve(&y, &none);
  if (st.ok()) {
    *q1 = prob.template stage_q<double>(y, s - 1);
    *p1 = y.template segment<n>(Problem::kP1);
    *lambda = y.template tail<m * s>();
  }
  return st;
}

template <class S, int s>
StepSummary SparkStepper<S, s>::step(double h) {
  VecN q1, p1;
  VecML lambda = lambda_;
  StepSummary st = map(h, q_, p_, &q1, &p1, &lambda);
  ++steps_;
  if (step_failed(&st, all_finite(q1) && all_finite(p1), "spark step ", steps_)) return st;
  q_ = q1;
  p_ = p1;
  lambda_ = lambda;
  return st;
}

template <class S, int s>
void SparkStepper<S, s>::sample(Sample<n, m>* smp) const {
  smp->has_p = true;
  smp->q = q_;
  smp->v = velocity<S, double>(sys_, q_, p_);
  smp->p = p_;
  smp->lambda = lambda_.template tail<m>();
  smp->discrete_constraint = sys_.template omega<double>(q_) * smp->v;
}

template <class S, int s>
auto SparkStepper<S, s>::phase() const -> Vec<double, 2 * n> {
  Vec<double, 2 * n> z;
  z << q_, p_;
  return z;
}

}  // namespace nhi

// The library compiles SparkStepper for every registered system (lib/src/methods/spark*.cpp):
// where this body is included, those instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::SparkStepper<nhi::S, 2>; extern template class nhi::SparkStepper<nhi::S, 3>; extern template class nhi::SparkStepper<nhi::S, 4>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
