// The scenes beyond the paper's two: what each one claims about itself.
//  * contact_oscillator_nr has exactly the trajectories of contact_oscillator:
//    the reference solution of one (hand-written acceleration) against a
//    reference solution of the other whose right-hand side is derived from L'
//    by autodiff (generic_acceleration), so the gauge term's cancellation is
//    checked, not assumed.
//  * the contact oscillators' first integrals H_y and R along the reference.
//  * the sleigh's closed forms (g = 0; the knife edge a = 0) against the
//    reference solution, and the sleigh's limit speed sqrt(2E/m).
//  * every registered scene file holds its system's default state and parameters.
#include <cstdio>
#include <fstream>

#include "nhi/methods/reference/reference_body.hpp"
#include "nhi/runner/scene.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

// A system whose acceleration() is derived from its Lagrangian by autodiff.
template <class S>
struct DerivedAcceleration : S {
  Vec<double, S::n> acceleration(const Vec<double, S::n>& q, const Vec<double, S::n>& v) const {
    return generic_acceleration(static_cast<const S&>(*this), q, v);
  }
};

TEST(ContactOscillators, TheGaugeTermLeavesTheTrajectoriesUnchanged) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 3; ++trial) {
    ContactOscillator rev;
    DerivedAcceleration<ContactOscillatorNR> nr;
    rev.epsilon = nr.epsilon = trial == 0 ? 0.3 : std::uniform_real_distribution<double>(0.1, 1.0)(rng);
    Vec<double, 3> q0, v0;
    if (trial == 0) {
      q0 = ContactOscillator::default_q0();
      v0 = ContactOscillator::default_v0();
    } else {
      random_state<ContactOscillator>(rng, &q0, &v0, rev);
    }
    Vec<double, 3> qa, va, qb, vb, qt, vt;
    reference_solution(rev, q0, v0, 20.0, 1e-12, &qa, &va);
    reference_solution(nr, q0, v0, 20.0, 1e-12, &qb, &vb);
    // The two agree to the reference's own error at rtol = atol = 1e-12, which a
    // run at 1e-14 measures (within a factor 10).
    reference_solution(rev, q0, v0, 20.0, 1e-14, &qt, &vt);
    const double err_q = std::max((qa - qt).cwiseAbs().maxCoeff(), 1e-13);
    const double err_v = std::max((va - vt).cwiseAbs().maxCoeff(), 1e-13);
    std::printf("    trial %d: |q - q'| = %.2e, |v - v'| = %.2e; reference error %.2e, %.2e\n", trial,
                (qa - qb).cwiseAbs().maxCoeff(), (va - vb).cwiseAbs().maxCoeff(), err_q, err_v);
    EXPECT_LE((qa - qb).cwiseAbs().maxCoeff(), 10 * err_q) << "trial " << trial;
    EXPECT_LE((va - vb).cwiseAbs().maxCoeff(), 10 * err_v) << "trial " << trial;
    EXPECT_GT((qa - qb).cwiseAbs().maxCoeff(), 0.0) << "the two right-hand sides are computed differently";
    // ... and the momenta really differ: p' = p + (0, 0, sin z).
    EXPECT_NEAR((momentum(nr, qa, va) - momentum(rev, qa, va))[2], std::sin(qa[2]), 1e-15);
    // The energy is the same function of (q, v).
    EXPECT_NEAR(energy(nr, qa, va), energy(rev, qa, va), 1e-14);
  }
}

TEST(ContactOscillators, FirstIntegralsAreConservedByTheReference) {
  const ContactOscillator sys;
  const Vec<double, 3> q0 = ContactOscillator::default_q0(), v0 = ContactOscillator::default_v0();
  const auto I0 = sys.first_integrals(q0, v0);
  EXPECT_NEAR(I0[0], 0.5, 1e-15);  // H_y of y = cos t
  EXPECT_NEAR(I0[1], 1.0, 1e-15);  // R = H - H_y: H = 3/2 (the default state's definition)
  EXPECT_NEAR(energy(sys, q0, v0), 1.5, 1e-15);
  double worst = 0;
  const RunReport rep =
      integrate(ReferenceStepper<ContactOscillator>(sys), q0, v0, 0.5, 200, [&](const Sample<3, 1>& s) {
        const auto I = sys.first_integrals(s.q, s.v);
        worst = std::max({worst, std::abs(I[0] - I0[0]), std::abs(I[1] - I0[1])});
        return true;
      });
  ASSERT_TRUE(rep.ok) << rep.reason;
  EXPECT_LT(worst, 1e-9);
  // y(t) = cos t exactly: y decouples.
  Vec<double, 3> q;
  reference_solution(sys, q0, v0, 10.0, 1e-13, &q);
  EXPECT_NEAR(q[1], std::cos(10.0), 1e-10);
}

// The closed form against the reference solution at several times, for the
// default sleigh, random sleighs (g = 0) and random knife edges (a = 0, g != 0).
void check_exact(const Sleigh& sys, const Vec<double, 3>& q0, const Vec<double, 3>& v0, const char* what) {
  for (double T : {0.5, 2.0, 7.0, 15.0}) {
    Vec<double, 3> qe, ve, qr, vr;
    ASSERT_TRUE(sys.exact_solution(q0, v0, T, &qe, &ve)) << what;
    reference_solution(sys, q0, v0, T, 1e-13, &qr, &vr);
    EXPECT_LE((qe - qr).cwiseAbs().maxCoeff(), 1e-10 * (1 + qr.cwiseAbs().maxCoeff())) << what << " T " << T;
    EXPECT_LE((ve - vr).cwiseAbs().maxCoeff(), 1e-10 * (1 + vr.cwiseAbs().maxCoeff())) << what << " T " << T;
    // The closed form itself satisfies the constraint and conserves the energy.
    EXPECT_LE(std::abs(constraint_values(sys, qe, ve)[0]), 1e-13 * (1 + ve.cwiseAbs().maxCoeff())) << what;
    EXPECT_NEAR(energy(sys, qe, ve), energy(sys, q0, v0), 1e-12 * (1 + std::abs(energy(sys, q0, v0)))) << what;
  }
}

TEST(Sleigh, ClosedFormsMatchTheReference) {
  check_exact(Sleigh{}, Sleigh::default_q0(), Sleigh::default_v0(), "default sleigh");
  std::mt19937 rng(32);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  for (int trial = 0; trial < 4; ++trial) {
    Sleigh sys;
    sys.mass = u(rng);
    sys.I = u(rng);
    Vec<double, 3> q0, v0;
    if (trial % 2 == 0) {
      sys.a = u(rng);  // the sleigh, g = 0
    } else {
      sys.a = 0.0;  // the knife edge on an inclined plane
      sys.g = u(rng);
    }
    random_state<Sleigh>(rng, &q0, &v0, sys);
    check_exact(sys, q0, v0, trial % 2 == 0 ? "random sleigh" : "random knife edge");
  }
  // No closed form with both a and g nonzero.
  Sleigh both;
  both.g = 1.0;
  Vec<double, 3> q, v;
  EXPECT_FALSE(both.exact_solution(Sleigh::default_q0(), Sleigh::default_v0(), 1.0, &q, &v));
}

TEST(Sleigh, TendsToStraightLineMotionAtTheLimitSpeed) {
  const Sleigh sys;
  const Vec<double, 3> q0 = Sleigh::default_q0(), v0 = Sleigh::default_v0();
  Vec<double, 3> q, v;
  reference_solution(sys, q0, v0, 40.0, 1e-12, &q, &v);
  const double c = std::sqrt(2 * energy(sys, q0, v0) / sys.mass);
  EXPECT_NEAR(v.head<2>().norm(), c, 1e-9);  // forward speed -> c
  EXPECT_LT(std::abs(v[2]), 1e-10);          // the turn rate decays like sech
}

// The limit speed and heading in closed form against the reference solution at
// the settle time limit_motion() gives, for the default and random sleighs,
// forwards and backwards; none for the knife edge.
TEST(Sleigh, LimitMotionIsTheReferencesLateMotion) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  for (int trial = 0; trial < 4; ++trial) {
    Sleigh sys;
    Vec<double, 3> q0 = Sleigh::default_q0(), v0 = Sleigh::default_v0();
    if (trial > 0) {
      sys.mass = u(rng), sys.I = u(rng), sys.a = u(rng);
      random_state<Sleigh>(rng, &q0, &v0, sys);
    }
    double speed = 0, heading = 0, T = 0;
    ASSERT_TRUE(sys.limit_motion(q0, v0, &speed, &heading, &T));
    Vec<double, 3> q, v;
    reference_solution(sys, q0, v0, T, 1e-12, &q, &v);
    const double forward = std::cos(q[2]) * v[0] + std::sin(q[2]) * v[1];
    EXPECT_NEAR(forward, speed, 1e-9 * speed) << "trial " << trial;
    EXPECT_NEAR(q[2], heading, 1e-9 * (1 + std::abs(heading))) << "trial " << trial;
  }
  Sleigh knife;
  knife.a = 0.0;
  double speed, heading;
  EXPECT_FALSE(knife.limit_motion(Sleigh::default_q0(), Sleigh::default_v0(), &speed, &heading));
}

// Each registered system's scene file holds its default state and parameters.
template <class S>
class SceneFileTest : public ::testing::Test {};
TYPED_TEST_SUITE(SceneFileTest, Systems);

TYPED_TEST(SceneFileTest, SceneFileHoldsTheDefaults) {
  using S = TypeParam;
  const json sc = validate_scene(load_scene_file(std::string(NHI_SCENES) + "/" + S::name + ".json"));
  for (int i = 0; i < S::n; ++i) {
    EXPECT_EQ(sc["q0"][i].template get<double>(), S::default_q0()[i]) << S::name << " q0[" << i << "]";
    EXPECT_EQ(sc["v0"][i].template get<double>(), S::default_v0()[i]) << S::name << " v0[" << i << "]";
  }
  const S sys;
  for (const auto& p : S::parameters())
    EXPECT_EQ(sc["params"][p.name].template get<double>(), sys.*(p.member)) << p.name;
}

// The runner reports the contact oscillators' first integrals at every recorded point.
TEST(ContactOscillators, RunnerReportsTheFirstIntegrals) {
  json sc = load_scene_file(std::string(NHI_SCENES) + "/contact_oscillator.json");
  sc["steps"] = 400;
  sc["method"] = "mp06";
  const json out = run_scene(validate_scene(sc));
  ASSERT_EQ(out["status"], "ok");
  const size_t points = out["t"].size();
  ASSERT_EQ(points, 401u);
  ASSERT_EQ(out["first_integrals"]["H_y"].size(), points);
  ASSERT_EQ(out["first_integrals"]["R"].size(), points);
  EXPECT_EQ(out["first_integrals"]["H_y"][0].get<double>(), 0.5);
  for (size_t k = 0; k < points; ++k) {  // E = H_y + R at every point
    const double E = out["energy"][k], Hy = out["first_integrals"]["H_y"][k], R = out["first_integrals"]["R"][k];
    EXPECT_NEAR(Hy + R, E, 1e-14) << k;
  }
  // mp06 is leapfrog in the decoupled y: H_y oscillates but does not drift.
  double worst = 0;
  for (const auto& Hy : out["first_integrals"]["H_y"]) worst = std::max(worst, std::abs(Hy.get<double>() - 0.5));
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(worst, 0.0);
}

TEST(Sleigh, SceneRejectsANegativeBladeDistance) {
  json sc = load_scene_file(std::string(NHI_SCENES) + "/sleigh.json");
  sc["params"]["a"] = -1.0;
  try {
    validate_scene(sc);
    FAIL() << "accepted a = -1";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("params.a"), std::string::npos) << e.what();
  }
  sc["params"]["a"] = 0.0;  // the knife edge is allowed
  sc["v0"] = {1.0, 0.0, 1.0};
  EXPECT_NO_THROW(validate_scene(sc));
}

}  // namespace
}  // namespace nhi::test
