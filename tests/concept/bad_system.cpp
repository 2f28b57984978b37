// Types that are not systems, given to a stepper: each must fail to compile
// with the system concept's message for what it lacks (system.hpp,
// check_system; tests/CMakeLists.txt compiles one case per test).
#include "nhi/methods/explicit/rk4.hpp"
#include "nhi/methods/mp06/mp06.hpp"

namespace {

#if defined(NHI_CONCEPT_CASE_no_omega)
// A Lagrangian, but the constraint is given as a function of the velocity
// instead of as one-forms omega(q).
struct NoOmega {
  static constexpr int n = 2, m = 1;
  template <class T>
  T lagrangian(const nhi::Vec<T, 2>& q, const nhi::Vec<T, 2>& v) const {
    return nhi::cst<T>(0.5) * v.squaredNorm() - q.squaredNorm();
  }
  double constraint(const nhi::Vec<double, 2>& q, const nhi::Vec<double, 2>& v) const { return v[0] - q[1] * v[1]; }
};
[[maybe_unused]] nhi::Mp06Stepper<NoOmega> stepper{NoOmega{}};

#elif defined(NHI_CONCEPT_CASE_no_acceleration)
// A system for the implicit methods, without the index-reduced ODE RK4 needs.
struct NoAcceleration {
  static constexpr int n = 2, m = 1;
  template <class T>
  T lagrangian(const nhi::Vec<T, 2>& q, const nhi::Vec<T, 2>& v) const {
    return nhi::cst<T>(0.5) * v.squaredNorm() - q.squaredNorm();
  }
  template <class T>
  nhi::Mat<T, 1, 2> omega(const nhi::Vec<T, 2>& q) const {
    nhi::Mat<T, 1, 2> w;
    w << nhi::cst<T>(1.0), -q[1];
    return w;
  }
};
[[maybe_unused]] nhi::Rk4Stepper<NoAcceleration> stepper{NoAcceleration{}};

#elif defined(NHI_CONCEPT_CASE_no_dimensions)
// Dimensions as run-time members.
struct NoDimensions {
  int n = 2, m = 1;
};
[[maybe_unused]] nhi::Mp06Stepper<NoDimensions> stepper{NoDimensions{}};

#else
#error "compile with one NHI_CONCEPT_CASE_* defined"
#endif

}  // namespace
