// Shared fixtures of the tests: the systems every contract runs on, random
// states on their constraint distributions, and a test-only unconstrained system.
#pragma once

#include <gtest/gtest.h>

#include <random>

#include "nhi/methods/methods.hpp"
#include "nhi/readings/fit.hpp"
#include "nhi/roles/integrate.hpp"
#include "nhi/runner/run.hpp"
#include "nhi/systems/registry.hpp"

namespace nhi::test {

// Systems whose index-reduced flow is a quadrature (rolling_disk.hpp): there
// every Runge-Kutta method is symmetric (test_methods.cpp), and omega(q) v is
// constant along the flow.
template <class S, class = void>
struct is_quadrature_flow : std::false_type {};
template <class S>
struct is_quadrature_flow<S, std::enable_if_t<S::quadrature_flow>> : std::true_type {};

// Every registered scene (systems/registry.hpp); typed tests run on each, or on
// those that declare the capability a suite needs.
using Systems = nhi::Systems::apply<::testing::Types>;
using ReversibleSystems = filter_t<is_reversible, nhi::Systems>::apply<::testing::Types>;
using ReversibleIntegrableSystems = filter_t<is_reversible_integrable, nhi::Systems>::apply<::testing::Types>;
using SeparableSystems = filter_t<is_separable, nhi::Systems>::apply<::testing::Types>;
using ChaplyginSystems = filter_t<has_chaplygin_split, nhi::Systems>::apply<::testing::Types>;
using PaperSystems = filter_t<is_paper_scene, nhi::Systems>::apply<::testing::Types>;
using MomentumEquationSystems = filter_t<has_momentum_equation, nhi::Systems>::apply<::testing::Types>;

template <class S>
S make_system() {
  return S{};
}

// The system's default initial state (the numbers of experiments/scenes/NAME.json;
// test_scenes.cpp checks that they agree).
template <class S>
void scene_state(Vec<double, S::n>* q, Vec<double, S::n>* v) {
  *q = S::default_q0();
  *v = S::default_v0();
}

// The system with every parameter of its table drawn from [0.5, 2] (so that no
// coefficient is 1 and swapped or dropped coefficients show).
template <class S>
S randomized_system(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.5, 2.0);
  S sys;
  for (const auto& p : S::parameters()) sys.*(p.member) = u(rng);
  return sys;
}

// A random configuration and a random velocity satisfying omega(q) v = 0 (of sys).
template <class S>
void random_state(std::mt19937& rng, Vec<double, S::n>* q, Vec<double, S::n>* v, const S& sys = make_system<S>()) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int i = 0; i < S::n; ++i) (*q)[i] = u(rng);
  Vec<double, S::n> w;
  for (int i = 0; i < S::n; ++i) w[i] = u(rng);
  // A rigid body's orientation is a unit quaternion (its configuration space).
  constexpr int qi = quaternion_at<S>::value;
  if constexpr (qi >= 0) q->template segment<4>(qi).normalize();
  // Project w onto ker omega(q).
  const Mat<double, S::m, S::n> W = sys.template omega<double>(*q);
  const Mat<double, S::m, S::m> G = W * W.transpose();
  *v = w - W.transpose() * G.ldlt().solve(W * w);
  // ... turning at the default state's energy: a random angular velocity of a
  // random size on a body of inertia ratio 100 (the Suslov problem's) is a
  // motion faster than any step of the tests (h up to 0.2) resolves.
  if constexpr (qi >= 0) *v *= std::sqrt(energy(sys, S::default_q0(), S::default_v0()) / energy(sys, *q, *v));
}

// A random phase point: q_i, p_i uniform in [-r, r], drawn in turn.
template <int n>
void random_phase(std::mt19937& rng, double r, Vec<double, n>* q, Vec<double, n>* p) {
  std::uniform_real_distribution<double> u(-r, r);
  for (int i = 0; i < n; ++i) {
    (*q)[i] = u(rng);
    (*p)[i] = u(rng);
  }
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
  Vec<double, 1> acceleration(const Vec<double, 1>& q, const Vec<double, 1>&) const { return -k * q; }
};

inline double fitted_order(const std::vector<double>& h, const std::vector<double>& err) {
  return loglog_slope(h, err);
}

}  // namespace nhi::test
