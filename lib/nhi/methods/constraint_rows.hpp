// The velocity constraint's rows omega(q1) v1 = 0, shared by the methods that
// hold it at the grid points: mp06 (eq. 4.18's last line, mp06.hpp), SPARK's
// grid-point rows (spark.hpp) and the endpoint discrete gradient
// (discrete_gradient.hpp).
#pragma once

#include <cmath>

#include "nhi/roles/core.hpp"

namespace nhi {

// omega(q1) v1 into r from row `first`, with the size of each row's terms
// (|omega_aj v_j| summed) for the solver's residual scale (terms may be null).
template <class T, int m, int n, int N>
void velocity_constraint_rows(const Mat<T, m, n>& W1, const Vec<T, n>& v1, int first, Vec<T, N>* r,
                              Vec<double, N>* terms) {
  for (int a = 0; a < m; ++a) {
    T c = cst<T>(0.0);
    double cs = 0;
    for (int j = 0; j < n; ++j) {
      c += W1(a, j) * v1[j];
      cs += std::abs(value_of(W1(a, j)) * value_of(v1[j]));
    }
    (*r)[first + a] = c;
    if (terms) (*terms)[first + a] = cs;
  }
}

}  // namespace nhi
