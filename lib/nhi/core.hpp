// Shared vocabulary of the library: fixed-size vectors, scalar constants that
// work for double, ceres::Jet and Jets of Jets, and small helpers for autodiff.
//
// Physics is written once, templated on the scalar T.  Write constants as
// nhi::cst<T>(x), not T(x): ceres::Jet<ceres::Jet<double,a>,b> (the nested Jet the
// DLA step needs for the Jacobian of D1 L_d) has no constructor from double, and
// mixed Jet*double products do not compile for it either.
#pragma once

#include <ceres/jet.h>

#include <Eigen/Core>
#include <cmath>
#include <type_traits>

namespace nhi {

template <class T, int N>
using Vec = Eigen::Matrix<T, N, 1>;
template <class T, int R, int C>
using Mat = Eigen::Matrix<T, R, C>;

template <class T>
struct is_jet : std::false_type {};
template <class T, int N>
struct is_jet<ceres::Jet<T, N>> : std::true_type {};

// The constant x as a scalar of type T (recursively through nested Jets).
template <class T>
inline T cst(double x) {
  if constexpr (is_jet<T>::value) {
    return T(cst<typename T::Scalar>(x));
  } else {
    return T(x);
  }
}

// The double value at the bottom of a (possibly nested) Jet.
template <class T>
inline double value_of(const T& x) {
  if constexpr (is_jet<T>::value) {
    return value_of(x.a);
  } else {
    return static_cast<double>(x);
  }
}

}  // namespace nhi
