// The DLA on the rotation group through the varying chart (Remark 4.2,
// methods/group/dla_group.hpp): on a flat scene it is the DLA with the alpha
// rule, step for step; on the rigid bodies it stays on the group (|p| = 1 to
// round-off), holds <a, Omega> through its chart's discrete constraint,
// reproduces the Suslov problem's steady rotation to its order, returns after
// h then -h (alpha = 1/2), and keeps the energy bounded.
#include <cmath>

#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/methods/group/dla_group_body.hpp"
#include "nhi/runner/scene.hpp"
#include "nhi/systems/suslov.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

template <class St, int n, int m>
std::vector<Sample<n, m>> run_samples(St& st, const Vec<double, n>& q0, const Vec<double, n>& v0, double h,
                                      long steps) {
  std::vector<Sample<n, m>> out;
  const RunReport rep = integrate(st, q0, v0, h, steps, [&](const Sample<n, m>& s) {
    out.push_back(s);
    return true;
  });
  EXPECT_TRUE(rep.ok) << rep.reason;
  return out;
}

template <class S>
class GroupDlaFlat : public ::testing::Test {};
TYPED_TEST_SUITE(GroupDlaFlat, Systems);

// Without a quaternion the chart is the identity and the step is eq. (6) with
// L_d^alpha, omega_d^alpha: the same run as DlaStepper's, to the solves' tolerance.
TYPED_TEST(GroupDlaFlat, IsTheAlphaDlaOnAFlatScene) {
  using S = TypeParam;
  if constexpr (quaternion_at<S>::value < 0) {
    const S sys = make_system<S>();
    const auto q0 = S::default_q0(), v0 = S::default_v0();
    for (double alpha : {0.5, 0.25}) {
      GroupDlaStepper<S> g(sys, alpha);
      DlaStepper<S, AlphaDiscretization> d(sys, AlphaDiscretization{alpha});
      const auto a = run_samples<GroupDlaStepper<S>, S::n, S::m>(g, q0, v0, 0.05, 200);
      const auto b = run_samples<DlaStepper<S, AlphaDiscretization>, S::n, S::m>(d, q0, v0, 0.05, 200);
      ASSERT_EQ(a.size(), b.size());
      double dq = 0, scale = 1;
      for (size_t k = 0; k < a.size(); ++k) {
        dq = std::max(dq, (a[k].q - b[k].q).cwiseAbs().maxCoeff());
        scale = std::max(scale, b[k].q.cwiseAbs().maxCoeff());
      }
      std::printf("    %s, alpha = %g: %zu points, max |q_group - q_dla| = %.2e\n", S::name, alpha, a.size(), dq);
      EXPECT_LT(dq, 1e-9 * scale) << S::name << " alpha = " << alpha;
    }
  }
}

Vec<double, 4> suslov_q0() { return Suslov::default_q0(); }
Vec<double, 4> suslov_v0() { return Suslov::default_v0(); }

// On the Suslov problem with a principal axis the motion is a steady rotation
// (suslov.hpp; experiments/scenes/suslov_steady.json): the midpoint group DLA
// converges to it with order 2.
TEST(GroupDla, SuslovSteadyRotationAtOrderTwo) {
  const json sc = validate_scene(load_scene_file(std::string(NHI_SCENES) + "/suslov_steady.json"));
  Suslov sys;
  sys.a1 = sc["params"]["a1"], sys.a2 = sc["params"]["a2"], sys.a3 = sc["params"]["a3"];
  ASSERT_TRUE(sys.principal_axis());
  Vec<double, 4> q0, v0;
  for (int i = 0; i < 4; ++i) q0[i] = sc["q0"][i], v0[i] = sc["v0"][i];
  const double T = 4;
  std::vector<double> hs, errs;
  for (double h : {0.1, 0.05, 0.025, 0.0125}) {
    GroupDlaStepper<Suslov> st(sys, 0.5);
    const long steps = std::lround(T / h);
    const auto s = run_samples<GroupDlaStepper<Suslov>, 4, 2>(st, q0, v0, h, steps);
    Vec<double, 4> q, v;
    ASSERT_TRUE(sys.exact_solution(q0, v0, s.back().t, &q, &v));
    hs.push_back(h);
    errs.push_back((s.back().q - q).norm());
  }
  for (size_t i = 0; i < hs.size(); ++i) std::printf("    h = %g: |q(T) - q_exact(T)| = %.3e\n", hs[i], errs[i]);
  for (size_t i = 1; i < hs.size(); ++i) {
    const double order = std::log(errs[i - 1] / errs[i]) / std::log(hs[i - 1] / hs[i]);
    EXPECT_NEAR(order, 2.0, 0.1) << "h = " << hs[i];
  }
}

// The step stays on the group and holds its discrete constraint <a, xi> = 0;
// the energy stays bounded over 10^4 steps on the body with a not a principal axis.
TEST(GroupDla, StaysOnTheGroupAndHoldsTheConstraint) {
  Suslov sys;
  sys.a1 = 0.0, sys.a2 = 0.6, sys.a3 = 0.8;
  Vec<double, 4> q0(1, 0, 0, 0), v0;
  const Vec<double, 3> Om(-1.0, 0.0008, -0.0006);
  v0 << 0.0, 0.5 * Om;
  GroupDlaStepper<Suslov> st(sys, 0.5);
  const auto s = run_samples<GroupDlaStepper<Suslov>, 4, 2>(st, q0, v0, 0.01, 10000);
  const double E0 = energy(sys, q0, v0);
  double norm = 0, wd = 0, dE = 0;
  for (const auto& x : s) {
    norm = std::max(norm, std::abs(x.q.norm() - 1));
    wd = std::max(wd, std::abs(x.discrete_constraint[1]));
    dE = std::max(dE, std::abs(energy(sys, x.q, x.v) - E0));
  }
  std::printf("    %zu points: max ||p| - 1| = %.2e, max |<a, xi>|/h = %.2e, max |E - E0| = %.2e (E0 = %.4f)\n",
              s.size(), norm, wd, dE, E0);
  EXPECT_LT(norm, 16 * kEps);
  EXPECT_LT(wd, 1e-12);
  EXPECT_LT(dE, 1e-2 * E0);
}

// alpha = 1/2 is self-adjoint in the positions: a step of h, then one of -h
// from the reached state, returns to q_0.
TEST(GroupDla, StepOfHThenMinusHReturns) {
  const Suslov sys;
  GroupDlaStepper<Suslov> st(sys, 0.5), ref(sys, 0.5);
  st.start(suslov_q0(), suslov_v0());
  ref.start(suslov_q0(), suslov_v0());
  ASSERT_TRUE(ref.step(0.1).ok());  // q_1
  ASSERT_TRUE(st.step(0.1).ok());
  ASSERT_TRUE(st.step(0.1).ok());   // q_2
  ASSERT_TRUE(st.step(-0.1).ok());  // back from (q_2, P_2): q_1 again
  const double d = (st.phase().head<4>() - ref.phase().head<4>()).norm();
  std::printf("    h then -h: |q - q_1| = %.2e\n", d);
  EXPECT_LT(d, 1e-13);
}

}  // namespace
}  // namespace nhi::test
