// The paper's claim at h = 0.2 (sections 6.1-6.2, Figures 1 and 3), as an
// assertion on each scene: over a long run the DLA (alpha = 1/2) energy error
// stays bounded while RK4's grows.
#include "scenes.hpp"

namespace nhi::test {
namespace {

template <class S>
class EnergyTest : public ::testing::Test {};
TYPED_TEST_SUITE(EnergyTest, PaperSystems);

// max |E - E0| over each sixteenth of a run of `steps` steps.
template <class S, class Integrate>
std::vector<double> bin_maxima(const S& sys, long steps, Integrate&& run) {
  Vec<double, S::n> q0, v0;
  scene_state<S>(&q0, &v0);
  const double E0 = energy(sys, q0, v0);
  std::vector<double> worst(16, 0.0);
  const RunReport rep = run(q0, v0, steps, [&](const Sample<S::n, S::m>& s) {
    const size_t bin = std::min<size_t>(15, static_cast<size_t>(16 * s.k / (steps + 1)));
    worst[bin] = std::max(worst[bin], std::abs(energy(sys, s.q, s.v) - E0));
    return true;
  });
  EXPECT_TRUE(rep.ok) << rep.reason;
  return worst;
}

TYPED_TEST(EnergyTest, DlaEnergyBoundedWhileRk4Drifts) {
  using S = TypeParam;
  const S sys = make_system<S>();
  const double h = 0.2;
  const long steps = 50000;  // T = 10^4
  const auto d = bin_maxima(sys, steps, [&](auto q0, auto v0, long n, auto&& obs) {
    return integrate(DlaStepper<S, AlphaDiscretization>(sys, AlphaDiscretization{0.5}), q0, v0, h, n, obs);
  });
  const auto r = bin_maxima(sys, steps, [&](auto q0, auto v0, long n, auto&& obs) {
    return integrate(Rk4Stepper<S>(sys), q0, v0, h, n, obs);
  });
  // DLA: the error in the last sixteenth is no larger than in the first (bounded oscillation).
  EXPECT_LE(d[15], 1.1 * d[0]) << d[0] << " " << d[15];
  // RK4: the error grows from quarter to quarter and ends far above its start.
  for (int i = 7; i < 16; i += 4) EXPECT_GT(r[i], r[i - 4]) << "bin " << i;
  EXPECT_GT(r[15], 5.0 * r[0]);
  // And on this horizon the DLA's bounded error is below RK4's final one.
  EXPECT_LT(d[15], r[15]);
}

}  // namespace
}  // namespace nhi::test
