// The library's steppers where Boost.Odeint expects a stepper (nhi/interop/odeint.hpp):
// the knife edge (knife_edge.hpp) integrated by odeint's integrate_const with
// odeint's runge_kutta4 on the index-reduced ODE, then with nhi's mp06 by
// changing the stepper line; integrate_n_steps with mp06's order-4
// composition; and a failing step inside odeint's loop, caught as
// nhi::StepFailed.
#include <array>
#include <boost/numeric/odeint/integrate/integrate_const.hpp>
#include <boost/numeric/odeint/integrate/integrate_n_steps.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <cmath>
#include <cstdio>
#include <functional>

#include "knife_edge.hpp"
#include "nhi/interop/odeint.hpp"
#include "nhi/methods/composition.hpp"
#include "nhi/methods/mp06/mp06_body.hpp"

namespace odeint = boost::numeric::odeint;
using state_type = std::array<double, 6>;  // x = (q, v)

// The odeint user's system: dx/dt = (v, a(q, v)), the index-reduced ODE.
struct KnifeOde {
  KnifeEdge knife;
  void operator()(const state_type& x, state_type& dxdt, double /*t*/) const {
    const nhi::Vec<double, 3> q(x[0], x[1], x[2]), v(x[3], x[4], x[5]);
    const nhi::Vec<double, 3> a = knife.acceleration(q, v);
    for (int i = 0; i < 3; ++i) dxdt[i] = x[3 + i], dxdt[3 + i] = a[i];
  }
};

// An odeint observer: the largest energy error and constraint error seen.
struct Watch {
  KnifeEdge knife;
  double E0 = 0, energy = 0, constraint = 0;
  long points = 0;
  void operator()(const state_type& x, double /*t*/) {
    const nhi::Vec<double, 3> q(x[0], x[1], x[2]), v(x[3], x[4], x[5]);
    const double E = nhi::energy(knife, q, v);
    if (points++ == 0) E0 = E;
    energy = std::max(energy, std::abs(E - E0));
    constraint = std::max(constraint, std::abs(nhi::constraint_values(knife, q, v)[0]));
  }
  void print(const char* name) const {
    std::printf("%-42s %5ld points  max |E - E0| %8.2e  max |omega(q) v| %8.2e\n", name, points, energy, constraint);
  }
};

int main() {
  const KnifeEdge knife;
  const KnifeOde ode{knife};
  const state_type x0 = {0.0, 0.0, 0.0, 1.0, 0.0, 1.0};
  const double h = 0.1, T = 100.0;

  // An odeint user's loop, with odeint's RK4 ...
  odeint::runge_kutta4<state_type> stepper;
  state_type x = x0;
  Watch rk4{knife};
  odeint::integrate_const(stepper, ode, x, 0.0, T + h / 2, h, std::ref(rk4));
  rk4.print("odeint runge_kutta4, integrate_const");

  // ... and with nhi's mp06: the stepper line changed (the system is
  // ignored: mp06 has the knife edge's Lagrangian and constraint).
  x = x0;
  Watch nh{knife};
  nhi::OdeintStepper<nhi::Mp06Stepper<KnifeEdge>> mp06{nhi::Mp06Stepper<KnifeEdge>(knife)};
  odeint::integrate_const(mp06, ode, x, 0.0, T + h / 2, h, std::ref(nh));
  nh.print("nhi mp06, integrate_const");

  // integrate_n_steps with mp06's triple jump (order 4).
  using TripleJump = nhi::Composed<nhi::Mp06Stepper<KnifeEdge>>;
  nhi::OdeintStepper<TripleJump> tj{TripleJump(nhi::Mp06Stepper<KnifeEdge>(knife), nhi::composition("triple_jump"))};
  x = x0;
  Watch tw{knife};
  odeint::integrate_n_steps(tj, ode, x, 0.0, h, 1000, std::ref(tw));
  tw.print("nhi mp06 + triple_jump, integrate_n_steps");

  // A step that fails inside odeint's loop throws, naming the step: here a
  // deliberately absurd one, whose state overflows.
  x = x0;
  try {
    odeint::integrate_n_steps(mp06, ode, x, 0.0, 1e200, 10, [](const state_type&, double) {});
    std::printf("expected a failed step, got none\n");
    return 1;
  } catch (const nhi::StepFailed& e) {
    std::printf("nhi mp06 at h = 1e200 inside integrate_n_steps: %s\n", e.what());
  }
  const bool as_expected = nh.points == 1001 && tw.points == 1001 && nh.constraint < 1e-12 &&
                           tw.constraint < 1e-12 && tw.energy < nh.energy && rk4.constraint > 1e-9;
  return as_expected ? 0 : 1;
}
