// The body of EpsCayleyStepper::step (eps_cayley.hpp): the Newton solve of
// (DEPS) on its closed-form Jacobian, then the Cayley update of the
// quaternion and the nonholonomic Legendre transform of M_{k+1}.  The
// library compiles it once for every registered system
// (lib/src/methods/eps_cayley.cpp); include this header only to step a
// system outside the registry.
#pragma once

#include <string>

#include "nhi/methods/group/eps_cayley.hpp"

namespace nhi {

template <class S>
StepSummary EpsCayleyStepper<S>::step(double h) {
  StepSummary st;
  if constexpr (!kApplies) {
    st.failure = FailureKind::kSolve;
    st.message = std::string("eps_cayley steps a free rigid body with a left-invariant constraint on Omega "
                             "(the Suslov problem), not ") + S::name;
    return st;
  } else {
    // Start: y ~ h Omega(t_{k+1/2}); from the second step on the extrapolation
    // 2 h Omega_k - (h / h_{k-1}) y_{k-1} (also right for a step back, h_k = -h_{k-1}).
    Vec3 y = steps_ == 0 ? Vec3(h * Omega_) : Vec3(2.0 * h * Omega_ - (h / h_) * y_);
    Vec<double, 1> lambda(steps_ == 0 ? 0.0 : (h / h_) * lambda_);
    const Problem prob(J_, a_, J_.cwiseProduct(Omega_), h);  // M_k = J Omega_k (mod a)
    st = NewtonSolver<Problem>(prob, options_).solve(&y, &lambda);
    if (st.ok()) {
      const double s2 = s_ * s_, before = steps_ == 0 ? q0_.squaredNorm() : s2 * u_.squaredNorm();
      Vec<double, 4> c(1.0, 0.5 * y[0], 0.5 * y[1], 0.5 * y[2]);  // cay(y) on quaternions,
      c /= std::sqrt(1.0 + 0.25 * y.squaredNorm());               // (1, y/2) / sqrt(1 + |y|^2/4)
      u_ = quaternion::mul<double>(u_, c);
      u_.normalize();
      const Vec3 Jy = J_.cwiseProduct(y);
      const Vec3 M = (Jy - 0.5 * y.cross(Jy) + (0.25 * y.dot(Jy)) * y) / h;  // M_{k+1} = D2 L_d
      Omega_ = project(M.cwiseQuotient(J_));
      y_prev_ = y_;
      y_ = y;
      lambda_ = lambda[0];
      h_prev_ = h_;
      h_ = h;
      norm_rate_ = (s2 * u_.squaredNorm() - before) / (2 * h);
      ++steps_;
    }
    step_failed(&st, all_finite(u_) && all_finite(Omega_), "eps_cayley step ", steps_ + (st.ok() ? 0 : 1));
    return st;
  }
}

}  // namespace nhi

// Where this body is included, the registered systems' instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::EpsCayleyStepper<nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
