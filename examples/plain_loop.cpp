// The user's own loop instead of nhi::integrate: start, step, sample, and a
// failed step handled.  The knife edge (knife_edge.hpp) with mp06 at h = 0.1,
// then with a deliberately absurd step, h = 1e200, whose state overflows:
// the step reports the failure, and the loop prints it and stops.
#include <cmath>
#include <cstdio>

#include "knife_edge.hpp"
#include "nhi/methods/mp06/mp06_body.hpp"  // mp06's step, compiled here for KnifeEdge

namespace {

long fail(long k, const nhi::StepSummary& step) {
  std::printf("  step %ld failed (%s): %s\n", k, nhi::to_string(step.failure), step.message.c_str());
  return k;
}

void print(const KnifeEdge& knife, double t, const nhi::Sample<3, 1>& s) {
  std::printf("  t = %6.1f  q = (%8.4f, %8.4f, %8.4f)  E = %.12f  omega(q) v = %9.2e\n", t, s.q[0], s.q[1], s.q[2],
              nhi::energy(knife, s.q, s.v), nhi::constraint_values(knife, s.q, s.v)[0]);
}

// Step from (q0, v0) with step h, printing every `every`-th point.  Returns
// the index of the step that failed, or 0 when none did.
template <class Stepper>
long loop(Stepper& stepper, const KnifeEdge& knife, double h, long steps, long every) {
  const nhi::Vec<double, 3> q0(0.0, 0.0, 0.0), v0(1.0, 0.0, 1.0);
  stepper.start(q0, v0);
  nhi::Sample<3, 1> s;
  for (long k = 1; k <= steps; ++k) {
    const nhi::StepSummary step = stepper.step(h);
    if (!step.ok()) return fail(k, step);  // step.failure and step.message say why
    stepper.sample(&s);                    // the point reached: s.q, s.v (mp06: s.p, s.lambda too)
    if (k % every == 0) print(knife, k * h, s);
  }
  return 0;
}

}  // namespace

int main() {
  const KnifeEdge knife;
  std::printf("mp06, h = 0.1:\n");
  nhi::Mp06Stepper<KnifeEdge> mp06(knife);
  if (loop(mp06, knife, 0.1, 1000, 200) != 0) return 1;

  std::printf("mp06, h = 1e200:\n");
  const long failed = loop(mp06, knife, 1e200, 10, 1);
  if (failed == 0) {
    std::printf("  expected a failed step, got none\n");
    return 1;
  }
  std::printf("  handled: the loop stopped at step %ld\n", failed);
  return 0;
}
