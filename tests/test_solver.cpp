// The Newton solver shared by the implicit methods (solver.hpp): a start at
// round-off takes its update, and the failure path (no convergence, a
// non-finite state) ends a run the same way for every method.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "nhi/systems/robot_extrinsic.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

template <class S>
class SolverTest : public ::testing::Test {};
TYPED_TEST_SUITE(SolverTest, SeparableSystems);

template <class S>
class FailurePathTest : public ::testing::Test {};
TYPED_TEST_SUITE(FailurePathTest, Systems);

// NewtonSolver::newton: a start already within round-off (relative residual
// <= 16 eps) is accepted without an iteration, but moved by the update its
// first evaluation paid the Jacobian for.  mp06's reduced problem (lambda
// alone) at random states of every separable scene: from lambda* + d with
// d set so that the start's relative residual is ~8 eps, the result has at
// most half the start's residual (without the update it would be the start
// itself).  (Not its distance to lambda*: Newton's lambda* is itself
// accepted anywhere within 16 eps, further off than d on the sleigh.)
TYPED_TEST(SolverTest, NewtonStartAtRoundOffTakesItsUpdate) {
  using S = TypeParam;
  constexpr int m = S::m;
  std::mt19937 rng(43);
  double worst_rel = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const S rs = randomized_system<S>(rng);
    Vec<double, S::n> q0, p0;
    random_phase(rng, 2.0, &q0, &p0);
    using P = Mp06SeparableProblem<S>;
    const SeparableVelocity<S> vel(rs);
    const P prob(rs, vel, 0.2, q0, p0);
    const NewtonSolver<P> solver(prob);
    Vec<double, m> star = Vec<double, m>::Zero();
    Vec<double, 0> none;
    ASSERT_TRUE(solver.solve(&star, &none).ok()) << trial;
    // The residual is linear in d near lambda*: scale a probe to 8 eps.
    const Vec<double, m> probe = Vec<double, m>::Constant(1e-10 * (1 + star.cwiseAbs().maxCoeff()));
    const double rel_probe = solver.relative_residual(Vec<double, m>(star + probe), none);
    ASSERT_GT(rel_probe, 0) << trial;
    Vec<double, m> d = probe * (8 * kEps / rel_probe);
    d *= 8 * kEps / solver.relative_residual(Vec<double, m>(star + d), none);  // (not quite linear on the sleigh)
    Vec<double, m> y = star + d;
    const double rel_start = solver.relative_residual(y, none);
    ASSERT_GE(rel_start, 4 * kEps) << trial;
    ASSERT_LE(rel_start, 12 * kEps) << trial;
    const StepSummary s = solver.solve(&y, &none);
    ASSERT_TRUE(s.ok()) << trial;
    EXPECT_EQ(s.iterations, 0) << trial;
    EXPECT_EQ(s.jacobians, 1) << trial;
    // One evaluation, and the rounding terms where the start's residual is
    // above 16 eps of the scale without them (solver.hpp, rounding_terms).
    EXPECT_LE(s.evaluations, 2) << trial;
    const double rel = solver.relative_residual(y, none) / rel_start;
    EXPECT_LE(rel, 0.5) << trial;
    worst_rel = std::max(worst_rel, rel);
  }
  std::printf("[ %s ] start at 8 eps: residual after its update / the start's <= %.2g\n", S::name, worst_rel);
}

// The fallback's Jacobian in all N = ny + nl unknowns (FallbackCost: the
// y-columns from Newton's Jet pass, the multiplier columns (-Wt; 0) by the
// saddle-point form) is the Jacobian of Jets over all N unknowns, bit for bit,
// for the problems with multipliers apart from y: the DLA step (eq. 6, with
// the holonomic rows on the robot's extrinsic form) and mp06's velocity form.
template <class P>
void expect_fallback_jacobian_is_the_jet_pass(const P& prob, const Vec<double, P::ny>& y,
                                              const Vec<double, P::nl>& lambda) {
  constexpr int ny = P::ny, nl = P::nl, N = ny + nl;
  const NewtonSolver<P> solver(prob);
  Vec<double, N> x, r;
  x << y, lambda;
  Mat<double, N, N> J;
  ASSERT_TRUE(typename NewtonSolver<P>::FallbackCost{&solver}(x.data(), r.data(), J.data()));
  using Jt = ceres::Jet<double, N>;
  Vec<Jt, ny> yj;
  Vec<Jt, nl> lj;
  for (int i = 0; i < ny; ++i) yj[i] = Jt(y[i], i);
  for (int a = 0; a < nl; ++a) lj[a] = Jt(lambda[a], ny + a);
  Vec<Jt, N> rj;
  prob.template residual<Jt>(yj, lj, &rj, nullptr);
  for (int i = 0; i < N; ++i) {
    EXPECT_EQ(r[i], rj[i].a) << "row " << i;
    for (int j = 0; j < N; ++j) EXPECT_EQ(J(i, j), rj[i].v[j]) << "row " << i << ", column " << j;
  }
}

template <class S>
void expect_fallback_jacobians(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double h,
                               bool mp06) {
  const Vec<double, S::n> p0 = momentum(sys, q0, v0);
  const Vec<double, S::n> q1 = q0 + h * v0 + Vec<double, S::n>::Constant(1e-3);
  const AlphaDiscretization disc{0.5};
  using D = DlaStepProblem<S, AlphaDiscretization>;
  const D dla(sys, disc, h, q0, p0);
  expect_fallback_jacobian_is_the_jet_pass(dla, q1, Vec<double, D::nl>::Constant(0.1));
  if constexpr (S::m > 0) {
    if (!mp06) return;
    using M = Mp06Problem<S>;
    const M mp(sys, h, q0, p0);
    expect_fallback_jacobian_is_the_jet_pass(mp, Vec<double, S::n>(v0 + Vec<double, S::n>::Constant(0.01)),
                                             Vec<double, M::nl>::Constant(0.1));
  }
}

TEST(Solver, FallbackJacobianIsTheJetPassOverAllUnknowns) {
  Vec<double, 3> q, v;
  scene_state<Particle>(&q, &v);
  expect_fallback_jacobians(Particle(), q, v, 0.2, true);
  Vec<double, 4> qr, vr;
  scene_state<Robot>(&qr, &vr);
  expect_fallback_jacobians(Robot(), qr, vr, 0.2, true);
  // with the holonomic rows of eq. 17 among the multipliers
  expect_fallback_jacobians(RobotExtrinsic(), RobotExtrinsic::embed(qr), RobotExtrinsic::embed_velocity(qr, vr), 0.2,
                            false);
}

// The shared failure path: a solve that cannot reach its tolerance and a
// non-finite start end the run with status failed and the right kind, at the
// first step, with the points before it kept; a tiny step works.
TYPED_TEST(FailurePathTest, FailuresGoThroughTheSharedPath) {
  using S = TypeParam;
  const S sys = make_system<S>();
  for (const char* kind : {"mp06", "discrete_gradient"}) {
    for (const char* comp : {"none", "triple_jump"}) {
      MethodSpec spec = spec_of(kind, comp);
      long seen = 0;
      auto count = [&](const Sample<S::n, S::m>&) { return ++seen, true; };
      spec.tolerance = 1e-300;  // unreachable: Newton and the fallback both fail ...
      RunReport rep = run_method(sys, spec, S::default_q0(), S::default_v0(), 0.2, 10, count);
      // ... unless a residual is exactly zero: mp06 on a separable scene whose
      // constraint is linear in lambda (chaotic oscillator, sleigh) solves a step
      // in one exact Newton step, often to 0.  The same steps one by one: every
      // step that meets the tolerance has residual exactly 0, and the run fails,
      // through the shared path, at the first one that does not.
      long first_fail = 0;
      {
        const auto st = make_stepper(sys, spec);
        st->start(S::default_q0(), S::default_v0());
        for (long k = 1; k <= 10 && !first_fail; ++k) {
          const StepSummary sum = st->step(0.2);
          if (!sum.ok()) {
            first_fail = k;
          } else {
            EXPECT_EQ(sum.relative_residual, 0.0) << spec.label() << " step " << k << " met an unreachable tolerance";
          }
        }
      }
      if (std::string(kind) != "mp06") {
        EXPECT_EQ(first_fail, 1) << spec.label();
      }
      if (first_fail == 0) {
        EXPECT_TRUE(rep.ok) << spec.label();
      } else {
        EXPECT_FALSE(rep.ok) << spec.label();
        EXPECT_EQ(rep.failure, FailureKind::kSolve) << spec.label() << ": " << rep.reason;
        EXPECT_EQ(rep.failure_step, first_fail) << spec.label();
        EXPECT_EQ(seen, first_fail) << spec.label();
        EXPECT_NE(rep.reason.find(kind), std::string::npos) << rep.reason;
      }

      spec.tolerance = 1e-12;
      Vec<double, S::n> q0 = S::default_q0();
      q0[0] = std::numeric_limits<double>::quiet_NaN();
      seen = 0;
      rep = run_method(sys, spec, q0, S::default_v0(), 0.2, 10, count);
      EXPECT_FALSE(rep.ok) << spec.label();
      EXPECT_EQ(rep.failure, FailureKind::kNonFinite) << spec.label() << ": " << rep.reason;

      seen = 0;
      rep = run_method(sys, spec, S::default_q0(), S::default_v0(), 1e-9, 10, count);
      EXPECT_TRUE(rep.ok) << spec.label() << " tiny step: " << rep.reason;
      EXPECT_EQ(seen, 11);
    }
  }
}

// Root following (solver.hpp) on a scalar problem whose roots are known:
//     r(y) = (y - h (1 + y^2)) (y - 10).
// The first factor's roots are y = (1 -+ sqrt(1 - 4 h^2)) / 2h: the one that
// tends to 0 as h -> 0 (the continued root) and one near 1/h; they meet in a
// fold at h = 1/2 and do not exist beyond.  The second factor's root, 10,
// exists for every h but is not continued from h -> 0.
struct FoldProblem {
  static constexpr int ny = 1, nl = 0;
  double h;
  Mat<double, 1, 0> W_t;
  const Mat<double, 1, 0>& Wt() const { return W_t; }
  Vec<double, 1> y_scale(const Vec<double, 1>& y) const { return y.cwiseAbs(); }
  template <class T>
  void residual(const Vec<T, 1>& y, const Vec<T, 0>&, Vec<T, 1>* r, Vec<double, 1>* terms) const {
    const T f = y[0] - h * (1.0 + y[0] * y[0]), g = y[0] - 10.0;
    (*r)[0] = f * g;
    if (terms) {
      const double yv = value_of(y[0]);
      (*terms)[0] = (std::abs(yv) + std::abs(h) * (1 + yv * yv)) * (std::abs(yv) + 10);
    }
  }
  FoldProblem at_step(double h2) const { return FoldProblem{h2, W_t}; }
  void small_step_start(double ratio, Vec<double, 1>* y, Vec<double, 0>*) const { (*y)[0] *= ratio; }
};

double continued_root(double h) { return (1 - std::sqrt(1 - 4 * h * h)) / (2 * h); }

StepSummary solve_fold(double h, double start, double* y_out, bool continuation, bool root_check) {
  FoldProblem p{h, {}};
  SolverOptions opt;
  opt.continuation = continuation;
  opt.root_check = root_check;
  Vec<double, 1> y;
  y[0] = start;
  Vec<double, 0> none;
  const StepSummary s = NewtonSolver<FoldProblem>(p, opt).solve(&y, &none);
  *y_out = y[0];
  return s;
}

TEST(RootFollowing, ContinuationFindsTheRootFromZeroWhereTheStartFindsAnother) {
  static_assert(has_continuation<FoldProblem>::value);
  for (const double h : {0.1, 0.3, 0.45}) {
    const double yc = continued_root(h), y_far = (1 + std::sqrt(1 - 4 * h * h)) / (2 * h);
    for (const double start : {y_far * 1.02, 9.6, 0.9 * yc}) {
      double y = 0;
      // The start decides the root...
      const StepSummary plain = solve_fold(h, start, &y, false, false);
      ASSERT_TRUE(plain.ok()) << h << " " << start;
      EXPECT_EQ(plain.root, RootCheck::kUnchecked);
      const bool near_continued = std::abs(y - yc) <= 1e-10 * (1 + yc);
      EXPECT_TRUE(near_continued || std::abs(y - y_far) <= 1e-10 * y_far || std::abs(y - 10) <= 1e-10)
          << h << " " << start << " -> " << y;
      // ... the root check says which one it was (and leaves the root as it is) ...
      double y_checked = 0;
      const StepSummary checked = solve_fold(h, start, &y_checked, false, true);
      ASSERT_TRUE(checked.ok());
      EXPECT_EQ(y_checked, y);
      EXPECT_EQ(checked.root, near_continued ? RootCheck::kContinued : RootCheck::kOther) << h << " " << start;
      // ... and continuation finds the continued root from any start.
      double y_cont = 0;
      const StepSummary cont = solve_fold(h, start, &y_cont, true, false);
      ASSERT_TRUE(cont.ok()) << cont.message;
      EXPECT_EQ(cont.root, RootCheck::kContinued);
      EXPECT_NEAR(y_cont, yc, 1e-10 * (1 + yc)) << h << " " << start;
    }
  }
}

TEST(RootFollowing, BeyondTheFoldNoRootIsContinued) {
  double y = 0;
  // Newton from 9.6 finds 10, which no continuation from h -> 0 reaches.
  const StepSummary checked = solve_fold(0.6, 9.6, &y, false, true);
  ASSERT_TRUE(checked.ok());
  EXPECT_NEAR(y, 10.0, 1e-10);
  EXPECT_EQ(checked.root, RootCheck::kNotFound);
  const StepSummary cont = solve_fold(0.6, 9.6, &y, true, false);
  EXPECT_FALSE(cont.ok());
  EXPECT_EQ(cont.failure, FailureKind::kSolve);
  // It names where the branch was lost: at the fold, h = 1/2, to the continuation's resolution.
  const std::string key = "no root continued from h -> 0 beyond h = ";
  const size_t at = cont.message.find(key);
  ASSERT_NE(at, std::string::npos) << cont.message;
  const double lost = std::stod(cont.message.substr(at + key.size()));
  EXPECT_GE(lost, 0.45) << cont.message;
  EXPECT_LE(lost, 0.5) << cont.message;
}

}  // namespace
}  // namespace nhi::test
