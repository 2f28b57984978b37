// The Constrained Coordinate Formulation (paper section 4, eqs. 17-19).
//  - Theorem 4.3: when the chart composed with the embedding is linear, the DLA
//    in V with holonomic constraints g(v) = 0 (eq. 17) and the DLA on Q (eq. 6)
//    are the same integrator: v_{k+1} = J(q_{k+1}), mu-bar = mu.
//  - The robot with its circles as unit vectors (a nonlinear embedding, outside
//    the theorem): a different second-order integrator; how it differs.
#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/systems/robot_extrinsic.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

// S embedded affinely in V = R^{n+1}: J(q) = (B q + c, a.q + c0), B invertible.
// Q = {g = 0}, g(v) = v_n - a.P(v) - c0 with P(v) = B^-1 (v_head - c) (P o J = id);
//   Lagrangian on V:  L(P v, B^-1 vd_head) + kappa/2 (vd_n - a.B^-1 vd_head)^2,
//   one-forms on V:   omega(P v) [B^-1  0].
// Along TJ the added term vanishes, so L o TJ = L and J^* omega-tilde = omega.
template <class S>
struct LinearlyEmbedded {
  static constexpr int n = S::n + 1, m = S::m, l = 1;
  static constexpr const char* name = "linearly embedded";
  S sys;
  Mat<double, S::n, S::n> B, Binv;
  Vec<double, S::n> c, a;
  double c0 = 0.3, kappa = 2.0;

  LinearlyEmbedded() {
    constexpr int k = S::n;
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) B(i, j) = (i == j ? 1.5 : 0.0) + 0.3 * std::sin(1.0 + i + 2.0 * j);
      c[i] = 0.1 * (i + 1);
      a[i] = 0.7 - 0.4 * i;
    }
    Binv = B.inverse();
  }
  template <class T>
  Vec<T, S::n> chart_of(const Vec<T, n>& v, bool affine) const {  // B^-1 (v_head - c), or B^-1 v_head
    Vec<T, S::n> q;
    for (int i = 0; i < S::n; ++i) {
      q[i] = cst<T>(0.0);
      for (int j = 0; j < S::n; ++j) q[i] += cst<T>(Binv(i, j)) * (affine ? v[j] - cst<T>(c[j]) : v[j]);
    }
    return q;
  }
  template <class T>
  T normal_part(const Vec<T, n>& v, const Vec<T, S::n>& q) const {  // v_n - a.q
    T s = v[S::n];
    for (int i = 0; i < S::n; ++i) s -= cst<T>(a[i]) * q[i];
    return s;
  }
  template <class T>
  T lagrangian(const Vec<T, n>& v, const Vec<T, n>& vd) const {
    const Vec<T, S::n> q = chart_of(v, true), qd = chart_of(vd, false);
    const T w = normal_part(vd, qd);
    return sys.template lagrangian<T>(q, qd) + cst<T>(0.5 * kappa) * w * w;
  }
  template <class T>
  Mat<T, m, n> omega(const Vec<T, n>& v) const {
    const Mat<T, m, S::n> W = sys.template omega<T>(chart_of(v, true));
    Mat<T, m, n> out;
    for (int r = 0; r < m; ++r) {
      for (int j = 0; j < S::n; ++j) {
        out(r, j) = cst<T>(0.0);
        for (int i = 0; i < S::n; ++i) out(r, j) += W(r, i) * cst<T>(Binv(i, j));
      }
      out(r, S::n) = cst<T>(0.0);
    }
    return out;
  }
  // A quaternion's norm row (the rigid bodies) stays the row it is, and the
  // DLA holds it as the level set of |p|^2 / 2 (system.hpp) in either coordinates.
  static constexpr int norm_row = norm_row_of<S>::value;
  template <class T>
  T norm_invariant(const Vec<T, n>& v) const {
    constexpr int qi = quaternion_at<S>::value;
    const Vec<T, S::n> q = chart_of(v, true);
    T g = cst<T>(0.0);
    for (int i = qi; i < qi + 4; ++i) g += q[i] * q[i];
    return cst<T>(0.5) * g;
  }
  template <class T>
  Vec<T, 1> g(const Vec<T, n>& v) const {
    return Vec<T, 1>(normal_part(v, chart_of(v, true)) - cst<T>(c0));
  }
  Mat<double, n, S::n> A() const {
    Mat<double, n, S::n> out;
    out.template topRows<S::n>() = B;
    out.template bottomRows<1>() = a.transpose();
    return out;
  }
  Vec<double, n> embed(const Vec<double, S::n>& q) const {
    Vec<double, n> v;
    v.template head<S::n>() = B * q + c;
    v[S::n] = a.dot(q) + c0;
    return v;
  }
};

template <class S>
class Theorem43 : public ::testing::Test {};
TYPED_TEST_SUITE(Theorem43, Systems);

// One step of each formulation from the same state, at every point of a run:
// (6) from (q_k, p_k) and (17) from (J q_k, D2 L-tilde_d(J q_{k-1}, J q_k)).
TYPED_TEST(Theorem43, LinearEmbeddingGivesTheSameIntegrator) {
  using S = TypeParam;
  constexpr int n = S::n, m = S::m;
  const S sys = make_system<S>();
  const LinearlyEmbedded<S> ext;
  const Mat<double, n + 1, n> A = ext.A();
  Vec<double, n> q0, v0;
  scene_state<S>(&q0, &v0);
  const double h = 0.1;
  for (double alpha : {0.5, 0.25, 1.0}) {
    const AlphaDiscretization disc{alpha};
    DlaStepper<S, AlphaDiscretization> in(sys, disc);
    const DlaMap<LinearlyEmbedded<S>, AlphaDiscretization> out(ext, disc, h);
    std::vector<Vec<double, n>> qs, ps;
    std::vector<Vec<double, m>> mus;
    ASSERT_TRUE(integrate(in, q0, v0, h, 300, [&](const Sample<n, m>& s) {
                  qs.push_back(s.q);
                  ps.push_back(s.p);
                  mus.push_back(s.lambda);
                  return true;
                }).ok);
    double worst_q = 0, worst_mu = 0, worst_p = 0;
    for (size_t k = 1; k + 1 < qs.size(); ++k) {
      const Vec<double, n + 1> va = ext.embed(qs[k - 1]), vb = ext.embed(qs[k]);
      Vec<double, n + 1> pt, v1, p1;
      discrete_lagrangian_slots<LinearlyEmbedded<S>, AlphaDiscretization, double>(ext, disc, h, va, vb, nullptr, &pt);
      Vec<double, m + 1> lam = Vec<double, m + 1>::Zero();
      const StepSummary st = out.step(vb, pt, vb + (vb - va), &v1, &lam, &p1);
      ASSERT_EQ(st.status, SolveStatus::kConverged) << st.message;
      const double qscale = 1.0 + qs[k + 1].cwiseAbs().maxCoeff();
      worst_q = std::max(worst_q, (v1 - ext.embed(qs[k + 1])).cwiseAbs().maxCoeff() / qscale);
      worst_mu = std::max(
          worst_mu, (lam.template head<m>() - mus[k]).cwiseAbs().maxCoeff() / (1.0 + mus[k].cwiseAbs().maxCoeff()));
      worst_p = std::max(
          worst_p, (A.transpose() * p1 - ps[k + 1]).cwiseAbs().maxCoeff() / (1.0 + ps[k + 1].cwiseAbs().maxCoeff()));
    }
    std::printf(
        "    %s, alpha = %g: one step of (17) vs (6): |v - J(q)| %.1e, |mu-bar - mu| %.1e, |A^T p-tilde - p| %.1e "
        "(relative)\n",
        S::name, alpha, worst_q, worst_mu, worst_p);
    // Round-off: the step is solved to a relative residual 1e-12 at most, and the
    // multiplier is the worst-conditioned output (it comes from a difference of momenta).
    EXPECT_LT(worst_q, 1e-12) << "alpha " << alpha;
    EXPECT_LT(worst_p, 1e-11) << "alpha " << alpha;
    EXPECT_LT(worst_mu, 1e-9) << "alpha " << alpha;
  }
}

// The whole run in V stays on Q and follows the run on Q.
TYPED_TEST(Theorem43, LinearEmbeddingRunStaysOnTheIntrinsicRun) {
  using S = TypeParam;
  constexpr int n = S::n, m = S::m;
  const S sys = make_system<S>();
  const LinearlyEmbedded<S> ext;
  Vec<double, n> q0, v0;
  scene_state<S>(&q0, &v0);
  const double h = 0.1;
  DlaStepper<S, AlphaDiscretization> in(sys, AlphaDiscretization{0.5});
  DlaStepper<LinearlyEmbedded<S>, AlphaDiscretization> out(ext, AlphaDiscretization{0.5});
  std::vector<Vec<double, n>> qs;
  ASSERT_TRUE(integrate(in, q0, v0, h, 1000, [&](const Sample<n, m>& s) {
                qs.push_back(s.q);
                return true;
              }).ok);
  double worst = 0, worst_g = 0;
  long k = 0;
  ASSERT_TRUE(integrate(out, ext.embed(q0), ext.A() * v0, h, 1000, [&](const Sample<n + 1, m>& s) {
                worst = std::max(worst, (ext.chart_of(s.q, true) - qs[k]).cwiseAbs().maxCoeff() /
                                            (1.0 + qs[k].cwiseAbs().maxCoeff()));
                // relative to |q|: the sleigh's position grows along its line
                worst_g =
                    std::max(worst_g, std::abs(ext.template g<double>(s.q)[0]) / (1.0 + s.q.cwiseAbs().maxCoeff()));
                ++k;
                return true;
              }).ok);
  std::printf("    %s: 1000 steps, max |P(v_k) - q_k| = %.1e (relative), max |g(v_k)| / (1 + |v_k|) = %.1e\n", S::name,
              worst, worst_g);
  EXPECT_LT(worst, 1e-10);  // round-off carried along 1000 steps of a non-chaotic flow
  EXPECT_LT(worst_g, 1e-13);
}

// ---- The robot with unit vectors: a nonlinear embedding --------------------

struct Trajectory {
  std::vector<Vec<double, 4>> q, v;  // in the angle chart
  double max_g = 0;
};

Trajectory intrinsic_run(double h, long steps) {
  Vec<double, 4> q0, v0;
  scene_state<Robot>(&q0, &v0);
  Trajectory tr;
  EXPECT_TRUE(integrate(DlaStepper<Robot, AlphaDiscretization>(Robot{}, AlphaDiscretization{0.5}), q0, v0, h, steps,
                        [&](const Sample<4, 2>& s) {
                          tr.q.push_back(s.q);
                          tr.v.push_back(s.v);
                          return true;
                        })
                  .ok);
  return tr;
}

// The extrinsic run, read back in the angle chart (velocities by the chart's
// tangent map applied to the central-difference velocity in V).
Trajectory extrinsic_run(double h, long steps) {
  Vec<double, 4> q0, v0;
  scene_state<Robot>(&q0, &v0);
  Trajectory tr;
  const RobotExtrinsic sys;
  DlaStepper<RobotExtrinsic, AlphaDiscretization> st(sys, AlphaDiscretization{0.5});
  Vec<double, 4> near = q0;
  EXPECT_TRUE(integrate(st, RobotExtrinsic::embed(q0), RobotExtrinsic::embed_velocity(q0, v0), h, steps,
                        [&](const Sample<6, 2>& s) {
                          const Vec<double, 4> q = RobotExtrinsic::chart(s.q, near);
                          near = q;
                          tr.q.push_back(q);
                          tr.v.push_back(RobotExtrinsic::chart_velocity(s.q, s.v));
                          tr.max_g = std::max(tr.max_g, sys.g<double>(s.q).cwiseAbs().maxCoeff());
                          return true;
                        })
                  .ok);
  return tr;
}

TEST(ExtrinsicRobot, StaysOnTheCirclesAndIsAnotherIntegrator) {
  const double h = 0.2;
  const Trajectory a = intrinsic_run(h, 50), b = extrinsic_run(h, 50);
  ASSERT_EQ(a.q.size(), b.q.size());
  double diff = 0;
  for (size_t k = 0; k < a.q.size(); ++k) diff = std::max(diff, (a.q[k] - b.q[k]).cwiseAbs().maxCoeff());
  std::printf("    h = 0.2, 50 steps: max |q_extrinsic - q_intrinsic| = %.2e; max |g| = %.1e\n", diff, b.max_g);
  EXPECT_LT(b.max_g, 1e-14);
  EXPECT_GT(diff, 1e-6);  // Theorem 4.3 does not apply: not the same integrator
}

TEST(ExtrinsicRobot, BothAreSecondOrder) {
  Vec<double, 4> q0, v0;
  scene_state<Robot>(&q0, &v0);
  const double T = 2.0;
  std::vector<double> hs, ein, eex, gap;
  for (double h : {0.1, 0.05, 0.025, 0.0125}) {
    const long steps = std::lround(T / h);
    Vec<double, 4> qT, vT;
    Robot{}.reduced_flow(q0, v0, T, 200000, &qT, &vT);
    const Trajectory a = intrinsic_run(h, steps), b = extrinsic_run(h, steps);
    hs.push_back(h);
    ein.push_back((a.q.back() - qT).cwiseAbs().maxCoeff());
    eex.push_back((b.q.back() - qT).cwiseAbs().maxCoeff());
    gap.push_back((a.q.back() - b.q.back()).cwiseAbs().maxCoeff());
  }
  const double s_in = loglog_slope(hs, ein), s_ex = loglog_slope(hs, eex), s_gap = loglog_slope(hs, gap);
  std::printf(
      "    order at T = 2: intrinsic %.2f, extrinsic %.2f, their difference %.2f; errors at h = 0.0125: %.2e, %.2e\n",
      s_in, s_ex, s_gap, ein.back(), eex.back());
  EXPECT_NEAR(s_in, 2.0, 0.15);
  EXPECT_NEAR(s_ex, 2.0, 0.15);
  EXPECT_NEAR(s_gap, 2.0, 0.15);  // they differ at O(h^2): different leading error terms
}

TEST(ExtrinsicRobot, EnergyStaysBounded) {
  // 20000 steps at h = 0.2 (t = 4000): no drift in either, compare halves.
  const double h = 0.2;
  const long steps = 20000;
  const Robot sys;
  for (int which = 0; which < 2; ++which) {
    const Trajectory tr = which == 0 ? intrinsic_run(h, steps) : extrinsic_run(h, steps);
    const double E0 = energy(sys, tr.q[0], tr.v[0]);
    double first = 0, second = 0;
    for (size_t k = 0; k < tr.q.size(); ++k) {
      const double dE = std::abs(energy(sys, tr.q[k], tr.v[k]) - E0);
      (k < tr.q.size() / 2 ? first : second) = std::max(k < tr.q.size() / 2 ? first : second, dE);
    }
    std::printf("    %s: max |E - E0| over t in [0, 2000] %.3e, over [2000, 4000] %.3e\n",
                which == 0 ? "intrinsic" : "extrinsic", first, second);
    // At h = 0.2 the oscillation is large (the robot's E0 is 1.5; see the README),
    // but it does not grow: the second half stays within 5% of the first.
    EXPECT_LT(second, 1.05 * first);
  }
}

}  // namespace
}  // namespace nhi::test
