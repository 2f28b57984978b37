// The rigid bodies on the unit-quaternion embedding (suslov.hpp,
// chaplygin_sphere.hpp), each derived a second time, independently of its
// quaternion Lagrangian: the Euler-Poincare-Suslov equations and Newton and
// Euler's equations of the rolling ball, written with quaternion products,
// against the Lagrange-d'Alembert equations of L and omega by autodiff
// (generic_acceleration); the principal-axis Suslov problem's steady rotation
// and the Fedorov-Zenkov scene's reduced closed form against the reference
// solution; the sphere's first integrals along it; and the midpoint DLA's
// discrete constraint p_mid . (p1 - p0) = (|p1|^2 - |p0|^2) / 2 = 0 holding |p|.
#include <fstream>

#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/methods/reference/reference_body.hpp"
#include "nhi/runner/scene.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

namespace qn = nhi::quaternion;
using Vec3 = Vec<double, 3>;
using Vec4 = Vec<double, 4>;

Vec4 pure(const Vec3& v) {
  Vec4 r;
  r << 0.0, v;
  return r;
}
Vec4 conj(const Vec4& p) {
  Vec4 r = -p;
  r[0] = p[0];
  return r;
}
Vec4 random_unit_quaternion(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Vec4 p;
  for (int i = 0; i < 4; ++i) p[i] = g(rng);
  return p / p.norm();
}

// quaternion.hpp's matrices are the products they stand for.
TEST(Quaternion, MatricesAreTheProducts) {
  std::mt19937 rng(58);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  double worst = 0;
  for (int trial = 0; trial < 100; ++trial) {
    Vec4 p, d;
    Vec3 w;
    for (int i = 0; i < 4; ++i) p[i] = u(rng), d[i] = u(rng);
    for (int i = 0; i < 3; ++i) w[i] = u(rng);
    const Vec4 pb_d = qn::product(conj(p), d), d_pb = qn::product(d, conj(p));
    worst = std::max(worst, (qn::G<double>(p, d) - pb_d.tail<3>()).cwiseAbs().maxCoeff());
    worst = std::max(worst, std::abs(p.dot(d) - pb_d[0]));
    worst = std::max(worst, (qn::E<double>(p, d) - d_pb.tail<3>()).cwiseAbs().maxCoeff());
    worst = std::max(worst, (qn::Gt<double>(p, w) - qn::product(p, pure(w))).cwiseAbs().maxCoeff());
    worst = std::max(worst, (qn::matrix<double>(p) * d - qn::G<double>(p, d)).cwiseAbs().maxCoeff());
    const Vec3 Rw = qn::product(qn::product(p, pure(w)), conj(p)).tail<3>();
    worst = std::max(worst, (qn::rotate(p, w) - Rw).cwiseAbs().maxCoeff());
    const Vec3 ez(0, 0, 1), gamma = qn::product(qn::product(conj(p), pure(ez)), p).tail<3>();  // R^T e_z
    worst = std::max(worst, (qn::vertical<double>(p) - gamma).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-13);
  // On |p| = 1, pdot = p (0, Omega) / 2 has Omega = 2 G(p) pdot and p . pdot = 0.
  const Vec4 p = random_unit_quaternion(rng);
  const Vec3 Om(0.3, -1.2, 0.7);
  const Vec4 pd = 0.5 * qn::product(p, pure(Om));
  EXPECT_LT((2.0 * qn::G<double>(p, pd) - Om).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT(std::abs(p.dot(pd)), 1e-16);
  EXPECT_LT((qn::half_exp(Vec3(1e-9, 0, 0)) - Vec4(1, 5e-10, 0, 0)).cwiseAbs().maxCoeff(), 1e-20);
}

// pddot of the reconstruction pdot = p (0, Omega) / 2 (|p| = 1):
//   pddot = p (0, Omega) (0, Omega) / 4 + p (0, Omegadot) / 2 = -|Omega|^2 p / 4 + p (0, Omegadot) / 2.
Vec4 reconstruction_acceleration(const Vec4& p, const Vec3& Om, const Vec3& Omdot) {
  return -0.25 * Om.squaredNorm() * p + 0.5 * qn::product(p, pure(Omdot));
}

// Derivation 1, the Euler-Poincare-Suslov equations on SO(3):
//   d/dt (I Omega) = I Omega x Omega + mu a,   <a, Omegadot> = 0,
// against derivation 2, generic_acceleration() of the quaternion L and omega,
// at random unit-quaternion states on the constraint, random bodies and random
// (not principal) a; and the multipliers: mu is the row 2 a^T G(p)'s, and the
// row p^T's is -2 Omega^T I Omega (suslov.hpp).
TEST(Suslov, EulerPoincareSuslovIsTheLagrangeDAlembertFlow) {
  std::mt19937 rng(581);
  std::uniform_real_distribution<double> u(0.5, 2.0), sym(-1.5, 1.5);
  double worst = 0, worst_mu = 0, worst_hand = 0;
  for (int trial = 0; trial < 200; ++trial) {
    Suslov sys;  // the default body (I = 1, 10, 100) on the first trials, then random ones
    if (trial >= 20) sys.I1 = u(rng), sys.I2 = u(rng), sys.I3 = u(rng);
    sys.a1 = sym(rng), sys.a2 = sym(rng), sys.a3 = sym(rng);
    const Vec3 I(sys.I1, sys.I2, sys.I3), a(sys.a1, sys.a2, sys.a3);
    const Vec4 p = random_unit_quaternion(rng);
    Vec3 Om(sym(rng), sym(rng), sym(rng));
    Om -= a.dot(Om) / a.squaredNorm() * a;  // <a, Omega> = 0
    const Vec3 Pi = I.cwiseProduct(Om), f = Pi.cross(Om);
    const double mu = -a.cwiseQuotient(I).dot(f) / a.cwiseQuotient(I).dot(a);
    const Vec3 Omdot = (f + mu * a).cwiseQuotient(I);
    const Vec4 q = p, v = 0.5 * qn::product(p, pure(Om));
    const Vec4 eps = reconstruction_acceleration(p, Om, Omdot);
    Vec<double, 2> lambda;
    const Vec4 gen = generic_acceleration(sys, q, v, &lambda);
    worst = std::max(worst, (gen - eps).cwiseAbs().maxCoeff() / (1 + eps.cwiseAbs().maxCoeff()));
    worst_mu = std::max(worst_mu, std::abs(lambda[1] - mu) / (1 + std::abs(mu)));
    worst_mu = std::max(worst_mu, std::abs(lambda[0] + 2 * Om.dot(Pi)) / (1 + 2 * Om.dot(Pi)));
    worst_hand =
        std::max(worst_hand, (sys.acceleration(q, v) - eps).cwiseAbs().maxCoeff() / (1 + eps.cwiseAbs().maxCoeff()));
  }
  std::printf(
      "    Euler-Poincare-Suslov vs autodiff of L: accelerations %.2g, multipliers %.2g; vs acceleration() %.2g "
      "(relative)\n",
      worst, worst_mu, worst_hand);
  EXPECT_LT(worst, 1e-13);
  EXPECT_LT(worst_mu, 1e-13);
  EXPECT_LT(worst_hand, 1e-13);
}

// Derivation 1 for the ball, Newton and Euler with the contact force F
// (space frame, at -r e_z from the centre): m a_c = F - m g e_z, I Omegadot =
// I Omega x Omega + (-r gamma) x R^T F, rolling a_c = r omegadot x e_z with
// omegadot = R Omegadot, so F = m r (R Omegadot) x e_z + m g e_z and
// (I + m r^2 (1 - gamma gamma^T)) Omegadot = I Omega x Omega.  Against
// generic_acceleration() (derivation 2); the rows' multipliers are F_x, F_y.
TEST(ChaplyginSphere, NewtonEulerIsTheLagrangeDAlembertFlow) {
  std::mt19937 rng(582);
  std::uniform_real_distribution<double> u(0.5, 2.0), sym(-1.5, 1.5);
  double worst = 0, worst_force = 0, worst_hand = 0;
  for (int trial = 0; trial < 200; ++trial) {
    ChaplyginSphere sys;
    if (trial >= 20) sys.mass = u(rng), sys.r = u(rng), sys.I1 = u(rng), sys.I2 = u(rng), sys.I3 = u(rng);
    const Vec3 I(sys.I1, sys.I2, sys.I3), ez(0, 0, 1);
    const Vec4 p = random_unit_quaternion(rng);
    const Vec3 Om(sym(rng), sym(rng), sym(rng));
    const auto R = [&](const Vec3& b) { return Vec3(qn::product(qn::product(p, pure(b)), conj(p)).tail<3>()); };
    const Vec3 gamma = qn::product(qn::product(conj(p), pure(ez)), p).tail<3>();
    const double mr2 = sys.mass * sys.r * sys.r;
    const Mat<double, 3, 3> K =
        Mat<double, 3, 3>(I.asDiagonal()) + mr2 * (Mat<double, 3, 3>::Identity() - gamma * gamma.transpose());
    const Vec3 Omdot = K.partialPivLu().solve(Vec3(I.cwiseProduct(Om).cross(Om)));
    const Vec3 F = sys.mass * sys.r * R(Omdot).cross(ez);  // its horizontal part
    const Vec3 vc = sys.r * R(Om).cross(ez);               // centre velocity, rolling
    Vec<double, 6> q, v, a;
    q << 0.3, -0.7, p;
    v << vc[0], vc[1], 0.5 * qn::product(p, pure(Om));
    a << F[0] / sys.mass, F[1] / sys.mass, reconstruction_acceleration(p, Om, Omdot);
    Vec<double, 3> lambda;
    const Vec<double, 6> gen = generic_acceleration(sys, q, v, &lambda);
    worst = std::max(worst, (gen - a).cwiseAbs().maxCoeff() / (1 + a.cwiseAbs().maxCoeff()));
    worst_force = std::max(
        worst_force, std::max(std::abs(lambda[1] - F[0]), std::abs(lambda[2] - F[1])) / (1 + F.cwiseAbs().maxCoeff()));
    worst_hand =
        std::max(worst_hand, (sys.acceleration(q, v) - a).cwiseAbs().maxCoeff() / (1 + a.cwiseAbs().maxCoeff()));
  }
  std::printf(
      "    Newton-Euler vs autodiff of L: accelerations %.2g, contact force %.2g; vs acceleration() %.2g "
      "(relative)\n",
      worst, worst_force, worst_hand);
  EXPECT_LT(worst, 1e-13);
  EXPECT_LT(worst_force, 1e-13);
  EXPECT_LT(worst_hand, 1e-13);
}

// With a a principal axis every motion is a steady rotation about a fixed body
// axis (Omega constant): exact_solution() against the reference solution (CVODE
// on acceleration()), from the default state, a random unit one, and one with
// |p| = 1.3 (the embedding's flow keeps |p|, at the rate Omega / |p|^2), for
// a = e1, e2, e3 and -e2.
TEST(Suslov, SteadyRotationIsTheReferenceSolution) {
  std::mt19937 rng(583);
  std::uniform_real_distribution<double> sym(-1.5, 1.5);
  double worst_q = 0, worst_v = 0;
  for (int axis = 0; axis < 4; ++axis) {
    Suslov sys;
    const Vec3 a = axis < 3 ? Vec3::Unit(axis) : Vec3(0, -2, 0);
    sys.a1 = a[0], sys.a2 = a[1], sys.a3 = a[2];
    ASSERT_TRUE(sys.principal_axis());
    for (int state = 0; state < 3; ++state) {
      Vec4 q0 = Suslov::default_q0();
      Vec3 Om(1.0, 0.1, 0.0);
      if (state > 0) {
        q0 = random_unit_quaternion(rng) * (state == 2 ? 1.3 : 1.0);
        Om = Vec3(sym(rng), sym(rng), sym(rng));
      }
      Om -= a.dot(Om) / a.squaredNorm() * a;
      // the rotation p / |p| at the body rate Omega
      const Vec4 v0 = 0.5 * qn::product(q0, pure(Om));
      for (double t : {0.7, 5.0, 18.0}) {
        Vec4 qe, ve, qr, vr;
        ASSERT_TRUE(sys.exact_solution(q0, v0, t, &qe, &ve));
        reference_solution(sys, q0, v0, t, 1e-13, &qr, &vr);
        worst_q = std::max(worst_q, (qe - qr).cwiseAbs().maxCoeff());
        worst_v = std::max(worst_v, (ve - vr).cwiseAbs().maxCoeff());
      }
    }
  }
  std::printf("    steady rotation vs reference (tol 1e-13) up to t = 18: q %.2g, v %.2g\n", worst_q, worst_v);
  // The reference's own global error over up to seven turns is ~1e-9 (at tol 1e-12, ~1e-8).
  EXPECT_LT(worst_q, 1e-8);
  EXPECT_LT(worst_v, 1e-8);
  EXPECT_GT(worst_q, 0.0);  // two computations
  Suslov tilted;
  tilted.a2 = 0.6, tilted.a3 = 0.8;
  Vec4 q, v;
  EXPECT_FALSE(tilted.exact_solution(Suslov::default_q0(), Suslov::default_v0(), 1.0, &q, &v));
}

// The scene with a not a principal axis (experiments/scenes/suslov.json, the default):
// a = (0, alpha, beta) in the plane of e2 and e3, so with b = (0, beta, -alpha)
// and Omega = u e1 + w b the reduced equations are the Chaplygin sleigh's,
//   I1 u' = k w^2,  J w' = -k u w,  k = alpha beta (I3 - I2),  J = beta^2 I2 + alpha^2 I3,
// u = c tanh(kappa (t - t*)), w = w* sech(kappa (t - t*)), c = sqrt(2E/I1),
// kappa = k c / J, w* = c sqrt(I1 / J): the body turns over from the steady
// rotation -c e1 to +c e1 at constant energy.  Against the reference solution.
TEST(Suslov, FedorovZenkovSceneTurnsOverAtConstantEnergy) {
  const json sc = validate_scene(load_scene_file(std::string(NHI_SCENES) + "/suslov.json"));
  Suslov sys;
  sys.I1 = sc["params"]["I1"], sys.I2 = sc["params"]["I2"], sys.I3 = sc["params"]["I3"];
  sys.a1 = sc["params"]["a1"], sys.a2 = sc["params"]["a2"], sys.a3 = sc["params"]["a3"];
  ASSERT_EQ(sys.a1, 0.0);
  ASSERT_FALSE(sys.principal_axis());
  const double al = sys.a2, be = sys.a3;
  ASSERT_NEAR(al * al + be * be, 1.0, 1e-15);
  Vec4 q0, v0;
  for (int i = 0; i < 4; ++i) q0[i] = sc["q0"][i], v0[i] = sc["v0"][i];
  const Vec3 b(0, be, -al);
  auto body = [&](const Vec4& q, const Vec4& v) { return Vec3(2.0 * qn::G<double>(q, v) / q.squaredNorm()); };
  const Vec3 Om0 = body(q0, v0);
  const double I1 = sys.I1, J = be * be * sys.I2 + al * al * sys.I3, k = al * be * (sys.I3 - sys.I2);
  const double E = 0.5 * I1 * Om0[0] * Om0[0] + 0.5 * J * std::pow(Om0.dot(b), 2);
  const double c = std::sqrt(2 * E / I1), kappa = k * c / J, ts = -std::atanh(Om0[0] / c) / kappa;
  const double ws = c * std::sqrt(I1 / J) * (Om0.dot(b) > 0 ? 1 : -1);
  const double h = sc["h"], T = h * sc["steps"].get<double>();
  double worst = 0, worst_E = 0, worst_p = 0;
  Vec3 last;
  const double E0 = energy(sys, q0, v0);
  ReferenceOptions opt;
  opt.rtol = opt.atol = 1e-13;
  integrate(ReferenceStepper<Suslov>(sys, opt), q0, v0, 0.25, std::lround(T / 0.25), [&](const Sample<4, 2>& s) {
    const Vec3 Om = body(s.q, s.v);
    const double x = kappa * (s.t - ts);
    worst = std::max(worst, std::abs(Om[0] - c * std::tanh(x)));
    worst = std::max(worst, std::abs(Om.dot(b) - ws / std::cosh(x)));
    worst_E = std::max(worst_E, std::abs(energy(sys, s.q, s.v) - E0));
    worst_p = std::max(worst_p, std::abs(s.q.squaredNorm() - 1.0));
    last = Om;
    return true;
  });
  std::printf(
      "    t* = %.3f, kappa = %.4f: |Omega - closed form| %.2g, |E - E0| %.2g, ||p|^2 - 1| %.2g; Omega(T) = "
      "(%.6f, %.2g, %.2g)\n",
      ts, kappa, worst, worst_E, worst_p, last[0], last[1], last[2]);
  // The reference's error (tol 1e-13) over T = 18: ~1e-9 (measured 4.4e-10, its energy 3.8e-11).
  EXPECT_LT(worst, 1e-8);
  EXPECT_LT(worst_E, 2e-9);
  EXPECT_GT(ts, 1.0);  // it starts on its way from -c e1 and turns over within the run
  EXPECT_LT(ts, T - 5.0 / kappa);
  EXPECT_LT(Om0[0], -0.5 * c);
  EXPECT_LT(c - last[0], 1e-4);
}

// The ball's first integrals besides the energy (|M|^2, <M, gamma>, |gamma|^2)
// are constant along the reference solution from the default state, over a
// motion in which the vertical moves all over the body.
TEST(ChaplyginSphere, FirstIntegralsAreConstantAlongTheReferenceSolution) {
  const ChaplyginSphere sys;
  Vec<double, 6> q0, v0;
  scene_state<ChaplyginSphere>(&q0, &v0);
  const auto I0 = sys.first_integrals(q0, v0);
  const double E0 = energy(sys, q0, v0);
  const Vec3 gamma0 = qn::vertical<double>(ChaplyginSphere::quat(q0));
  double worst[4] = {0, 0, 0, 0}, moved = 0;
  ReferenceOptions opt;
  opt.rtol = opt.atol = 1e-13;
  integrate(ReferenceStepper<ChaplyginSphere>(sys, opt), q0, v0, 0.5, 40, [&](const Sample<6, 3>& s) {
    const auto I = sys.first_integrals(s.q, s.v);
    for (int i = 0; i < 3; ++i) worst[i] = std::max(worst[i], std::abs(I[i] - I0[i]));
    worst[3] = std::max(worst[3], std::abs(energy(sys, s.q, s.v) - E0));
    moved = std::max(moved, (qn::vertical<double>(ChaplyginSphere::quat(s.q)) - gamma0).norm());
    return true;
  });
  std::printf(
      "    T = 20: |M|^2 %.2g, <M, gamma> %.2g, |gamma|^2 %.2g, E %.2g off their start (%.4g, %.4g, %.4g, %.4g); "
      "max |gamma - gamma0| %.3f\n",
      worst[0], worst[1], worst[2], worst[3], I0[0], I0[1], I0[2], E0, moved);
  for (int i = 0; i < 4; ++i) EXPECT_LT(worst[i], 1e-9) << i;
  EXPECT_EQ(I0[2], qn::vertical<double>(ChaplyginSphere::quat(q0)).squaredNorm());
  EXPECT_GT(moved, 1.0);  // the motion is not trivial
}

// The norm row p^T pdot = 0 is held as the increment of g = |p|^2 / 2,
// (p0 + p1) . (p1 - p0) / 2h = 0 (roles/discretization.hpp, eq. 17), at every
// alpha: every DLA rule keeps |p| to round-off.  The alpha rule's own row,
// p_alpha . (p1 - p0) / h, would not: it is (|p1|^2 - |p0|^2 - (1 - 2 alpha)
// |p1 - p0|^2) / 2h (checked below on random pairs), which off the midpoint
// moves |p| by O(h^2) a step.  Each step solves its discrete constraint to
// round-off of its terms (MethodContract's 64 eps), so |p1|^2 - |p0|^2 is at
// most 128 eps |p|^2 a step, and the bound over N steps is N 128 eps.
template <class S, class D>
double norm_drift(const D& disc, double h, long steps) {
  const S sys;
  double worst = 0;
  const RunReport rep = integrate(DlaStepper<S, D>(sys, disc), S::default_q0(), S::default_v0(), h, steps,
                                  [&](const Sample<S::n, S::m>& s) {
                                    const Vec4 p = s.q.template tail<4>();
                                    worst = std::max(worst, std::abs(p.squaredNorm() - 1.0));
                                    return true;
                                  });
  EXPECT_TRUE(rep.ok) << rep.reason;
  return worst;
}

template <class S>
void expect_norm_held_by_every_rule() {
  const double bound = 2000 * 128 * std::numeric_limits<double>::epsilon();
  std::printf("    %s, h = 0.05, T = 100: max ||p|^2 - 1|", S::name);
  for (double a : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double d = norm_drift<S>(AlphaDiscretization{a}, 0.05, 2000);
    std::printf(", alpha %g %.2g", a, d);
    EXPECT_LT(d, bound) << "alpha " << a;
  }
  const double sym = norm_drift<S>(SymmetricDiscretization{0.0}, 0.05, 2000);
  std::printf(", symmetric alpha = 0 %.2g\n", sym);
  EXPECT_LT(sym, bound);
  // The alpha rule's own row (what the norm row replaces), on random pairs.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Vec4 p0, p1;
    for (int i = 0; i < 4; ++i) p0[i] = u(rng), p1[i] = u(rng);
    const double a = 0.5 * (1 + u(rng));
    const Vec4 pa = (1 - a) * p0 + a * p1;
    const double row = pa.dot(p1 - p0), identity = 0.5 * (p1.squaredNorm() - p0.squaredNorm() - (1 - 2 * a) * (p1 - p0).squaredNorm());
    EXPECT_NEAR(row, identity, 1e-14);
  }
}

TEST(Suslov, EveryDlaRuleHoldsTheNorm) { expect_norm_held_by_every_rule<Suslov>(); }
TEST(ChaplyginSphere, EveryDlaRuleHoldsTheNorm) { expect_norm_held_by_every_rule<ChaplyginSphere>(); }

}  // namespace
}  // namespace nhi::test
