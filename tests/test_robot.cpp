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
      sys.mass = 2.0;
      sys.I = 0.5;
      sys.Iw = 0.2;
      sys.R = 0.7;
      sys.V0 = 3.0;
      q0 << 0.3, -1.0, 0.4, 2.0;
      const double thd = -0.8, psid = 1.3;
      v0 << sys.R * std::cos(q0[2]) * psid, sys.R * std::sin(q0[2]) * psid, thd, psid;
    }
    const double h = 0.5;
    double worst = 0;
    integrate(ReferenceStepper<Robot>(sys, ReferenceOptions{1e-12, 1e-12}), q0, v0, h, 80, [&](const Sample<4, 2>& s) {
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

// The DLA's fast path (predictor passes, residual check, polish) against the
// exact step: the root of eq. (6) from the same (q_k, p_k), refined in long
// double (the residual in long double, Newton corrections with the double
// Jacobian).  At h = 0.4 / 2^7, where theta (|q|_inf) has grown to ~60, the
// fast path's q_{k+1} is within a few hundredths of eps |q|_inf of it, with
// no bias; Newton from the plain start stops up to ~ eps |q|_inf / 2 away and
// biased (measured: psi off by +0.62 eps |q|_inf on average over 2e4 steps,
// mean |offset| 0.43-0.72 per coordinate, against |mean| <= 0.001 and mean
// |offset| <= 0.026 for the fast path).  So where the two differ at small h,
// the fast path is the accurate one.
TEST(Robot, DlaFastPathIsTheExactStepToRoundOff) {
  using S = Robot;
  using D = AlphaDiscretization;
  constexpr int n = S::n, mc = S::m;
  using VecN = Vec<double, n>;
  using VecL = Vec<long double, n>;
  const S sys;
  const D disc{0.5};
  const double h = 0.4 / 128;
  const auto exact_step = [&](const VecN& q, const VecN& p, VecN q1d, Vec<double, mc> l0) {
    const DlaStepProblem<S, D> prob(sys, disc, h, q, p);
    VecL q1 = q1d.cast<long double>();
    Vec<long double, mc> l = l0.cast<long double>();
    const VecL q0 = q.cast<long double>();
    const auto om = [&](int, const VecL& qc) { return sys.template omega<long double>(qc); };
    for (int it = 0; it < 3; ++it) {
      VecL D1;
      discrete_lagrangian_slots<S, D, long double>(sys, disc, (long double)h, q0, q1, &D1, nullptr);
      Vec<long double, n + mc> r;
      r.template head<n>() = p.cast<long double>() + D1 - prob.Wt().cast<long double>() * l;
      r.template tail<mc>() = discrete_constraint_with<S, D, long double>(sys, om, disc, (long double)h, q0, q1, nullptr);
      using J = ceres::Jet<double, n>;
      Vec<J, n> yj;
      for (int i = 0; i < n; ++i) yj[i] = J(double(q1[i]), i);
      Vec<J, n + mc> rj;
      Vec<double, n + mc> terms;
      prob.template residual<J>(yj, Vec<J, mc>(l.template cast<double>().template cast<J>()), &rj, &terms);
      Mat<double, n + mc, n + mc> K = Mat<double, n + mc, n + mc>::Zero();
      for (int i = 0; i < n + mc; ++i)
        for (int j = 0; j < n; ++j) K(i, j) = rj[i].v[j];
      K.template topRightCorner<n, mc>() = -prob.Wt();
      const Vec<double, n + mc> dx = K.partialPivLu().solve(Vec<double, n + mc>(r.template cast<double>()));
      q1 -= dx.template head<n>().template cast<long double>();
      l -= dx.template tail<mc>().template cast<long double>();
    }
    return q1;
  };
  DlaStepper<S, D> st(sys, disc);
  st.start(S::default_q0(), S::default_v0());
  double mean[n] = {}, mean_abs[n] = {};
  long count = 0;
  for (int k = 0; k < 20000; ++k) {
    const Vec<double, 2 * n> z = st.phase();
    const VecN q = z.template head<n>(), p = z.template tail<n>();
    ASSERT_TRUE(st.step(h).ok());
    if (k < 3) continue;
    const VecN q1 = st.phase().template head<n>();
    const VecL qx = exact_step(q, p, q1, st.lambda());
    const double unit = std::numeric_limits<double>::epsilon() * q.cwiseAbs().maxCoeff();
    for (int i = 0; i < n; ++i) {
      const double e = double((long double)q1[i] - qx[i]) / unit;
      mean[i] += e;
      mean_abs[i] += std::abs(e);
    }
    ++count;
  }
  double total = 0;
  for (int i = 0; i < n; ++i) {
    EXPECT_LE(std::abs(mean[i] / count), 0.05) << "coordinate " << i << ": a biased offset";
    EXPECT_LE(mean_abs[i] / count, 0.15) << "coordinate " << i;
    total += mean_abs[i];
  }
  EXPECT_GT(total, 0.0);  // the long-double root is not the double iterate itself
  EXPECT_GT(st.phase().template head<n>().cwiseAbs().maxCoeff(), 50.0);  // theta has grown: eps |q|_inf >> eps |psi|
}

}  // namespace
}  // namespace nhi::test
