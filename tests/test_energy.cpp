// The paper's claim at h = 0.2 (section 6.1, Figure 1), as an assertion: over a
// long run the DLA (alpha = 1/2) energy error stays bounded while RK4's grows.
#include "scenes.hpp"

namespace nhi::test {
namespace {

// max |E - E0| over each quarter of a run of `steps` steps.
template <class Integrate>
std::vector<double> quarter_maxima(const Particle& sys, long steps, Integrate&& run) {
  const Vec<double, 3> q0(1.0, 0.5, 0.0), v0(0.5, 1.0, 0.25);
  const double E0 = energy(sys, q0, v0);
  std::vector<double> worst(4, 0.0);
  const RunReport rep = run(q0, v0, steps, [&](const Sample<3, 1>& s) {
    const size_t quarter = std::min<size_t>(3, static_cast<size_t>(4 * s.k / (steps + 1)));
    worst[quarter] = std::max(worst[quarter], std::abs(energy(sys, s.q, s.v) - E0));
    return true;
  });
  EXPECT_TRUE(rep.ok) << rep.reason;
  return worst;
}

TEST(PaperClaim, DlaEnergyBoundedWhileRk4Drifts) {
  const Particle sys;
  const double h = 0.2;
  const long steps = 50000;  // T = 10^4
  DlaStepper<Particle, AlphaDiscretization> dla(sys, AlphaDiscretization{0.5}, h);
  const auto d = quarter_maxima(sys, steps, [&](auto q0, auto v0, long n, auto&& obs) {
    return integrate_dla(dla, q0, v0, n, obs);
  });
  const auto r = quarter_maxima(sys, steps, [&](auto q0, auto v0, long n, auto&& obs) {
    return integrate_rk4(Rk4Stepper<Particle>(sys, h), q0, v0, n, obs);
  });
  // DLA: the error in the last quarter is no larger than in the first (bounded oscillation).
  EXPECT_LE(d[3], 1.1 * d[0]) << d[0] << " " << d[3];
  // RK4: the error keeps growing from quarter to quarter and ends far above its start.
  for (int i = 1; i < 4; ++i) EXPECT_GT(r[i], r[i - 1]) << "quarter " << i;
  EXPECT_GT(r[3], 2.0 * r[0]);
  // And at this h the DLA's bounded error is below RK4's final one.
  EXPECT_LT(d[3], r[3]);
}

}  // namespace
}  // namespace nhi::test
