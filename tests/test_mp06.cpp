// mp06 (McLachlan & Perlmutter's reversible RATTLE-type method, mp06.hpp)
// against independent derivations: the generic inverse Legendre map against
// the hand-written ones; the velocity form the stepper solves against the
// phase form of the equations as stated; the general form against the
// separable (multiplier-only) form and its explicit step; the solver's
// rounding terms against central differences; the particle's step against
// its closed form and contact_oscillator_nr's against a hand reduction.
// Orders, reversibility and bounded energies are in the typed contract suite
// (test_methods.cpp).
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "../experiments/studies/hand_steps.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

template <class S>
class Mp06Test : public ::testing::Test {};
TYPED_TEST_SUITE(Mp06Test, Systems);

template <class S>
class Mp06SeparableTest : public ::testing::Test {};
TYPED_TEST_SUITE(Mp06SeparableTest, SeparableSystems);

// The hand-written V(q, p) (the fast path) against the generic one from the
// partials, with random parameters, and p -> V -> p round trips.
TYPED_TEST(Mp06Test, InverseLegendreMapIsTheGenericOne) {
  using S = TypeParam;
  constexpr int n = S::n;
  std::mt19937 rng(31);
  for (int trial = 0; trial < 10; ++trial) {
    const S sys = randomized_system<S>(rng);
    Vec<double, n> q, p;
    random_phase(rng, 2.0, &q, &p);
    const Vec<double, n> v = velocity<S, double>(sys, q, p), vg = generic_velocity<S, double>(sys, q, p);
    EXPECT_LE((v - vg).cwiseAbs().maxCoeff(), 16 * kEps * (1 + v.cwiseAbs().maxCoeff()));
    EXPECT_LE((momentum(sys, q, v) - p).cwiseAbs().maxCoeff(), 16 * kEps * (1 + p.cwiseAbs().maxCoeff()));
    const double H = hamiltonian<S, double>(sys, q, p);
    EXPECT_NEAR(H, energy(sys, q, v), 16 * kEps * (1 + p.squaredNorm()));
  }
}

// The velocity form that the mp06 stepper solves on a non-separable system
// (Mp06Problem: unknowns v1 and lambda, q1 and p1 explicit in v1) is the
// phase form of the equations as stated (Mp06PhaseProblem: q1, p1, lambda),
// on every scene with random parameters and states, from h = 0.2 down to
// 1e-7: the same step to round-off of q1, p1 and the impulse h lambda, and
// the phase form's own residual at the velocity form's step within its
// tolerance.
TYPED_TEST(Mp06Test, Mp06VelocityFormIsThePhaseForm) {
  using S = TypeParam;
  constexpr int n = S::n, m = S::m;
  std::mt19937 rng(53);
  double worst_q = 0, worst_p = 0, worst_l = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const S sys = randomized_system<S>(rng);
    Vec<double, n> q0, p0;
    random_phase(rng, 1.0, &q0, &p0);
    for (const double h : {0.2, 1e-3, 1e-7}) {
      const Mp06PhaseProblem<S> phase(sys, h, q0, p0);
      Vec<double, 2 * n> y = phase.guess(q0, Vec<double, m>::Zero());
      Vec<double, m> lp = Vec<double, m>::Zero();
      ASSERT_TRUE(NewtonSolver<Mp06PhaseProblem<S>>(phase).solve(&y, &lp).ok()) << trial << " h " << h;
      const Mp06Problem<S> vel(sys, h, q0, p0);
      Vec<double, n> v1 = vel.guess(q0, Vec<double, m>::Zero());
      Vec<double, m> lv = Vec<double, m>::Zero();
      ASSERT_TRUE(NewtonSolver<Mp06Problem<S>>(vel).solve(&v1, &lv).ok()) << trial << " h " << h;
      Vec<double, n> q1, p1;
      vel.finish(v1, lv, &q1, &p1);
      const Vec<double, n> qp = y.template head<n>(), pp = y.template tail<n>();
      const double sq = 1 + qp.cwiseAbs().maxCoeff(), sp = 1 + pp.cwiseAbs().maxCoeff();
      worst_q = std::max(worst_q, (q1 - qp).cwiseAbs().maxCoeff() / sq);
      worst_p = std::max(worst_p, (p1 - pp).cwiseAbs().maxCoeff() / sp);
      worst_l = std::max(worst_l, h * (lv - lp).cwiseAbs().maxCoeff() / sp);
      Vec<double, 2 * n> yv;
      yv << q1, p1;
      EXPECT_LE(NewtonSolver<Mp06PhaseProblem<S>>(phase).relative_residual(yv, lv), SolverOptions{}.tolerance)
          << trial << " h " << h;
    }
  }
  EXPECT_LE(worst_q, 64 * kEps);
  EXPECT_LE(worst_p, 64 * kEps);
  EXPECT_LE(worst_l, 64 * kEps);
  std::printf("[ %s ] mp06 velocity form - phase form, in eps: q1 %.2g, p1 %.2g, h lambda %.2g\n", S::name,
              worst_q / kEps, worst_p / kEps, worst_l / kEps);
}

// The velocity form's step is finished by the phase form's own equations
// (Mp06Problem::finish), because p1 = dL/dqdot(q1, v1) itself, although within
// a few eps of the phase form's p1 (above), biases the energy: on
// contact_oscillator_nr (the registered scene whose stepper solves the
// velocity form), mp06 + order 6 at h = 0.0125 would drift about a hundred
// times further over t = 100 than with the phase form's solve.  Here the two
// drifts agree within a factor 3 (measured: 9.1e-14 and 9.3e-14).
TEST(Mp06, VelocityFormKeepsThePhaseFormEnergyRoundOff) {
  using S = ContactOscillatorNR;
  constexpr int n = S::n;
  const S sys;
  const std::vector<double> gamma = composition("order6").gamma;
  const double h = 0.0125;
  const Vec<double, n> q0 = S::default_q0(), p0 = momentum(sys, q0, S::default_v0());
  const double H0 = hamiltonian<S, double>(sys, q0, p0);
  Mp06Stepper<S> vel(sys);
  ASSERT_FALSE((is_separable<S>::value));
  vel.start(q0, S::default_v0());
  Vec<double, n> q = q0, p = p0;
  Vec<double, S::m> lambda = Vec<double, S::m>::Zero();
  double drift_vel = 0, drift_phase = 0;
  for (int k = 0; k < 8000; ++k) {
    for (const double g : gamma) {
      ASSERT_TRUE(vel.step(g * h).ok());
      const Mp06PhaseProblem<S> phase(sys, g * h, q, p);
      Vec<double, 2 * n> y = phase.guess(q, lambda);
      ASSERT_TRUE(NewtonSolver<Mp06PhaseProblem<S>>(phase).solve(&y, &lambda).ok());
      phase.finish(y, lambda, &q, &p);
    }
    const auto z = vel.phase();
    drift_vel =
        std::max(drift_vel, std::abs(hamiltonian<S, double>(sys, z.template head<n>(), z.template tail<n>()) - H0));
    drift_phase = std::max(drift_phase, std::abs(hamiltonian<S, double>(sys, q, p) - H0));
  }
  std::printf("    max |H - H0| over t = 100: velocity form %.3g, phase form %.3g\n", drift_vel, drift_phase);
  EXPECT_LE(drift_vel, 3 * drift_phase);
  EXPECT_LE(drift_phase, 1e-12);  // both at round-off: order 6 at h = 0.0125
}

// mp06's general form (the velocity form, unknowns v1 and lambda) and its
// reduced form (lambda only, for separable systems) are the same map: 50 steps
// agree to round-off.

TYPED_TEST(Mp06SeparableTest, Mp06GeneralAndSeparableFormsAgree) {
  using S = TypeParam;
  static_assert(is_separable<S>::value);
  const S sys = make_system<S>();
  Mp06Stepper<S, true> fast(sys);
  Mp06Stepper<S, false> full(sys);
  fast.start(S::default_q0(), S::default_v0());
  full.start(S::default_q0(), S::default_v0());
  for (int k = 0; k < 50; ++k) {
    ASSERT_TRUE(fast.step(0.2).ok());
    ASSERT_TRUE(full.step(0.2).ok());
  }
  const auto z1 = fast.phase(), z2 = full.phase();
  EXPECT_LE((z1 - z2).cwiseAbs().maxCoeff(), 1e-12 * (1 + z1.cwiseAbs().maxCoeff()));
  EXPECT_LE((fast.lambda() - full.lambda()).cwiseAbs().maxCoeff(), 1e-11 * (1 + fast.lambda().cwiseAbs().maxCoeff()));
}

// SeparableVelocity (hamiltonian.hpp), the V = M^-1 p that mp06's separable
// form applies: at random parameters and states it is the system's V to
// round-off, in value and, through Jets, in derivative; identity() holds
// exactly when M^-1 is the identity, and there p itself (IdentityVelocity,
// what the stepper then uses) is the system's V bit for bit.  With M^-1 not
// the identity (random masses: the robot and the sleigh), mp06's separable
// form, which then applies the products, is the general form's map over 50
// steps.
TYPED_TEST(Mp06SeparableTest, SeparableVelocityIsTheSystemsV) {
  using S = TypeParam;
  constexpr int n = S::n;
  using J = ceres::Jet<double, n>;
  std::mt19937 rng(47);
  int products = 0;
  for (int trial = 0; trial < 11; ++trial) {
    const S sys = trial == 0 ? make_system<S>() : randomized_system<S>(rng);
    const SeparableVelocity<S> V(sys);
    EXPECT_EQ(V.identity(), V.matrix() == (Mat<double, n, n>::Identity())) << trial;
    Vec<double, n> q, p;
    random_phase(rng, 2.0, &q, &p);
    const Vec<double, n> v = velocity<S, double>(sys, q, p), vs = V(p);
    EXPECT_LE((v - vs).cwiseAbs().maxCoeff(), 4 * kEps * v.cwiseAbs().maxCoeff()) << trial;
    if (V.identity()) {
      EXPECT_TRUE(v == IdentityVelocity{}(p)) << trial;
    }
    Vec<J, n> qj, pj;
    for (int i = 0; i < n; ++i) {
      qj[i] = J(q[i]);
      pj[i] = J(p[i], i);
    }
    const Vec<J, n> vj = velocity<S, J>(sys, qj, pj), vsj = V(pj);
    for (int i = 0; i < n; ++i)
      EXPECT_LE((vj[i].v - vsj[i].v).cwiseAbs().maxCoeff(), 4 * kEps * (1 + vj[i].v.cwiseAbs().maxCoeff()));
    if (V.identity() || products >= 2) continue;
    ++products;
    Mp06Stepper<S, true> fast(sys);
    Mp06Stepper<S, false> full(sys);
    fast.start(S::default_q0(), S::default_v0());
    full.start(S::default_q0(), S::default_v0());
    for (int k = 0; k < 50; ++k) {
      ASSERT_TRUE(fast.step(0.2).ok()) << trial << " step " << k;
      ASSERT_TRUE(full.step(0.2).ok()) << trial << " step " << k;
    }
    const auto z1 = fast.phase(), z2 = full.phase();
    EXPECT_LE((z1 - z2).cwiseAbs().maxCoeff(), 1e-12 * (1 + z1.cwiseAbs().maxCoeff())) << trial;
    EXPECT_LE((fast.lambda() - full.lambda()).cwiseAbs().maxCoeff(), 1e-11 * (1 + fast.lambda().cwiseAbs().maxCoeff()))
        << trial;
  }
  // The scenes with masses among their parameters draw M^-1 != I.
  const std::string name = S::name;
  if (name == "robot" || name == "sleigh") {
    EXPECT_EQ(products, 2);
  }
}

// The explicit mp06 step (mp06.hpp, explicit_structure): where the structural
// probe says omega(q1) does not depend on lambda, that holds at random states
// and parameters too (autodiff through the step), and the direct m x m solve is
// the Newton solve of the same equations to round-off, over 50 steps.  The
// probe's verdict on the scenes whose structure we know by hand: the particle,
// the robot and the contact and chaotic oscillators are explicit, the sleigh
// with a != 0 is not (its constraint force turns theta), the knife edge is.
TYPED_TEST(Mp06SeparableTest, Mp06ExplicitStepIsTheNewtonStep) {
  using S = TypeParam;
  const S sys = make_system<S>();
  const bool is_explicit = Mp06Stepper<S, true>::explicit_structure(sys);
  const std::string name = S::name;
  if (name == "particle" || name == "robot" || name == "contact_oscillator" || name == "chaotic_oscillator") {
    EXPECT_TRUE(is_explicit) << name;
  }
  if constexpr (std::is_same_v<S, Sleigh>) {
    EXPECT_FALSE(is_explicit);
    Sleigh knife = sys;
    knife.a = 0;
    EXPECT_TRUE((Mp06Stepper<Sleigh, true>::explicit_structure(knife)));
  }
  if (!is_explicit) return;
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  using J = ceres::Jet<double, S::m>;
  for (int trial = 0; trial < 20; ++trial) {
    const S rs = randomized_system<S>(rng);
    Vec<double, S::n> q0, p0;
    random_phase(rng, 2.0, &q0, &p0);
    const SeparableVelocity<S> vel(rs);
    const Mp06SeparableProblem<S> prob(rs, vel, 0.1 + 0.2 * trial / 20.0, q0, p0);
    Vec<J, S::m> lj;
    for (int a = 0; a < S::m; ++a) lj[a] = J(u(rng), a);
    Vec<J, S::n> q1, p1, v1;
    prob.template state<J>(lj, &q1, &p1, &v1);
    const Mat<J, S::m, S::n> W1 = rs.template omega<J>(q1);
    for (int a = 0; a < S::m; ++a)
      for (int j = 0; j < S::n; ++j) EXPECT_EQ(W1(a, j).v.cwiseAbs().maxCoeff(), 0.0) << trial;
  }
  Mp06Stepper<S, true> direct(sys), newton(sys, {}, false);
  ASSERT_TRUE(direct.is_explicit());
  ASSERT_FALSE(newton.is_explicit());
  direct.start(S::default_q0(), S::default_v0());
  newton.start(S::default_q0(), S::default_v0());
  for (int k = 0; k < 50; ++k) {
    const StepSummary sd = direct.step(0.2), sn = newton.step(0.2);
    ASSERT_TRUE(sd.ok() && sn.ok());
    EXPECT_EQ(sd.iterations, 0);  // no Newton iteration was needed
  }
  const auto z1 = direct.phase(), z2 = newton.phase();
  EXPECT_LE((z1 - z2).cwiseAbs().maxCoeff(), 1e-12 * (1 + z1.cwiseAbs().maxCoeff()));
  EXPECT_LE((direct.lambda() - newton.lambda()).cwiseAbs().maxCoeff(),
            1e-11 * (1 + direct.lambda().cwiseAbs().maxCoeff()));
}

// mp06's reduced problem reads q1 = q_half + (h/2) V(p1(lambda)) through
// omega; its rounding terms (NewtonSolver's rounding_terms, solver.hpp) are
// sum_k |d r_a / d q1_k| |q1_k| over the coordinates q1_k that lambda moves
// (found here by a Jet in lambda).  Checked against central differences in
// each such q1_k at random states and parameters of every separable scene
// (the residual r_a = omega_a(q1) V(p1) with p1 held), relative step 2^-26;
// where the step is explicit (omega reads no coordinate lambda moves) they
// are exactly zero.
TYPED_TEST(Mp06SeparableTest, Mp06RoundingTermsAreTheResidualsResponseToQ1) {
  using S = TypeParam;
  constexpr int n = S::n, m = S::m;
  std::mt19937 rng(47);
  double worst = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const S rs = randomized_system<S>(rng);
    Vec<double, n> q0, p0;
    random_phase(rng, 2.0, &q0, &p0);
    using P = Mp06SeparableProblem<S>;
    const SeparableVelocity<S> vel(rs);
    const P prob(rs, vel, 0.2, q0, p0);
    Vec<double, m> lambda;
    for (int a = 0; a < m; ++a) lambda[a] = std::uniform_real_distribution<double>(-1, 1)(rng);
    Vec<double, 0> none;
    Vec<double, m> extra;
    prob.rounding_terms(lambda, none, &extra);
    Vec<double, n> q1, p1, v1;
    prob.template state<double>(lambda, &q1, &p1, &v1);
    using J = ceres::Jet<double, m>;
    Vec<J, m> lj;
    for (int a = 0; a < m; ++a) lj[a] = J(lambda[a], a);
    Vec<J, n> q1j, p1j, v1j;
    prob.template state<J>(lj, &q1j, &p1j, &v1j);
    if (Mp06Stepper<S>::explicit_structure(rs))
      EXPECT_TRUE((extra.array() == 0.0).all()) << S::name << " trial " << trial;
    Vec<double, m> fd = Vec<double, m>::Zero();
    for (int k = 0; k < n; ++k) {
      if ((q1j[k].v.array() == 0.0).all()) continue;  // a coordinate lambda does not move
      const double d = std::ldexp(1.0, -26) * std::max(std::abs(q1[k]), 1e-3);
      Vec<double, n> qp = q1, qm = q1;
      qp[k] += d;
      qm[k] -= d;
      const Vec<double, m> dr = (rs.template omega<double>(qp) - rs.template omega<double>(qm)) * v1 / (2 * d);
      fd += dr.cwiseAbs() * std::abs(q1[k]);
    }
    const Vec<double, m> size = rs.template omega<double>(q1).cwiseAbs() * v1.cwiseAbs();
    for (int a = 0; a < m; ++a) {
      const double err = std::abs(extra[a] - fd[a]) / (extra[a] + size[a] + kEps);
      worst = std::max(worst, err);
      EXPECT_LE(err, 1e-6) << S::name << " trial " << trial << " row " << a << ": " << extra[a] << " against " << fd[a];
    }
  }
  std::printf("[ %s ] rounding terms against central differences: worst relative difference %.2g\n", S::name, worst);
}

// Why the rounding terms (solver.hpp): where mp06 on the sleigh runs
// straight (the default state after 10^3 steps at h = 0.2: theta ~ 3.09,
// x ~ -344), omega_a(q1) V(p1) cannot be pinned to 16 eps of its terms.  At
// the step's solution, one ulp of any q1_k moves the residual by up to
// ~20 eps of the terms |omega_aj v_j| (the two that cancel are 0.087 each,
// and sin(theta) ~ 0.05 takes theta's last bit as a relative error of
// ~1e-14), yet by no more than eps times the rounding terms (an ulp of q1_k is
// at most eps |q1_k|).  And a composed step whose stages start at that floor
// takes no Newton iteration: over the last 100 of 10^3 composed steps, none
// for the triple jump, Suzuki 5 and order 6 (without the rounding terms,
// stages 4 and 5 of Suzuki 5 start at ~20 eps of the terms, take one
// iteration and stay there).
TEST(Mp06, SleighResidualFloorIsTheRoundingOfQ1) {
  using S = Sleigh;
  constexpr int n = S::n;
  const S sys;
  Mp06Stepper<S> st(sys);
  st.start(S::default_q0(), S::default_v0());
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(st.step(0.2).ok());
  const Vec<double, 2 * n> z = st.phase();
  using P = Mp06SeparableProblem<S>;
  const SeparableVelocity<S> vel(sys);
  const P prob(sys, vel, 0.2, z.head<n>(), z.tail<n>());
  Vec<double, 1> lambda = st.lambda();
  Vec<double, 0> none;
  ASSERT_TRUE(NewtonSolver<P>(prob).solve(&lambda, &none).ok());
  Vec<double, n> q1, p1, v1;
  prob.state<double>(lambda, &q1, &p1, &v1);
  Vec<double, 1> r, terms, extra;
  prob.residual<double>(lambda, none, &r, &terms);
  prob.rounding_terms(lambda, none, &extra);
  const double r1 = (sys.omega<double>(q1) * v1)[0];
  double spread = 0;
  for (int k = 0; k < n; ++k)
    for (const double dir : {-1.0, 1.0}) {
      Vec<double, n> qk = q1;
      qk[k] = std::nextafter(qk[k], dir * std::numeric_limits<double>::infinity());
      spread = std::max(spread, std::abs((sys.omega<double>(qk) * v1)[0] - r1));
    }
  std::printf(
      "    one ulp of q1: residual moves by %.3g = %.1f eps of its terms (%.3g), %.2f eps of the rounding terms "
      "(%.3g)\n",
      spread, spread / (kEps * terms[0]), terms[0], spread / (kEps * extra[0]), extra[0]);
  EXPECT_GT(spread, 16 * kEps * terms[0]);
  EXPECT_LE(spread, kEps * extra[0] + 4 * kEps * terms[0]);
  for (const char* name : {"triple_jump", "suzuki5", "order6"}) {
    Composed<Mp06Stepper<S>> composed(Mp06Stepper<S>(sys), composition(name));
    composed.start(S::default_q0(), S::default_v0());
    long tail = 0;
    for (int k = 0; k < 1000; ++k) {
      const StepSummary s = composed.step(0.2);
      ASSERT_TRUE(s.ok()) << name << " step " << k << ": " << s.message;
      if (k >= 900) tail += s.iterations;
    }
    EXPECT_EQ(tail, 0) << name;
  }
}

// mp06 on the particle in closed form (McLachlan & Perlmutter eq. 4.18 with
// V = p, F = (-2 kx x, -2 ky y, 0), omega = (-y, 0, 1)): the y row of the
// constraint force is zero, so y1 is explicit and the constraint
// -y1 p1x + p1z = 0 is linear in lambda:
//   lambda = (y1 pb_x - pb_z) / (h (1 + y1 y_half)),  pb = p0 + h F(q_half).
TEST(Mp06, ParticleStepIsTheClosedForm) {
  std::mt19937 rng(5);
  const Particle sys = randomized_system<Particle>(rng);
  Vec<double, 3> q0, v0;
  random_state<Particle>(rng, &q0, &v0, sys);
  for (double h : {0.2, -0.13, 1e-6}) {
    const Vec<double, 3> p0 = v0;
    const Vec<double, 3> qh = q0 + 0.5 * h * p0;
    const Vec<double, 3> F(-2 * sys.kx * qh[0], -2 * sys.ky * qh[1], 0.0);
    const Vec<double, 3> pb = p0 + h * F;
    const double y1 = qh[1] + 0.5 * h * pb[1];
    const double lambda = (y1 * pb[0] - pb[2]) / (h * (1 + y1 * qh[1]));
    const Vec<double, 3> p1 = pb + h * lambda * Vec<double, 3>(-qh[1], 0.0, 1.0);
    const Vec<double, 3> q1 = qh + 0.5 * h * p1;

    Mp06Stepper<Particle> st(sys);
    st.start(q0, v0);
    ASSERT_TRUE(st.step(h).ok());
    const Vec<double, 6> z = st.phase();
    EXPECT_LE((z.head<3>() - q1).cwiseAbs().maxCoeff(), 64 * kEps * (1 + q1.cwiseAbs().maxCoeff())) << h;
    EXPECT_LE((z.tail<3>() - p1).cwiseAbs().maxCoeff(), 64 * kEps * (1 + p1.cwiseAbs().maxCoeff())) << h;
    EXPECT_NEAR(st.lambda()[0], lambda, 1e-12 * (1 + std::abs(lambda))) << h;
    EXPECT_LE(std::abs(-q1[1] * p1[0] + p1[2]), 16 * kEps * (1 + p1.cwiseAbs().maxCoeff()));  // held at q1
  }
}

// bench_steps' floor for mp06 on contact_oscillator_nr (experiments/studies/hand_steps.hpp:
// the step reduced by hand to one scalar equation) is the library's mp06 map:
// from random parameters and states, single steps at several h, and 2000
// chained steps at the benchmark's h = 0.2, agree to round-off.
TEST(Mp06, ContactOscillatorNRHandReducedStepIsTheLibraryStep) {
  using S = ContactOscillatorNR;
  std::mt19937 rng(11);
  for (int trial = 0; trial < 4; ++trial) {
    const S sys = randomized_system<S>(rng);
    Vec<double, 3> q0, v0;
    random_state<S>(rng, &q0, &v0, sys);
    const Mp06Stepper<S> lib(sys);
    floors::Mp06ContactOscillatorNR hand{sys.epsilon};
    for (double h : {0.2, -0.13, 0.01}) {
      Vec<double, 3> q = q0, p = momentum(sys, q0, v0), qa, pa, qb, pb;
      Vec<double, 1> lb = Vec<double, 1>::Zero();
      double la = 0, dq = 0, dp = 0, dhl = 0, size = 1;
      const int steps = h == 0.2 ? 2000 : 1;
      for (int k = 0; k < steps; ++k) {
        ASSERT_TRUE(hand.step(h, q, p, &qa, &pa, &la));
        ASSERT_TRUE(lib.map(h, q, p, &qb, &pb, &lb).ok());
        dq = std::max(dq, (qa - qb).cwiseAbs().maxCoeff());
        dp = std::max(dp, (pa - pb).cwiseAbs().maxCoeff());
        dhl = std::max(dhl, std::abs(h * (la - lb[0])));
        size = std::max({size, qb.cwiseAbs().maxCoeff(), pb.cwiseAbs().maxCoeff()});
        q = qb, p = pb, la = lb[0];  // both continue from the library's state
      }
      EXPECT_LE(dq, 64 * kEps * size) << "trial " << trial << " h " << h;
      EXPECT_LE(dp, 64 * kEps * size) << "trial " << trial << " h " << h;
      EXPECT_LE(dhl, 64 * kEps * size) << "trial " << trial << " h " << h;
    }
  }
}

}  // namespace
}  // namespace nhi::test
