// Shared fixtures of the tests: the systems every contract runs on, random
// states on their constraint distributions, and a test-only unconstrained system.
#pragma once

#include <gtest/gtest.h>

#include <random>

#include "nhi/fit.hpp"
#include "nhi/integrate.hpp"
#include "nhi/systems/particle.hpp"
#include "nhi/systems/robot.hpp"

namespace nhi::test {

// Every scene the library has; typed tests run on each.
using Systems = ::testing::Types<Particle, Robot>;

template <class S>
S make_system() {
  return S{};
}

// The initial state of the scene files (experiments/scenes/*.json).
template <class S>
void scene_state(Vec<double, S::n>* q, Vec<double, S::n>* v) {
  if constexpr (std::is_same_v<S, Particle>) {
    *q << 1.0, 0.5, 0.0;
    *v << 0.5, 1.0, 0.25;
  } else {
    *q << 0.0, 0.0, 0.0, 0.0;
    *v << 1.0, 0.0, 1.0, 1.0;
  }
}

// A random configuration and a random velocity satisfying omega(q) v = 0.
template <class S>
void random_state(std::mt19937& rng, Vec<double, S::n>* q, Vec<double, S::n>* v) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const S sys = make_system<S>();
  for (int i = 0; i < S::n; ++i) (*q)[i] = u(rng);
  Vec<double, S::n> w;
  for (int i = 0; i < S::n; ++i) w[i] = u(rng);
  // Project w onto ker omega(q).
  const Mat<double, S::m, S::n> W = sys.template omega<double>(*q);
  const Mat<double, S::m, S::m> G = W * W.transpose();
  *v = w - W.transpose() * G.ldlt().solve(W * w);
}

// Harmonic oscillator with no constraints, L = 1/2 v^2 - 1/2 k q^2 (n = 1, m = 0):
// its DLA is a linear three-term recurrence with a closed-form solution.
struct Oscillator {
  static constexpr int n = 1;
  static constexpr int m = 0;
  static constexpr const char* name = "oscillator";
  double k = 1.0;
  template <class T>
  T lagrangian(const Vec<T, 1>& q, const Vec<T, 1>& v) const {
    return cst<T>(0.5) * v[0] * v[0] - cst<T>(0.5 * k) * q[0] * q[0];
  }
  template <class T>
  Mat<T, 0, 1> omega(const Vec<T, 1>&) const {
    return Mat<T, 0, 1>();
  }
  Vec<double, 1> acceleration(const Vec<double, 1>& q, const Vec<double, 1>&) const {
    return -k * q;
  }
};

inline double fitted_order(const std::vector<double>& h, const std::vector<double>& err) {
  return loglog_slope(h, err);
}

}  // namespace nhi::test
