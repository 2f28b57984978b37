// Scene: the non-reversible contact oscillator of Modin & Verdier ("What makes
// nonholonomic integrators work?", Numer. Math. 145, 2020): the contact
// oscillator (contact_oscillator.hpp) with the gauge term -dS(q) . v,
// S(q) = cos z, added to its Lagrangian:
//   L' = L + sin(z) zd,   same constraint xd + y zd = 0.
// The added term is a total time derivative (d/dt (-cos z)), so the
// Euler-Lagrange-d'Alembert equations, and with them every continuous
// trajectory q(t), are exactly those of contact_oscillator (the hand-written
// acceleration() below is the same, and tests/test_scenes.cpp derives it
// from L' by autodiff).  The momenta differ, p' = p - dS = p + (0, 0, sin z), so
// every method defined through L or (q, p) is another map here, and the
// reversing symmetry (q, v) -> (q, -v) does not leave L' invariant: not declared
// reversible.  The energy p' . v - L' is the same function of (q, v) as for L.
#pragma once

#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "nhi/systems/contact_oscillator.hpp"

namespace nhi {

struct ContactOscillatorNR {
  static constexpr int n = 3;
  static constexpr int m = 1;
  static constexpr const char* name = "contact_oscillator_nr";
  // Integrable like contact_oscillator, but not reversible under (q, v) -> (q, -v);
  // L' = 1/2 |v|^2 + a(q) . v - U(q) with a = (0, 0, sin z): not `separable`.
  // Its trajectories are contact_oscillator's, so the flow is reversible; the maps are not.
  static constexpr bool reversible_flow = true;

  double epsilon = 0.3;

  static auto parameters() { return std::array{Param<ContactOscillatorNR>{"epsilon", &ContactOscillatorNR::epsilon}}; }
  static Vec<double, 3> default_q0() { return ContactOscillator::default_q0(); }
  static Vec<double, 3> default_v0() { return ContactOscillator::default_v0(); }

  ContactOscillator base() const {
    ContactOscillator b;
    b.epsilon = epsilon;
    return b;
  }

  template <class T>
  T lagrangian(const Vec<T, 3>& q, const Vec<T, 3>& v) const {
    using std::sin;
    return base().lagrangian<T>(q, v) + sin(q[2]) * v[2];
  }

  template <class T>
  void partials(const Vec<T, 3>& q, const Vec<T, 3>& v, Vec<T, 3>* dLdq, Vec<T, 3>* dLdv) const {
    using std::cos;
    using std::sin;
    const T c = cos(q[2]), s = sin(q[2]);  // one sincos call (robot.hpp)
    base().partials<T>(q, v, dLdq, dLdv);
    (*dLdq)[2] += c * v[2];
    (*dLdv)[2] += s;
  }

  // V(q, p') = p' - (0, 0, sin z).
  template <class T>
  Vec<T, 3> velocity(const Vec<T, 3>& q, const Vec<T, 3>& p) const {
    using std::sin;
    Vec<T, 3> v = p;
    v[2] -= sin(q[2]);
    return v;
  }

  template <class T>
  Mat<T, 1, 3> omega(const Vec<T, 3>& q) const {
    return base().omega<T>(q);
  }

  Vec<double, 3> acceleration(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    return base().acceleration(q, v);
  }

  static constexpr int section_coordinate = ContactOscillator::section_coordinate;
  std::vector<std::pair<Vec<double, 3>, Vec<double, 3>>> section_states(int count) const {
    return base().section_states(count);
  }

  static std::array<const char*, 2> first_integral_names() { return ContactOscillator::first_integral_names(); }
  std::array<double, 2> first_integrals(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    return base().first_integrals(q, v);
  }
};

}  // namespace nhi
