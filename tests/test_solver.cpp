// The Newton solver shared by the implicit methods (solver.hpp): a start at
// round-off takes its update, and the failure path (no convergence, a
// non-finite state) ends a run the same way for every method.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

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

}  // namespace
}  // namespace nhi::test
