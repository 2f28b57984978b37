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

// The default tolerance of every method that has one (the implicit methods'
// relative residual, the adaptive methods' rtol = atol): the scene's default.
inline constexpr double kDefaultTolerance = 1e-12;

template <class T, int N>
using Vec = Eigen::Matrix<T, N, 1>;
template <class T, int R, int C>
using Mat = Eigen::Matrix<T, R, C>;

// Is every entry finite?  The same test as Eigen's allFinite(), which
// computes (x - x) == (x - x) through an unrolled helper that GCC leaves out
// of line, a noticeable share of a particle DLA step.
template <class Derived>
inline bool all_finite(const Eigen::DenseBase<Derived>& x) {
  bool ok = true;
  for (Eigen::Index j = 0; j < x.cols(); ++j)
    for (Eigen::Index i = 0; i < x.rows(); ++i) ok &= std::isfinite(x.coeff(i, j));
  return ok;
}

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

// x * s for a constant s: for a first-order Jet the scalar product (the value
// and each derivative times s), cheaper than the Jet-by-Jet product with
// cst<T>(s) and equal to it bit for bit; otherwise x * cst<T>(s).
template <class T>
inline T scale(const T& x, double s) {
  if constexpr (is_jet<T>::value) {
    if constexpr (std::is_same_v<typename T::Scalar, double>) {
      return T(x.a * s, x.v * s);
    } else {
      return x * cst<T>(s);
    }
  } else {
    return x * s;
  }
}

// x / s for a constant s, the way ceres::Jet divides by a constant Jet (times
// 1/s, value and derivatives: the same bits, fewer operations); a double
// divides.
template <class T>
inline T divide(const T& x, double s) {
  if constexpr (is_jet<T>::value) {
    if constexpr (std::is_same_v<typename T::Scalar, double>) {
      const double inv = 1.0 / s;
      return T(x.a * inv, x.v * inv);
    } else {
      return x / cst<T>(s);
    }
  } else {
    return x / s;
  }
}

// What a stepper derives from the step size h (a matrix to invert, say), kept
// for the last two sizes: the stages of the triple jump and of Suzuki's
// composition alternate between two (the order-6 composition's five still
// miss).  at(h, make) returns the entry for h, made by make(h) when neither
// slot holds it (into the one not used last); current() the last one asked
// for (a default E before any).
template <class E>
class StepSizeCache {
 public:
  template <class Make>
  const E& at(double h, Make&& make) {
    if (!(h == h_[cur_])) {
      cur_ = 1 - cur_;
      if (!(h == h_[cur_])) {
        h_[cur_] = h;
        entry_[cur_] = make(h);
      }
    }
    return entry_[cur_];
  }
  const E& current() const { return entry_[cur_]; }

 private:
  E entry_[2] = {};
  double h_[2] = {0, 0};
  int cur_ = 0;
};

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
