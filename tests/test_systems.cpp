// Each scene's formulations agree: hand-written partials and index-reduced ODE
// against autodiff of L and omega; autodiff against finite differences; the
// fast D1/D2 L_d against autodiff of L_d itself (eqs. 9, 10).
#include "scenes.hpp"

namespace nhi::test {
namespace {

template <class S>
class SystemTest : public ::testing::Test {};
TYPED_TEST_SUITE(SystemTest, Systems);

TYPED_TEST(SystemTest, AutodiffPartialsMatchFiniteDifferences) {
  using S = TypeParam;
  constexpr int n = S::n;
  const S sys = make_system<S>();
  std::mt19937 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    Vec<double, n> q, v, dq, dv;
    random_state<S>(rng, &q, &v);
    autodiff_partials(sys, q, v, &dq, &dv);
    const double eps = 1e-6;
    for (int i = 0; i < n; ++i) {
      Vec<double, n> e = Vec<double, n>::Zero();
      e[i] = eps;
      const double fq =
          (sys.template lagrangian<double>(q + e, v) - sys.template lagrangian<double>(q - e, v)) / (2 * eps);
      const double fv =
          (sys.template lagrangian<double>(q, v + e) - sys.template lagrangian<double>(q, v - e)) / (2 * eps);
      EXPECT_NEAR(dq[i], fq, 1e-8 * (1 + std::abs(fq)));
      EXPECT_NEAR(dv[i], fv, 1e-8 * (1 + std::abs(fv)));
    }
  }
}

TYPED_TEST(SystemTest, OmegaJetDerivativesMatchFiniteDifferences) {
  using S = TypeParam;
  constexpr int n = S::n, m = S::m;
  using J = ceres::Jet<double, n>;
  const S sys = make_system<S>();
  std::mt19937 rng(2);
  for (int trial = 0; trial < 20; ++trial) {
    Vec<double, n> q, v;
    random_state<S>(rng, &q, &v);
    Vec<J, n> qj;
    for (int i = 0; i < n; ++i) qj[i] = J(q[i], i);
    const Mat<J, m, n> Wj = sys.template omega<J>(qj);
    const double eps = 1e-6;
    for (int k = 0; k < n; ++k) {
      Vec<double, n> e = Vec<double, n>::Zero();
      e[k] = eps;
      const Mat<double, m, n> fd = (sys.template omega<double>(q + e) - sys.template omega<double>(q - e)) / (2 * eps);
      for (int a = 0; a < m; ++a)
        for (int j = 0; j < n; ++j) {
          EXPECT_NEAR(Wj(a, j).v[k], fd(a, j), 1e-8);
          EXPECT_EQ(Wj(a, j).a, sys.template omega<double>(q)(a, j));
        }
    }
  }
}

TYPED_TEST(SystemTest, HandPartialsMatchAutodiffForDoubleAndJet) {
  using S = TypeParam;
  constexpr int n = S::n;
  using J = ceres::Jet<double, n>;
  if constexpr (!has_partials<S, double>::value) {
    GTEST_SKIP() << "system has no hand-written partials";
  } else {
    std::mt19937 rng(3);
    for (int trial = 0; trial < 20; ++trial) {
      // Non-default parameters on every trial but the first (defaults are often 1).
      const S sys = trial == 0 ? make_system<S>() : randomized_system<S>(rng);
      Vec<double, n> q, v, a1, b1, a2, b2;
      random_state<S>(rng, &q, &v, sys);
      sys.template partials<double>(q, v, &a1, &b1);
      autodiff_partials(sys, q, v, &a2, &b2);
      EXPECT_LE((a1 - a2).cwiseAbs().maxCoeff(), 1e-14 * (1 + a2.cwiseAbs().maxCoeff()));
      EXPECT_LE((b1 - b2).cwiseAbs().maxCoeff(), 1e-14 * (1 + b2.cwiseAbs().maxCoeff()));
      Vec<J, n> qj, vj, aj1, bj1, aj2, bj2;
      for (int i = 0; i < n; ++i) {
        qj[i] = J(q[i], i);
        vj[i] = J(v[i], (i + 1) % n);
      }
      sys.template partials<J>(qj, vj, &aj1, &bj1);
      autodiff_partials(sys, qj, vj, &aj2, &bj2);
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < n; ++k) {
          EXPECT_NEAR(aj1[i].v[k], aj2[i].v[k], 1e-13);
          EXPECT_NEAR(bj1[i].v[k], bj2[i].v[k], 1e-13);
        }
    }
  }
}

TYPED_TEST(SystemTest, HandAccelerationMatchesGenericIndexReduction) {
  using S = TypeParam;
  constexpr int n = S::n;
  std::mt19937 rng(4);
  for (int trial = 0; trial < 50; ++trial) {
    // Non-default parameters on every trial but the first (defaults are often 1).
    const S sys = trial == 0 ? make_system<S>() : randomized_system<S>(rng);
    Vec<double, n> q, v;
    random_state<S>(rng, &q, &v, sys);
    const Vec<double, n> a = sys.acceleration(q, v), g = generic_acceleration(sys, q, v);
    EXPECT_LE((a - g).cwiseAbs().maxCoeff(), 1e-13 * (1 + g.cwiseAbs().maxCoeff()));
    // The accelerations keep the velocity in the distribution:
    // d/dt (omega(q) v) = omega a + (d omega/dq v) v = 0, by a finite difference.
    const double dt = 1e-6;
    const auto c1 = constraint_values(sys, Vec<double, n>(q + dt * v), Vec<double, n>(v + dt * a));
    const auto c0 = constraint_values(sys, Vec<double, n>(q - dt * v), Vec<double, n>(v - dt * a));
    EXPECT_LE(((c1 - c0) / (2 * dt)).cwiseAbs().maxCoeff(), 1e-7);
  }
}

template <class S, class D>
void check_slots(const D& disc) {
  constexpr int n = S::n;
  const S sys = make_system<S>();
  std::mt19937 rng(5);
  const double h = 0.13;
  for (int trial = 0; trial < 10; ++trial) {
    Vec<double, n> q0, v, D1, D2;
    random_state<S>(rng, &q0, &v);
    const Vec<double, n> q1 = q0 + h * v;
    discrete_lagrangian_slots<S, D, double>(sys, disc, h, q0, q1, &D1, &D2);
    const Vec<double, n> A1 = discrete_lagrangian_slot<1, S, D, double>(sys, disc, h, q0, q1);
    const Vec<double, n> A2 = discrete_lagrangian_slot<2, S, D, double>(sys, disc, h, q0, q1);
    EXPECT_LE((D1 - A1).cwiseAbs().maxCoeff(), 1e-13 * (1 + A1.cwiseAbs().maxCoeff()));
    EXPECT_LE((D2 - A2).cwiseAbs().maxCoeff(), 1e-13 * (1 + A2.cwiseAbs().maxCoeff()));
  }
}

TYPED_TEST(SystemTest, DiscreteLagrangianSlotsMatchAutodiffOfLd) {
  for (double a : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    check_slots<TypeParam>(AlphaDiscretization{a});
    check_slots<TypeParam>(SymmetricDiscretization{a});
  }
}

TYPED_TEST(SystemTest, EnergyIsConservedAlongTheBenchmark) {
  // The index-reduced ODE conserves E = dL/dqdot.v - L (linear constraints).
  using S = TypeParam;
  constexpr int n = S::n;
  const S sys = make_system<S>();
  std::mt19937 rng(6);
  Vec<double, n> q, v;
  random_state<S>(rng, &q, &v);
  const double E0 = energy(sys, q, v);
  double worst = 0;
  integrate(ReferenceStepper<S>(sys), q, v, 0.1, 200, [&](const Sample<S::n, S::m>& s) {
    worst = std::max(worst, std::abs(energy(sys, s.q, s.v) - E0));
    return true;
  });
  EXPECT_LT(worst, 1e-9 * (1 + std::abs(E0)));
}

// particle.hpp writes omega's first two entries as one pair (-y)(1, 0), for
// speed: it is still the paper's row (-y, 0, 1), in double and in
// the Jet the solver differentiates, whatever the sign and size of y.
TEST(Particle, OmegaIsThePapersRowWrittenAsOnePair) {
  const Particle sys;
  for (double y : {0.5, -0.5, 0.0, -0.0, 1e300, -3e-310}) {
    const Vec<double, 3> q(0.7, y, -1.3);
    const Mat<double, 1, 3> w = sys.omega<double>(q);
    EXPECT_EQ(w[0], -y) << y;
    EXPECT_EQ(w[1], 0.0) << y;
    EXPECT_EQ(w[2], 1.0) << y;
    using J = ceres::Jet<double, 3>;
    Vec<J, 3> qj;
    for (int i = 0; i < 3; ++i) qj[i] = J(q[i], i);
    const Mat<J, 1, 3> wj = sys.omega<J>(qj);
    EXPECT_EQ(wj[0].a, -y);
    EXPECT_EQ(wj[1].a, 0.0);
    EXPECT_EQ(wj[2].a, 1.0);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(wj[0].v[i], i == 1 ? -1.0 : 0.0) << y << " " << i;
      EXPECT_EQ(wj[1].v[i], 0.0) << y << " " << i;
      EXPECT_EQ(wj[2].v[i], 0.0) << y << " " << i;
    }
  }
}

}  // namespace
}  // namespace nhi::test
