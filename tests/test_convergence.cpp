// What limits the order of the alpha != 1/2 DLA (the isolation runs), against
// the reference solution: the global error in q at T over a halving sequence of
// h, and the least-squares slope of log error against log h above the
// round-off floor.  That every method has the order it declares (section 4 of
// the paper: second order for alpha = 1/2 and the symmetric family, first
// order otherwise; RK4 fourth) is the method contract in test_methods.cpp.
#include <cstdio>

#include "scenes.hpp"

namespace nhi::test {
namespace {

template <class S>
class ConvergenceTest : public ::testing::Test {};
TYPED_TEST_SUITE(ConvergenceTest, Systems);

constexpr double kT = 4.0;

template <class S>
Vec<double, S::n> reference(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0) {
  Vec<double, S::n> q, v;
  reference_solution(sys, q0, v0, kT, 1e-13, &q, &v);
  return q;
}

template <class S, class Run>
double order_of(Run&& run_to_T) {
  const S sys = make_system<S>();
  std::mt19937 rng(21);
  Vec<double, S::n> q0, v0;
  random_state<S>(rng, &q0, &v0);
  const Vec<double, S::n> qref = reference(sys, q0, v0);
  std::vector<double> hs, errs;
  for (double h = 0.1; h > 0.003; h /= 2) {  // 0.1 .. 0.003125: asymptotic on both scenes
    const Vec<double, S::n> q = run_to_T(sys, q0, v0, h, std::lround(kT / h));
    const double e = (q - qref).cwiseAbs().maxCoeff();
    if (e > 1e-10) {  // above the round-off / benchmark floor
      hs.push_back(h);
      errs.push_back(e);
    }
  }
  EXPECT_GE(hs.size(), 3u) << "too few points above the floor to fit an order";
  const double p = fitted_order(hs, errs);
  std::printf("    fitted order %.3f over h = %g..%g (errors %.2e..%.2e)\n", p, hs.front(), hs.back(), errs.front(),
              errs.back());
  return p;
}

// consistent_start: p_0 = dL/dqdot + h (alpha_L - 1/2) dL/dq, the O(h) correction
// that makes p_0 match D2 L_d^alpha along the exact solution (the default start
// p_0 = dL/dqdot(q_0, v_0) is off by O(h) unless alpha = 1/2).
template <class S, class D>
double dla_order(const D& disc, bool consistent_start = false) {
  return order_of<S>([&](const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double h, long steps) {
    Vec<double, S::n> q, Lq, Lv;
    DlaStepper<S, D> st(sys, disc);
    autodiff_partials(sys, q0, v0, &Lq, &Lv);
    const Vec<double, S::n> p0 = consistent_start ? Vec<double, S::n>(Lv + h * (disc.nodes()[0].c - 0.5) * Lq) : Lv;
    st.start_momentum(p0);
    const RunReport rep = integrate(st, q0, v0, h, steps, [&](const Sample<S::n, S::m>& s) {
      q = s.q;
      return true;
    });
    EXPECT_TRUE(rep.ok) << rep.reason;
    return q;
  });
}

// Two separate causes, each enough on its own to cost one order:
//  - the start: p_0 = dL/dqdot(q_0, v_0) differs by h (alpha - 1/2) dL/dq from
//    D2 L_d^alpha along the exact solution; with the consistent start L_d^alpha
//    is second order for a natural Lagrangian L = T(v) - U(q) (`separable`), as
//    the paper says after eq. 10, citing [16]: then L_d^alpha - L_d^1/2 =
//    (alpha - 1/2) h^2 dL/dq . v + O(h^3) = -(alpha - 1/2) h^2 dU/dt, a discrete
//    gauge term.  Where dL/dq = 0 (the free sleigh, g = 0) L_d^alpha does not
//    depend on alpha and nothing is lost; where L is not natural (the gauge term
//    sin z zd of contact_oscillator_nr makes dL/dq . v = ... + cos z zd^2, not a
//    time derivative) L_d^alpha is first order whatever the start;
//  - the discrete constraint omega_d^alpha is first order whatever the start.
TYPED_TEST(ConvergenceTest, OffMidpointOrderIsLimitedByTheStartAndByOmegaD) {
  using S = TypeParam;
  const S sys = make_system<S>();
  Vec<double, S::n> q0, v0, Lq, Lv;
  scene_state<S>(&q0, &v0);
  autodiff_partials(sys, q0, v0, &Lq, &Lv);
  const bool force = Lq.cwiseAbs().maxCoeff() > 0;  // dL/dq = 0 at q0 (and everywhere): the free sleigh
  const bool natural = is_separable<S>::value;
  if constexpr (has_bilinear_kinematics<S>::value) {
    // A rigid body's bilinear kinematics (system.hpp): L_d^alpha and omega_d^alpha
    // agree with the midpoint's but for the radial term, and every rule is of order 2.
    for (double a : {0.0, 0.25}) {
      EXPECT_NEAR(dla_order<S>(SplitDiscretization{a, 0.5}), 2.0, 0.1) << "L_d^alpha, omega_d^1/2: alpha " << a;
      EXPECT_NEAR(dla_order<S>(SplitDiscretization{0.5, a}), 2.0, 0.1) << "L_d^1/2, omega_d^alpha: alpha " << a;
      EXPECT_NEAR(dla_order<S>(AlphaDiscretization{a}), 2.0, 0.1) << "L_d^alpha, omega_d^alpha: alpha " << a;
    }
    return;
  }
  for (double a : {0.0, 0.25}) {
    EXPECT_NEAR(dla_order<S>(SplitDiscretization{a, 0.5}), force ? 1.0 : 2.0, 0.15)
        << "L_d^alpha, omega_d^1/2, p_0 = dL/dqdot: alpha " << a;
    EXPECT_NEAR(dla_order<S>(SplitDiscretization{a, 0.5}, true), natural ? 2.0 : 1.0, natural ? 0.1 : 0.15)
        << "L_d^alpha, omega_d^1/2, consistent p_0: alpha " << a;
    EXPECT_NEAR(dla_order<S>(SplitDiscretization{0.5, a}), 1.0, 0.15) << "L_d^1/2, omega_d^alpha: alpha " << a;
    EXPECT_NEAR(dla_order<S>(AlphaDiscretization{a}, true), 1.0, 0.15)
        << "L_d^alpha, omega_d^alpha, consistent p_0: alpha " << a;
  }
}

}  // namespace
}  // namespace nhi::test
