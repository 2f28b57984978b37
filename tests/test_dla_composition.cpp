// The DLA composed by the triple jump: the variable-step recursion
//     D2 L_d^{h_{k-1}}(q_{k-1}, q_k) + D1 L_d^{h_k}(q_k, q_{k+1}) = omega(q_k)^T lambda_k
// with h_k cycling through gamma_1 h, gamma_2 h, gamma_3 h (gamma_1 = gamma_3 =
// 1/(2 - 2^(1/3)), gamma_2 = 1 - 2 gamma_1 < 0) is of order 4 in q after whole
// cycles, for alpha = 1/2 and the symmetric discretization with alpha = 0.
//
// Why, although the map (q_k, p_k) -> (q_{k+1}, p_{k+1}) on T*Q is not
// self-adjoint (dla.hpp): a step sees p_k only modulo omega(q_k)^T (lambda_k
// absorbs that component), and p_{k+1} = D2 L_d(q_k, q_{k+1}) depends only on
// positions.  So the DLA is a one-step map on (q, p mod omega(q)^T), and there
// h then -h is the identity (the momentum loses exactly omega(q_k)^T lambda_k):
// that map is self-adjoint and of order 2, which is all the triple jump needs.
// The start matters only through p_0 mod omega(q_0)^T: shifting p_0 along
// omega(q_0)^T changes nothing, an O(h^2) error in another direction costs
// the fourth order.
#include <cmath>
#include <cstdio>
#include <vector>

#include "scenes.hpp"

namespace nhi::test {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

const double kGamma1 = 1.0 / (2.0 - std::cbrt(2.0));
const std::vector<double> kTripleJump = {kGamma1, 1.0 - 2.0 * kGamma1, kGamma1};
const std::vector<double> kPlain = {1.0};

template <class S>
class DlaComposition : public ::testing::Test {};
TYPED_TEST_SUITE(DlaComposition, Systems);

// q(T) of the DLA from (q0, p0): `cycles` steps of h, each the substeps gamma_i h.
template <class S, class D>
Vec<double, S::n> q_end(const S& sys, const D& disc, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                        const Vec<double, S::n>& p0, double h, long cycles, const std::vector<double>& gamma) {
  DlaStepper<S, D> st(sys, disc);
  st.start_momentum(p0);
  st.start(q0, v0);
  for (long k = 0; k < cycles; ++k) {
    for (double g : gamma) {
      const StepSummary s = st.step(g * h);
      EXPECT_TRUE(s.ok()) << s.message;
      if (!s.ok()) return Vec<double, S::n>::Constant(std::nan(""));
    }
  }
  return st.phase().template head<S::n>();
}

// Fitted order of |q(T) - q_ref(T)| over h = 0.1 ... 0.003125, T = 4; p0 = p0_of(h).
template <class S, class D, class P0>
double fitted_q_order(const S& sys, const D& disc, const std::vector<double>& gamma, P0&& p0_of) {
  Vec<double, S::n> q0, v0, qref;
  scene_state<S>(&q0, &v0);
  const double T = 4.0;
  reference_solution(sys, q0, v0, T, 1e-13, &qref);
  std::vector<double> hs, errs;
  // On a rigid body's quaternion embedding the norm row, (|p_k+1|^2 - |p_k|^2) / h
  // (system.hpp, norm_increment), is solved to eps / h, and over 3 T / h solves that
  // round-off adds up to ~ 3 T eps / h^2, 1e-10 at h = 0.00625 (the Suslov body's
  // symmetric triple jump: 1.8e-10 there against 1.5e-9 / 16 at order 4): there
  // the fit stops at h = 0.0125.
  const double h_min = norm_row_of<S>::value >= 0 ? 0.01 : 0.003;
  for (double h = 0.1; h > h_min; h /= 2) {
    hs.push_back(h);
    errs.push_back(
        (q_end(sys, disc, q0, v0, p0_of(h, q0, v0), h, std::lround(T / h), gamma) - qref).cwiseAbs().maxCoeff());
  }
  // The finest triple-jump error is ~2e-10 and its local order still 4.0 on the
  // flat scenes; a finest point on a floor (the reference's, tol 1e-13, or the
  // solves') is dropped, as in MethodContract (fit.hpp).
  const OrderFit f = fit_order(hs, errs, 1e-11, 0, /*drop_floor_tail=*/true);
  std::printf("      errors");
  for (double e : errs) std::printf(" %.2e", e);
  std::printf("; local orders");
  for (const auto& l : f.local) std::printf(" %.2f", l.value_or(NAN));
  std::printf("\n");
  EXPECT_TRUE(f.order.has_value()) << "too few points above the floor";
  return f.order.value_or(std::nan(""));
}

template <class S, class D>
void check_orders(const S& sys, const D& disc) {
  const auto exact_p0 = [&](double, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0) {
    return momentum(sys, q0, v0);  // the stepper's own start, dL/dqdot(q0, v0)
  };
  // Off by h^2 along a direction d in the constraint distribution (ker omega(q0),
  // which pairs with it): (1, ..., 1) projected onto it (not v0, which is 0 in
  // the contact oscillators' default state).
  const auto h2_p0 = [&](double h, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0) {
    const Mat<double, S::m, S::n> W = sys.template omega<double>(q0);
    const Vec<double, S::n> w = Vec<double, S::n>::Ones();
    const Vec<double, S::n> d = w - W.transpose() * (W * W.transpose()).ldlt().solve(W * w);
    return Vec<double, S::n>(momentum(sys, q0, v0) + h * h * d);
  };
  const double plain = fitted_q_order(sys, disc, kPlain, exact_p0);
  const double tj = fitted_q_order(sys, disc, kTripleJump, exact_p0);
  const double tj_h2 = fitted_q_order(sys, disc, kTripleJump, h2_p0);
  std::printf("    %-9s %-24s plain %.3f, triple jump %.3f, triple jump with p0 + h^2 d %.3f\n", S::name,
              disc.name().c_str(), plain, tj, tj_h2);
  EXPECT_NEAR(plain, 2.0, 0.1) << disc.name();
  EXPECT_NEAR(tj, 4.0, 0.2) << disc.name() << ": the triple-jump DLA is no longer of order 4";
  EXPECT_NEAR(tj_h2, 2.0, 0.15) << disc.name() << ": an O(h^2) start error in D no longer limits the order";
}

TYPED_TEST(DlaComposition, TripleJumpIsFourthOrderInQ) {
  using S = TypeParam;
  const S sys = make_system<S>();
  check_orders(sys, AlphaDiscretization{0.5});
  check_orders(sys, SymmetricDiscretization{0.0});
}

// The mechanism: p0 + omega(q0)^T c gives the same q(T) as p0 (to round-off),
// through the sign changes of the triple jump, because lambda_0 absorbs c.
TYPED_TEST(DlaComposition, StartMattersOnlyModuloTheConstraintForms) {
  using S = TypeParam;
  const S sys = make_system<S>();
  Vec<double, S::n> q0, v0;
  scene_state<S>(&q0, &v0);
  const Vec<double, S::n> p0 = momentum(sys, q0, v0);
  const Vec<double, S::n> p0_shifted =
      p0 + sys.template omega<double>(q0).transpose() * Vec<double, S::m>::Constant(0.7);
  const double h = 0.05;
  const long cycles = 80;  // T = 4
  const auto check = [&](const auto& disc) {
    const Vec<double, S::n> a = q_end(sys, disc, q0, v0, p0, h, cycles, kTripleJump);
    const Vec<double, S::n> b = q_end(sys, disc, q0, v0, p0_shifted, h, cycles, kTripleJump);
    EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e4 * kEps * (1 + a.cwiseAbs().maxCoeff())) << disc.name();
  };
  check(AlphaDiscretization{0.5});
  check(SymmetricDiscretization{0.0});
}

}  // namespace
}  // namespace nhi::test
