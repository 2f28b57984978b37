// The bodies of Mp06Stepper's members (mp06.hpp): the construction (with
// the structural probe explicit_structure), start, map, step, sample and
// phase, which run the step's solve and its autodiff.  Included by the
// library's explicit instantiations (lib/src/methods/mp06.cpp), which compile
// them once for every registered system, and by code that instantiates
// Mp06Stepper for a system outside the registry (a test's own system); code
// that includes only mp06.hpp links to the library's instances.
#pragma once

#include "nhi/methods/mp06/mp06.hpp"

namespace nhi {

template <class S, bool kSeparableForm>
Mp06Stepper<S, kSeparableForm>::Mp06Stepper(const S& sys, SolverOptions options, bool allow_explicit)
    : sys_(sys), vel_(sys), options_(options), explicit_(allow_explicit && explicit_structure(sys)) {}

// Is the step explicit?  For a separable system, q1 = q_half + (h/2) V(p_base
// + h omega(q_half)^T lambda), and when the rows of omega depend only on
// coordinates whose velocities the constraint force does not change (the
// particle: omega depends on y, the force acts on x and z; the robot: on
// theta, the force on x, y, psi; the contact and chaotic oscillators; the
// knife edge), omega(q1) does not depend on lambda and the constraint
// omega(q1) V(p1) = 0 is linear in lambda: one m x m solve.  Detected by
// autodiff: d omega(q1(lambda)) / d lambda is exactly zero (a structural
// zero, not a small number) at two unrelated states.
template <class S, bool kSeparableForm>
bool Mp06Stepper<S, kSeparableForm>::explicit_structure(const S& sys) {
  if constexpr (!kSeparable) {
    return false;
  } else {
    using J = ceres::Jet<double, m>;
    for (int probe = 0; probe < 2; ++probe) {
      VecN q0, p0;
      for (int i = 0; i < n; ++i) {
        q0[i] = probe_q(i, probe);
        p0[i] = probe_v(i, probe);
      }
      const SeparableVelocity<S> vel(sys);
      const Mp06SeparableProblem<S> prob(sys, vel, 0.3, q0, p0);
      Vec<J, m> lj;
      for (int a = 0; a < m; ++a) lj[a] = J(0.1 * (a + 1), a);
      Vec<J, n> q1, p1, v1;
      prob.template state<J>(lj, &q1, &p1, &v1);
      const Mat<J, m, n> W1 = sys.template omega<J>(q1);
      for (int a = 0; a < m; ++a)
        for (int j = 0; j < n; ++j)
          if (!(W1(a, j).v.array() == 0.0).all()) return false;
    }
    return true;
  }
}

template <class S, bool kSeparableForm>
void Mp06Stepper<S, kSeparableForm>::start(const VecN& q0, const VecN& v0) {
  q_ = q0;
  p_ = momentum(sys_, q0, v0);
  lambda_ = VecM::Zero();
  steps_ = 0;
}

template <class S, bool kSeparableForm>
StepSummary Mp06Stepper<S, kSeparableForm>::map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1,
                                                VecM* lambda) const {
  StepSummary s;
  if constexpr (kSeparable) {
    // One test per step picks V (SeparableVelocity in hamiltonian.hpp).
    if (vel_.identity()) return map_separable(IdentityVelocity{}, h, q0, p0, q1, p1, lambda);
    return map_separable(vel_, h, q0, p0, q1, p1, lambda);
  } else {
    const Mp06Problem<S> prob(sys_, h, q0, p0);
    Vec<double, n> y = prob.guess(q0, *lambda);
    VecM l = *lambda;
    s = NewtonSolver<Mp06Problem<S>>(prob, options_).solve(&y, &l);
    if (s.ok()) {
      prob.finish(y, l, q1, p1);
      *lambda = l;
    }
  }
  return s;
}

template <class S, bool kSeparableForm>
StepSummary Mp06Stepper<S, kSeparableForm>::step(double h) {
  VecN q1, p1;
  VecM lambda = lambda_;
  StepSummary s = map(h, q_, p_, &q1, &p1, &lambda);
  ++steps_;
  if (step_failed(&s, all_finite(q1) && all_finite(p1), "mp06 step ", steps_)) return s;
  q_ = q1;
  p_ = p1;
  lambda_ = lambda;
  return s;
}

template <class S, bool kSeparableForm>
void Mp06Stepper<S, kSeparableForm>::sample(Sample<n, m>* s) const {
  s->has_p = true;
  s->q = q_;
  s->v = velocity<S, double>(sys_, q_, p_);
  s->p = p_;
  s->lambda = lambda_;
  s->discrete_constraint = sys_.template omega<double>(q_) * s->v;
}

template <class S, bool kSeparableForm>
auto Mp06Stepper<S, kSeparableForm>::phase() const -> Vec<double, 2 * n> {
  Vec<double, 2 * n> z;
  z << q_, p_;
  return z;
}

}  // namespace nhi

// The library compiles Mp06Stepper for every registered system (lib/src/methods/mp06.cpp):
// where this body is included, those instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::Mp06Stepper<nhi::S, true>; extern template class nhi::Mp06Stepper<nhi::S, false>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
