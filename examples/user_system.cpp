// A system of the user's own (knife_edge.hpp, not in the library's registry)
// integrated with mp06, its order-4 composition, the paper's DLA, RK4, the
// adaptive pair rkf78, the discrete gradient and a method of one's own
// (euler.hpp) through nhi::integrate, printing each
// method's energy error, constraint error and error against the closed form.  Exit 1 if a run fails or a
// method misses what its theory promises here.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "euler.hpp"
#include "knife_edge.hpp"
#include "nhi/all.hpp"  // every stepper, its step compiled here for KnifeEdge

namespace {

struct Errors {
  bool ok = false;
  double energy = 0, constraint = 0, position = 0;  // maxima over every step
};

// Run a stepper from (q0, v0) with step h; compare with the closed form.
template <class Stepper>
Errors run(const char* name, Stepper&& stepper, const KnifeEdge& knife, double h, long steps) {
  const nhi::Vec<double, 3> q0(0.0, 0.0, 0.0), v0(1.0, 0.0, 1.0);  // along the x axis, turning at 1 rad/s
  const double E0 = nhi::energy(knife, q0, v0);
  Errors e;
  const nhi::RunReport report = nhi::integrate(stepper, q0, v0, h, steps, [&](const nhi::Sample<3, 1>& s) {
    nhi::Vec<double, 3> q, v;
    knife.exact(q0, v0, s.t, &q, &v);
    e.energy = std::max(e.energy, std::abs(nhi::energy(knife, s.q, s.v) - E0));
    e.constraint = std::max(e.constraint, std::abs(nhi::constraint_values(knife, s.q, s.v)[0]));
    e.position = std::max(e.position, (s.q - q).cwiseAbs().maxCoeff());
    return true;  // false would stop the run
  });
  e.ok = report.ok;
  if (!report.ok)
    std::printf("%-22s failed at step %ld: %s\n", name, report.failure_step, report.reason.c_str());
  else
    std::printf("%-22s order %d  max |E - E0| %8.2e  max |omega(q) v| %8.2e  max |q - q_exact| %8.2e\n", name,
                stepper.traits().order, e.energy, e.constraint, e.position);
  return e;
}

}  // namespace

int main() {
  const KnifeEdge knife;
  const double h = 0.1;
  const long steps = 1000;  // T = 100, 16 turns of the blade
  std::printf("knife edge on an inclined plane, h = %g, T = %g\n", h, h * steps);
  const Errors mp06 = run("mp06", nhi::Mp06Stepper<KnifeEdge>(knife), knife, h, steps);
  const Errors tj = run("mp06 + triple_jump",
                        nhi::Composed<nhi::Mp06Stepper<KnifeEdge>>(nhi::Mp06Stepper<KnifeEdge>(knife),
                                                                    nhi::composition("triple_jump")),
                        knife, h, steps);
  const Errors dla = run("dla (alpha = 1/2)",
                         nhi::DlaStepper<KnifeEdge, nhi::AlphaDiscretization>(knife, nhi::AlphaDiscretization{0.5}),
                         knife, h, steps);
  const Errors rk4 = run("rk4", nhi::Rk4Stepper<KnifeEdge>(knife), knife, h, steps);
  const Errors euler = run("euler (euler.hpp)", nhi::EulerStepper<KnifeEdge>(knife), knife, h, steps);
  nhi::EmbeddedRkOptions tight;
  tight.atol = tight.rtol = 1e-10;
  const Errors rkf78 = run("rkf78 (tol 1e-10)", nhi::EmbeddedRkStepper<KnifeEdge, nhi::Rkf78Pair>(knife, tight), knife,
                           h, steps);
  const Errors dg = run("discrete_gradient", nhi::DiscreteGradientStepper<KnifeEdge>(knife), knife, h, steps);

  // What each method's theory says here: mp06 holds the constraint at
  // round-off, and its composition is the more accurate; RK4 does not hold
  // the constraint; Euler, of order 1, is the least accurate; rkf78 at
  // 1e-10 is the most accurate; the discrete gradient keeps the energy.
  const bool as_expected = mp06.ok && tj.ok && dla.ok && rk4.ok && euler.ok && rkf78.ok && dg.ok &&
                           mp06.constraint < 1e-12 && tj.constraint < 1e-12 && tj.position < mp06.position &&
                           rk4.constraint > 1e3 * mp06.constraint && euler.position > dla.position &&
                           rkf78.position < tj.position && dg.energy < 1e-12;
  if (!as_expected) std::printf("unexpected: a run failed or a method missed its theory's claim\n");
  return as_expected ? 0 : 1;
}
