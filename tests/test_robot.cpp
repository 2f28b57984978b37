// The robot's exact reduced description (theta linear in t, one equation for
// psi, x and y by quadrature) against the CVODE benchmark on the full
// index-reduced ODE: two independent formulations of the same motion.
#include "scenes.hpp"

namespace nhi::test {
namespace {

TEST(Robot, ReducedSolutionMatchesTheBenchmark) {
  for (int variant = 0; variant < 2; ++variant) {
    Robot sys;
    Vec<double, 4> q0, v0;
    scene_state<Robot>(&q0, &v0);
    if (variant == 1) {  // other parameters and a state off the defaults
      sys.mass = 2.0; sys.I = 0.5; sys.Iw = 0.2; sys.R = 0.7; sys.V0 = 3.0;
      q0 << 0.3, -1.0, 0.4, 2.0;
      const double thd = -0.8, psid = 1.3;
      v0 << sys.R * std::cos(q0[2]) * psid, sys.R * std::sin(q0[2]) * psid, thd, psid;
    }
    const double h = 0.5;
    double worst = 0;
    integrate(ReferenceStepper<Robot>(sys, ReferenceOptions{1e-12, 1e-12}), q0, v0, h, 80,
                        [&](const Sample<4, 2>& s) {
                          Vec<double, 4> q, v;
                          sys.reduced_flow(q0, v0, s.t, 2000, &q, &v);
                          worst = std::max(worst, (q - s.q).cwiseAbs().maxCoeff());
                          worst = std::max(worst, (v - s.v).cwiseAbs().maxCoeff());
                          return true;
                        });
    EXPECT_LT(worst, 1e-8) << "variant " << variant;
    EXPECT_GT(worst, 0.0);  // two computations, not one
  }
}

}  // namespace
}  // namespace nhi::test
