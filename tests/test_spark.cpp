// SPARK (Lobatto IIIA-IIIB, spark.hpp) against an independent implementation:
// one step of s = 2, 3, 4 from the default states of the contact oscillator,
// its non-reversible version and the rolling disk against odelab's
// Spark2/3/4 (odelab/scheme/rungekutta.py, its own residual solved to 1e-17
// and checked against a second, independent implementation of the stage
// equations to 4e-16); the tableaux' symplecticity condition that makes the
// pair a SPARK method; the constraint at the end of each step.  Orders,
// symmetry, reversibility and bounded energies are in the typed contract
// suite (test_methods.cpp), which runs spark with every stage count.
#include <cmath>
#include <limits>

#include "nhi/methods/methods.hpp"
#include "nhi/methods/spark/spark_body.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

// b_i ahat_ij + b_j a_ji = b_i b_j (Hairer, Lubich & Wanner, GNI, Theorem
// IV.2.3 for partitioned methods): Lobatto IIIA-IIIB is a symplectic pair.
template <int s>
void expect_symplectic_pair() {
  const auto& t = LobattoTableau<s>::get();
  double sum = 0;
  for (int i = 0; i < s; ++i) {
    sum += t.b[i];
    for (int j = 0; j < s; ++j) EXPECT_NEAR(t.b[i] * t.ahat[i][j] + t.b[j] * t.a[j][i], t.b[i] * t.b[j], 1e-16);
  }
  EXPECT_NEAR(sum, 1.0, 4 * std::numeric_limits<double>::epsilon());
  for (int j = 0; j < s; ++j) EXPECT_DOUBLE_EQ(t.a[s - 1][j], t.b[j]);
}

TEST(Spark, LobattoIIIAIIIBIsASymplecticPair) {
  expect_symplectic_pair<2>();
  expect_symplectic_pair<3>();
  expect_symplectic_pair<4>();
}

template <int s, class S>
void expect_step(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double h,
                 const Vec<double, S::n>& q1_ref, const Vec<double, S::n>& p1_ref,
                 const std::vector<double>& lambda_ref, double tol) {
  SparkStepper<S, s> st(sys);
  const Vec<double, S::n> p0 = momentum(sys, q0, v0);
  Vec<double, S::n> q1, p1;
  Vec<double, S::m* s> lambda = Vec<double, S::m * s>::Zero();
  const StepSummary sum = st.map(h, q0, p0, &q1, &p1, &lambda);
  ASSERT_TRUE(sum.ok()) << sum.message;
  for (int i = 0; i < S::n; ++i) {
    EXPECT_NEAR(q1[i], q1_ref[i], tol) << "s = " << s << ", q1[" << i << "]";
    EXPECT_NEAR(p1[i], p1_ref[i], tol) << "s = " << s << ", p1[" << i << "]";
  }
  ASSERT_EQ(lambda_ref.size(), static_cast<size_t>(S::m * s));
  for (int i = 0; i < S::m * s; ++i) EXPECT_NEAR(lambda[i], lambda_ref[i], 1e3 * tol) << "s = " << s << ", Lambda";
  // (6): the velocity constraint at the end point.
  const Vec<double, S::n> v1 = velocity<S, double>(sys, q1, p1);
  EXPECT_LE((sys.template omega<double>(q1) * v1).cwiseAbs().maxCoeff(), 1e-15);
}

// odelab's contact oscillator is this project's (eps = 0.3, default state, h = 2 sin(pi/40)).
TEST(Spark, ContactOscillatorStepIsOdelabs) {
  const ContactOscillator sys;
  const auto q0 = ContactOscillator::default_q0();
  const auto v0 = ContactOscillator::default_v0();
  const double h = 2 * std::sin(M_PI / 40);
  constexpr double tol = 1e-14;
  expect_step<2>(sys, q0, v0, h, {1.2720443317366878, 0.9876883405951378, 0.5038740955445917},
                 {-0.0481372043369421, -0.1559522297918752, 0.0487372406440849},
                 {1.058854883359222, 1.0681310899215406}, tol);
  expect_step<3>(sys, q0, v0, h, {1.2720647483562997, 0.9877135775289768, 0.5038535149616836},
                 {-0.048400823457879, -0.1562752070466507, 0.0490028937123314},
                 {1.0569255471107657, 1.0616404984919452, 1.0700482243511702}, tol);
  expect_step<4>(sys, q0, v0, h, {1.2720647674491974, 0.98771358269471, 0.5038534826353606},
                 {-0.048400584923065, -0.1562750093646221, 0.0490026519540382},
                 {1.0578821610477618, 1.0588895696103073, 1.0647493806672388, 1.0710111682746355}, tol);
}

// odelab's NonReversibleContactOscillator: p = v + (0, 0, sin z), as here.
TEST(Spark, NonReversibleContactOscillatorStepIsOdelabs) {
  const ContactOscillatorNR sys;
  const auto q0 = ContactOscillatorNR::default_q0();
  const auto v0 = ContactOscillatorNR::default_v0();
  const double h = 2 * std::sin(M_PI / 40);
  constexpr double tol = 1e-14;
  expect_step<2>(sys, q0, v0, h, {1.27203420011464, 0.9876883405951378, 0.5038826358117595},
                 {-0.0481362895055123, -0.1559522297918752, 0.5315655643029997},
                 {1.0580319543198045, 1.0689580599588246}, tol);
  expect_step<3>(sys, q0, v0, h, {1.2720646885669022, 0.9877135775289768, 0.5038534869964968},
                 {-0.0484008387585463, -0.1562752070466507, 0.5318066328513642},
                 {1.05721387097856, 1.0614893884018701, 1.070365026017335}, tol);
  expect_step<4>(sys, q0, v0, h, {1.2720647674469696, 0.98771358269471, 0.5038534826409262},
                 {-0.0484005849251364, -0.1562750093646221, 0.5318063717898743},
                 {1.057880479778569, 1.0588903095101276, 1.0647486586453565, 1.071012759658921}, tol);
}

// odelab's VerticalRollingDisk with m = R = I = J = 1 (this project's
// defaults), q = (x, y, theta, phi) = 0, v = (1, 0, 1, 2), h = 0.1.  The
// exact step keeps theta' and phi' and turns (x', y') with phi.
TEST(Spark, RollingDiskStepIsOdelabs) {
  const RollingDisk sys;
  const Vec<double, 4> q0 = Vec<double, 4>::Zero();
  const Vec<double, 4> v0(1.0, 0.0, 1.0, 2.0);
  const double h = 0.1;
  constexpr double tol = 1e-14;
  const Vec<double, 4> p1 = momentum(sys, Vec<double, 4>(0.0, 0.0, 0.0, 0.2),
                                     Vec<double, 4>(0.9800665778412417, 0.1986693307950612, 1.0, 2.0));
  expect_step<2>(sys, q0, v0, h, {0.0994991686252251, 0.0099832164567869, 0.1005008313747749, 0.2}, p1,
                 {-0.10016627495497904, 1.996643291357382, -0.29850216822018666, 1.9767433245438424}, tol);
  expect_step<3>(sys, q0, v0, h, {0.0993351338563033, 0.0099667580820365, 0.1000004159744732, 0.2}, p1,
                 {-0.00024958468389764, 2.006651705046651, -0.1993350507670623, 1.986701572087633, -0.39841554177335364,
                  1.9667018543064871},
                 tol);
  expect_step<4>(sys, q0, v0, h, {0.099334665614226, 0.0099667111011212, 0.1000000001481925, 0.2}, p1,
                 {6.655104982953935e-05, 2.00000844583758, -0.11053068724055837, 1.996941716099189, -0.2884036419838716,
                  1.9790948915121478, -0.3974055639786808, 1.9601282115130805},
                 tol);
}

// The stage-wise Jacobian (SparkProblem::jacobian) against the Jet pass over
// all of y that NewtonSolver uses for a problem without one: the same sums
// term by term, so the same bits.  At a point off the solution (the start
// plus a perturbation of every unknown), on a system whose omega depends on q
// (the rolling disk) and one whose V does (the magnetic particle).
template <int s, class S>
void expect_jacobian_is_the_jet_pass(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0) {
  using P = SparkProblem<S, s>;
  const P prob(sys, 0.3, q0, momentum(sys, q0, v0));
  Vec<double, P::ny> y = prob.guess(Vec<double, S::m * s>::Constant(0.2));
  for (int i = 0; i < P::ny; ++i) y[i] += 0.01 * std::sin(1.0 + i);
  const Vec<double, 0> none;
  Mat<double, P::ny, P::ny> Jy;
  prob.jacobian(y, none, &Jy);
  using J = ceres::Jet<double, P::ny>;
  Vec<J, P::ny> yj;
  for (int i = 0; i < P::ny; ++i) yj[i] = J(y[i], i);
  Vec<J, P::ny> rj;
  prob.template residual<J>(yj, Vec<J, 0>(), &rj, nullptr);
  int nonzero = 0;
  for (int i = 0; i < P::ny; ++i)
    for (int j = 0; j < P::ny; ++j) {
      EXPECT_EQ(Jy(i, j), rj[i].v[j]) << "s = " << s << ", row " << i << ", column " << j;
      nonzero += Jy(i, j) != 0;
    }
  EXPECT_GT(nonzero, 2 * P::ny);  // more than the identity blocks
}

TEST(Spark, StageWiseJacobianIsTheJetPassBitForBit) {
  const RollingDisk disk;
  expect_jacobian_is_the_jet_pass<2>(disk, Vec<double, 4>(0.1, -0.2, 0.3, 0.4), Vec<double, 4>(1.0, 0.0, 1.0, 2.0));
  expect_jacobian_is_the_jet_pass<4>(disk, Vec<double, 4>(0.1, -0.2, 0.3, 0.4), Vec<double, 4>(1.0, 0.0, 1.0, 2.0));
  const MagneticParticle mag;
  Vec<double, 3> q0, v0;
  scene_state<MagneticParticle>(&q0, &v0);
  expect_jacobian_is_the_jet_pass<3>(mag, q0, v0);
}

// On a separable system V(q, p) = M^-1 p does not depend on q, so both
// stages of s = 2 have the velocity (q1 - q0)/h, the averaged constraint
// G_1 + G_2 = 0 is (omega(q0) + omega(q1)) (q1 - q0)/h = 0, the symmetric
// DLA's omega_d (eq. 14), and the momentum equations are the DEL equations of
// the trapezoidal L_d (eq. 10 with alpha = 0) with the constraint force split
// between the two ends: SPARK 2 is the symmetric DLA with alpha = 0.  Where V
// depends on q (a gyroscopic term), the two differ at O(h^3) a step.
template <class S>
class SparkSeparableTest : public ::testing::Test {};
TYPED_TEST_SUITE(SparkSeparableTest, SeparableSystems);

template <class S>
Vec<double, S::n> final_q(const S& sys, const MethodSpec& spec, double h, long steps) {
  Vec<double, S::n> q0, v0, q;
  scene_state<S>(&q0, &v0);
  const RunReport rep = run_method(sys, spec, q0, v0, h, steps, [&](const Sample<S::n, S::m>& s) {
    q = s.q;
    return true;
  });
  EXPECT_TRUE(rep.ok) << rep.reason;
  return q;
}

TYPED_TEST(SparkSeparableTest, TwoStagesAreTheSymmetricDlaWithAlphaZero) {
  using S = TypeParam;
  const S sys = make_system<S>();
  MethodSpec spark = spec_of("spark"), dla = spec_of("dla");
  spark.stages = 2;
  dla.discretization = "symmetric";
  dla.alpha = 0.0;
  const double h = 0.1;
  const Vec<double, S::n> a = final_q(sys, spark, h, 200), b = final_q(sys, dla, h, 200);
  const Vec<double, S::n> one = final_q(sys, spark, h, 1), one_dla = final_q(sys, dla, h, 1);
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-11 * (1 + a.cwiseAbs().maxCoeff()));
  EXPECT_LE((one - one_dla).cwiseAbs().maxCoeff(), 1e-14 * (1 + one.cwiseAbs().maxCoeff()));
}

// ... and where V depends on q it is another map (a negative control).
TEST(Spark, TwoStagesDifferFromTheSymmetricDlaWhereVelocityDependsOnQ) {
  const MagneticParticle sys;
  MethodSpec spark = spec_of("spark"), dla = spec_of("dla");
  dla.discretization = "symmetric";
  dla.alpha = 0.0;
  const Vec<double, 3> a = final_q(sys, spark, 0.1, 200), b = final_q(sys, dla, 0.1, 200);
  EXPECT_GT((a - b).cwiseAbs().maxCoeff(), 1e-4);
}

}  // namespace
}  // namespace nhi::test
