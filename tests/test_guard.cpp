// A blown-up run is a failed run (guard.hpp), and the adaptive pairs rkf78 and
// dopri5 run as library methods (embedded_rk.hpp): through `nhi run`, on every
// registered system, bit for bit Boost.Odeint's integrate_adaptive over one
// output interval, to their tolerance.
#include <gtest/gtest.h>

#include <boost/numeric/odeint/integrate/integrate_adaptive.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>

#include "nhi/methods/reference/reference.hpp"
#include "nhi/roles/guard.hpp"
#include "nhi/runner/scene.hpp"
#include "scenes.hpp"

namespace {

using nhi::json;
using nhi::Vec;

// `nhi run SCENE --set ...`: the exit status and the result (null if none).
struct CliRun {
  int exit_code = -1;
  json result;
};
CliRun nhi_run(const std::string& scene, const std::string& sets) {
  // One file per process: ctest runs each test as its own process, two at a time.
  const std::string out = testing::TempDir() + "nhi_guard_result_" + std::to_string(::getpid()) + ".json";
  std::filesystem::remove(out);
  const std::string cmd =
      std::string(NHI_BINARY) + " run " + NHI_SCENES + "/" + scene + " " + sets + " -o " + out + " 2> /dev/null";
  const int status = std::system(cmd.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (std::ifstream in(out); in) r.result = json::parse(in);
  std::filesystem::remove(out);
  return r;
}

TEST(EnergyLimit, BoundAndWords) {
  const auto d = nhi::EnergyLimit::runner_default();
  EXPECT_DOUBLE_EQ(d.bound(0.25), 1.0);
  EXPECT_DOUBLE_EQ(d.bound(-3.0), 3.0);
  EXPECT_EQ(d.describe(), "max(|E0|, 1)");
  const auto r = nhi::EnergyLimit::relative_to_E0(nhi::EnergyLimit::Mode::kStop);
  EXPECT_DOUBLE_EQ(r.bound(0.25), 0.25);
  EXPECT_EQ(r.describe(), "|E0|");
  EXPECT_EQ(nhi::EnergyLimit::absolute_bound(0.5).describe(), "0.5");
  EXPECT_TRUE(d.exceeded(std::numeric_limits<double>::quiet_NaN(), 1.0));
  EXPECT_FALSE(d.exceeded(1.0, 1.0));
  EXPECT_TRUE(d.exceeded(1.0 + 1e-15, 0.0));
  EXPECT_FALSE(nhi::EnergyLimit::off().on());
}

// The case: mp06 at h = 3 on the particle grows to |E - E0| ~ 1e240 in
// 100 steps with a finite state; the runner says failed (exit 3), names the
// step and why, and writes the points before it.
TEST(Guard, BlownUpRunIsFailedWithItsStepNamed) {
  const CliRun r = nhi_run("particle.json", "--set method=mp06 --set h=3 --set steps=100");
  ASSERT_EQ(r.exit_code, 3);
  ASSERT_EQ(r.result["status"], "failed");
  const json& f = r.result["failure"];
  EXPECT_EQ(f["kind"], "energy");
  const long step = f["step"];
  EXPECT_GT(step, 0);
  EXPECT_LT(step, 100);
  EXPECT_NE(f["reason"].get<std::string>().find("energy limit"), std::string::npos) << f["reason"];
  EXPECT_EQ(r.result["scene"]["energy_limit"], "auto");
  // Every point written is within the limit max(|E0|, 1); the next is the one that passed it.
  ASSERT_EQ(r.result["t"].size(), size_t(step));
  const double E0 = r.result["energy"][0];
  for (const auto& E : r.result["energy"]) EXPECT_LE(std::abs(E.get<double>() - E0), std::max(std::abs(E0), 1.0));
}

// The DLA with alpha = 1 gains energy (README, finding 3): the run fails
// where |E - E0| first passes max(|E0|, 1), kind "energy".  (At h = 1e6 the
// DLA's energy stays bounded, |E - E0| = 0.66 on the particle: the guard sees
// a run blow up, not a run that is merely inaccurate.)
TEST(Guard, DlaWithAlphaOneFailsWhereItsEnergyPassesTheLimit) {
  const CliRun r = nhi_run("particle.json", "--set method=dla --set alpha=1 --set h=0.2 --set steps=5000");
  ASSERT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.result["failure"]["kind"], "energy");
  const double E0 = r.result["energy"][0];
  double worst = 0;
  for (const auto& E : r.result["energy"]) worst = std::max(worst, std::abs(E.get<double>() - E0));
  EXPECT_LE(worst, std::max(std::abs(E0), 1.0));
  EXPECT_GT(worst, 0.5 * std::max(std::abs(E0), 1.0));  // it grew towards the limit, it did not jump
}

// "off" turns the check off (the same run reaches its end, its energy error
// far past the limit); a number is an absolute bound on |E - E0|.
TEST(Guard, SceneKeyTurnsTheCheckOffOrSetsTheBound) {
  const CliRun off = nhi_run("particle.json", "--set method=mp06 --set h=3 --set steps=100 --set energy_limit=off");
  ASSERT_EQ(off.exit_code, 0);
  EXPECT_EQ(off.result["status"], "ok");
  EXPECT_GT(off.result["summary"]["max_abs_energy_error"].get<double>(), 1e100);

  const CliRun tight = nhi_run("particle.json", "--set method=rk4 --set h=0.2 --set steps=2000 --set energy_limit=1e-3");
  ASSERT_EQ(tight.exit_code, 3);
  EXPECT_EQ(tight.result["failure"]["kind"], "energy");
  const CliRun loose = nhi_run("particle.json", "--set method=rk4 --set h=0.2 --set steps=2000 --set energy_limit=1");
  EXPECT_EQ(loose.exit_code, 0);
  // A bad value is refused naming the key, nothing written.
  const CliRun bad = nhi_run("particle.json", "--set energy_limit=-1");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_TRUE(bad.result.is_null());
}

// The guard reads the run, it does not change it: with the limit on, a run
// that stays within it is the run without a limit, bit for bit.
template <class S>
class GuardOnEverySystem : public ::testing::Test {};
TYPED_TEST_SUITE(GuardOnEverySystem, nhi::test::Systems);

TYPED_TEST(GuardOnEverySystem, MovesNoNumberOfARunWithinTheLimit) {
  using S = TypeParam;
  const S sys;
  Vec<double, S::n> q0, v0;
  nhi::test::scene_state<S>(&q0, &v0);
  for (const char* kind : {"mp06", "rk4", "dla"}) {
    const nhi::MethodSpec spec = nhi::spec_of(kind);
    std::vector<double> a, b;
    auto keep = [](std::vector<double>* out) {
      return [out](const nhi::Sample<S::n, S::m>& s) {
        out->insert(out->end(), s.q.data(), s.q.data() + S::n);
        return true;
      };
    };
    const nhi::RunReport ra = nhi::run_method(sys, spec, q0, v0, 0.05, 200, keep(&a));
    const nhi::RunReport rb =
        nhi::run_method(sys, spec, q0, v0, 0.05, 200, keep(&b), nhi::EnergyLimit::runner_default());
    ASSERT_TRUE(ra.ok && rb.ok) << kind << ": " << rb.reason;
    EXPECT_EQ(a, b) << kind;
  }
}

// The recorded mode (the stability study's) notes the first point past the
// bound and goes on to the end.
TYPED_TEST(GuardOnEverySystem, RecordModeNotesTheFirstPointPastTheBoundAndGoesOn) {
  using S = TypeParam;
  const S sys;
  Vec<double, S::n> q0, v0;
  nhi::test::scene_state<S>(&q0, &v0);
  const double E0 = nhi::energy(sys, q0, v0);
  // A bound of 0 is passed at the first point whose energy differs from E0 at all.
  nhi::EnergyLimit lim{nhi::EnergyLimit::Mode::kRecord, 0.0, 0.0};
  long first = -1;
  const nhi::RunReport rep = nhi::run_method(
      sys, nhi::spec_of("rk4"), q0, v0, 0.1, 50,
      [&](const nhi::Sample<S::n, S::m>& s) {
        if (first < 0 && std::abs(nhi::energy(sys, s.q, s.v) - E0) > 0) first = s.k;
        return true;
      },
      lim);
  EXPECT_TRUE(rep.ok);
  EXPECT_EQ(rep.steps_taken, 50);
  EXPECT_EQ(rep.energy_exceeded_step, first);
}

// rkf78 and dopri5 over one output interval h = T are Boost.Odeint's
// integrate_adaptive over [0, T] (the work-precision study's settings: atol =
// rtol = tol, first trial step 0.01), bit for bit.
template <class S, class Pair>
Vec<double, 2 * S::n> odeint_adaptive(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                                      double T, double tol) {
  namespace odeint = boost::numeric::odeint;
  nhi::OdeState<S> x;
  for (int i = 0; i < S::n; ++i) x[i] = q0[i], x[S::n + i] = v0[i];
  long rhs = 0;
  odeint::integrate_adaptive(odeint::make_controlled<typename Pair::template stepper<nhi::OdeState<S>>>(tol, tol),
                             nhi::OdeRhs<S>{&sys, &rhs}, x, 0.0, T, 0.01);
  return Eigen::Map<const Vec<double, 2 * S::n>>(x.data());
}

template <class S>
class PairsOnEverySystem : public ::testing::Test {};
TYPED_TEST_SUITE(PairsOnEverySystem, nhi::test::Systems);

TYPED_TEST(PairsOnEverySystem, OneOutputIntervalIsOdeintsIntegrateAdaptiveBitForBit) {
  using S = TypeParam;
  const S sys;
  Vec<double, S::n> q0, v0;
  nhi::test::scene_state<S>(&q0, &v0);
  for (double tol : {1e-5, 1e-10}) {
    for (const char* kind : {"rkf78", "dopri5"}) {
      nhi::MethodSpec spec = nhi::spec_of(kind);
      spec.tolerance = tol;
      auto st = nhi::make_stepper(sys, spec);
      st->start(q0, v0);
      ASSERT_TRUE(st->step(3.0).ok());
      const Vec<double, 2 * S::n> want = std::string(kind) == "rkf78"
                                             ? odeint_adaptive<S, nhi::Rkf78Pair>(sys, q0, v0, 3.0, tol)
                                             : odeint_adaptive<S, nhi::Dopri5Pair>(sys, q0, v0, 3.0, tol);
      const Vec<double, 2 * S::n> got = st->phase();
      for (int i = 0; i < 2 * S::n; ++i) EXPECT_EQ(got[i], want[i]) << kind << " tol " << tol << " component " << i;
    }
  }
}

// Their error at the output points follows the tolerance: against CVODE at
// 1e-13, max |q(t_k) - q_ref(t_k)| over t_k = 0.5 k <= 5 is below 100 tol at
// tol = 1e-6 and 1e-9 (an error-per-step control keeps the global error a
// modest multiple of tol over a few time units), and no larger at the
// tighter one (on the sleigh and the rolling disk rkf78 is already at ~5e-9
// with tol = 1e-6).  Points land on the grid exactly.
TYPED_TEST(PairsOnEverySystem, ErrorAtTheOutputGridFollowsTheTolerance) {
  using S = TypeParam;
  const S sys;
  Vec<double, S::n> q0, v0;
  nhi::test::scene_state<S>(&q0, &v0);
  nhi::ReferenceOptions ro;
  ro.rtol = ro.atol = 1e-13;
  for (const char* kind : {"rkf78", "dopri5"}) {
    double err[2];
    int i = 0;
    for (double tol : {1e-6, 1e-9}) {
      nhi::MethodSpec spec = nhi::spec_of(kind);
      spec.tolerance = tol;
      nhi::CvodeReference<S> ref(sys, 0.0, q0, v0, ro);
      double e = 0;
      long points = 0;
      const nhi::RunReport rep = nhi::run_method(sys, spec, q0, v0, 0.5, 10, [&](const nhi::Sample<S::n, S::m>& s) {
        EXPECT_EQ(s.t, s.k * 0.5);
        if (s.k > 0) {
          Vec<double, S::n> qr, vr;
          ref.advance(s.t, &qr, &vr);
          e = std::max(e, (s.q - qr).cwiseAbs().maxCoeff());
        }
        ++points;
        return true;
      });
      ASSERT_TRUE(rep.ok) << kind << ": " << rep.reason;
      EXPECT_EQ(points, 11);
      EXPECT_GT(rep.internal_steps, 0);
      EXPECT_LT(e, 100 * tol) << kind << " tol " << tol;
      err[i++] = e;
    }
    EXPECT_LE(err[1], err[0]) << kind;
  }
}

// `nhi run --set method=rkf78 --set tolerance=TOL --set h=10 --set steps=1`
// gives the work-precision study's final error for the same settings (its
// row final_error = max_i |q_i(10) - q_ref,i(10)|, q_ref the reference
// solution at 1e-13), bit for bit, in the committed results/.
TEST(Pairs, RunnerGivesTheWorkPrecisionStudysFinalError) {
  std::ifstream in(std::string(NHI_SOURCE_DIR) + "/results/work_precision.json");
  ASSERT_TRUE(in.good());
  const json wp = json::parse(in);
  const json ref = nhi_run("particle.json", "--set method=benchmark --set tolerance=1e-13 --set h=10 --set steps=1").result;
  ASSERT_EQ(ref["status"], "ok");
  int compared = 0;
  for (const auto& row : wp["scenes"]["particle"]["runs"]) {
    const std::string label = row["label"];
    if (label != "rkf78" && label != "dopri5") continue;
    const double tol = row["param"];
    if (tol != 1e-6 && tol != 1e-9) continue;
    char sets[160];
    std::snprintf(sets, sizeof sets, "--set method=%s --set tolerance=%.17g --set h=10 --set steps=1", label.c_str(), tol);
    const json r = nhi_run("particle.json", sets).result;
    double e = 0;
    for (int i = 0; i < 3; ++i) e = std::max(e, std::abs(r["q"][1][i].get<double>() - ref["q"][1][i].get<double>()));
    EXPECT_EQ(e, row["final_error"].get<double>()) << label << " tol " << tol;
    ++compared;
  }
  EXPECT_EQ(compared, 4);
}

TEST(Pairs, RunFromTheRunnerWithStatsAndTheirTraits) {
  const CliRun r = nhi_run("particle.json", "--set method=rkf78 --set tolerance=1e-8 --set h=0.5 --set steps=20");
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.result["t"].size(), 21u);
  EXPECT_EQ(r.result["t"][20].get<double>(), 10.0);
  EXPECT_GT(r.result["stats"]["internal_steps"].get<long>(), 20);
  EXPECT_GE(r.result["stats"]["rejected_steps"].get<long>(), 0);
  EXPECT_GT(r.result["stats"]["rhs_evaluations"].get<long>(), 13 * 20);
  const nhi::MethodTraits t = nhi::method_traits(nhi::Particle{}, nhi::spec_of("dopri5"));
  EXPECT_TRUE(t.adaptive);
  EXPECT_EQ(t.order, 5);
  // Not symmetric: a composition is refused.
  EXPECT_EQ(nhi_run("particle.json", "--set method=dopri5 --set composition=triple_jump").exit_code, 2);
}

}  // namespace
