// The library's steppers where Boost.Odeint expects a stepper (odeint.hpp):
// odeint's integrate_const and integrate_n_steps give the trajectory of `nhi
// run`, bit for bit; a failing step throws naming the step `nhi run` names;
// the adapter's restarts and its fixed-step rule.
#include <gtest/gtest.h>

#include <array>
#include <boost/numeric/odeint/integrate/integrate_const.hpp>
#include <boost/numeric/odeint/integrate/integrate_n_steps.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nhi/interop/odeint.hpp"
#include "nhi/methods/composition.hpp"
#include "nhi/methods/dla/dla.hpp"
#include "nhi/methods/explicit/rk4.hpp"
#include "nhi/methods/mp06/mp06.hpp"
#include "nhi/systems/particle.hpp"

namespace {

using nhi::Particle;
using State = std::array<double, 6>;
using nlohmann::json;
namespace odeint = boost::numeric::odeint;

// `nhi run experiments/scenes/particle.json --set ...`, its result.
json nhi_run(const std::string& sets) {
  const std::string out = testing::TempDir() + "nhi_odeint_result.json";
  std::filesystem::remove(out);
  const std::string cmd =
      std::string(NHI_BINARY) + " run " + NHI_SCENES + "/particle.json " + sets + " -o " + out + " 2> /dev/null";
  const int status = std::system(cmd.c_str());
  EXPECT_TRUE(WIFEXITED(status)) << cmd;
  std::ifstream in(out);
  EXPECT_TRUE(in.good()) << cmd << " wrote no result";
  return json::parse(in);
}

// What an odeint observer saw: the times and states.
struct Trajectory {
  std::vector<double> t;
  std::vector<State> x;
  void operator()(const State& s, double time) {
    t.push_back(time);
    x.push_back(s);
  }
};

State start_state(const json& r) {
  State x;
  for (int i = 0; i < 3; ++i) x[i] = r["scene"]["q0"][i], x[3 + i] = r["scene"]["v0"][i];
  return x;
}

// Every recorded point of `nhi run`, t, q and v, equal bit for bit to the odeint trajectory.
void expect_same_bits(const json& r, const Trajectory& tr) {
  ASSERT_EQ(r["status"], "ok");
  ASSERT_EQ(tr.t.size(), r["t"].size());
  long differ = 0;
  for (size_t k = 0; k < tr.t.size(); ++k) {
    differ += tr.t[k] != r["t"][k].get<double>();
    for (int i = 0; i < 3; ++i) {
      differ += tr.x[k][i] != r["q"][k][i].get<double>();
      differ += tr.x[k][3 + i] != r["v"][k][i].get<double>();
    }
  }
  EXPECT_EQ(differ, 0) << "numbers differing from nhi run, of " << 7 * tr.t.size();
}

nhi::SolverOptions default_options() {
  nhi::MethodSpec spec;  // the scene's defaults: tolerance 1e-12, the predictor start
  return nhi::solver_options(spec);
}

const Particle kParticle{};  // particle.json's params are the defaults (kx = ky = 1)

TEST(Odeint, IntegrateConstWithMp06IsNhiRunBitForBit) {
  const json r = nhi_run("--set method=mp06");
  const double h = r["scene"]["h"];
  const long steps = r["scene"]["steps"];
  nhi::OdeintStepper<nhi::Mp06Stepper<Particle>> stepper{nhi::Mp06Stepper<Particle>(kParticle, default_options())};
  EXPECT_EQ(stepper.order(), 2);
  State x = start_state(r);
  Trajectory tr;
  // Half a step past the last point: odeint stops where t + dt exceeds the
  // end by more than its epsilon, and k h is rounded (odeint.hpp).
  const size_t taken = odeint::integrate_const(stepper, nullptr, x, 0.0, (steps + 0.5) * h, h, std::ref(tr));
  EXPECT_EQ(taken, static_cast<size_t>(steps));
  expect_same_bits(r, tr);
}

TEST(Odeint, IntegrateConstWithTheDlaIsNhiRunBitForBit) {
  // The DLA reports point k once q_{k+1} is known (lag 1): the adapter steps one ahead.
  const json r = nhi_run("--set method=dla");
  const double h = r["scene"]["h"];
  const long steps = r["scene"]["steps"];
  using Dla = nhi::DlaStepper<Particle, nhi::AlphaDiscretization>;
  nhi::OdeintStepper<Dla> stepper{Dla(kParticle, nhi::AlphaDiscretization{0.5}, default_options())};
  State x = start_state(r);
  Trajectory tr;
  odeint::integrate_const(stepper, nullptr, x, 0.0, (steps + 0.5) * h, h, std::ref(tr));
  expect_same_bits(r, tr);
  EXPECT_EQ(stepper.last_sample().k, 0) << "odeint steps a copy of a stepper passed by value";
}

TEST(Odeint, IntegrateNStepsWithAComposedMethodIsNhiRunBitForBit) {
  const json r = nhi_run("--set method=mp06 --set composition=triple_jump --set steps=200");
  const double h = r["scene"]["h"];
  using Tj = nhi::Composed<nhi::Mp06Stepper<Particle>>;
  nhi::OdeintStepper<Tj> stepper{
      Tj(nhi::Mp06Stepper<Particle>(kParticle, default_options()), nhi::composition("triple_jump"))};
  EXPECT_EQ(stepper.order(), 4);
  State x = start_state(r);
  Trajectory tr;
  // By reference: the stepper keeps its state (and its last sample) afterwards.
  odeint::integrate_n_steps(std::ref(stepper), nullptr, x, 0.0, h, 200, std::ref(tr));
  expect_same_bits(r, tr);
  EXPECT_EQ(stepper.last_sample().k, 200);
  EXPECT_TRUE(stepper.last_sample().has_p);
}

TEST(Odeint, AFailingStepThrowsNamingTheStepNhiRunNames) {
  // RK4 far outside its stability interval overflows (as in test_cli).
  const json r = nhi_run("--set method=rk4 --set h=5 --set steps=2000 --set energy_limit=off");
  ASSERT_EQ(r["status"], "failed");
  const long failed = r["failure"]["step"];
  nhi::OdeintStepper<nhi::Rk4Stepper<Particle>> stepper{nhi::Rk4Stepper<Particle>(kParticle)};
  State x = start_state(r);
  Trajectory tr;
  try {
    odeint::integrate_const(stepper, nullptr, x, 0.0, 2000.5 * 5.0, 5.0, std::ref(tr));
    FAIL() << "no exception from a failing step";
  } catch (const nhi::StepFailed& e) {
    EXPECT_EQ(e.step, failed);
    EXPECT_EQ(e.kind, nhi::FailureKind::kNonFinite);
    EXPECT_DOUBLE_EQ(e.time, failed * 5.0);
    EXPECT_NE(std::string(e.what()).find("step " + std::to_string(failed) + " "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
  // Every point before the failure was observed, and x holds the last one reached.
  ASSERT_EQ(tr.t.size(), static_cast<size_t>(failed));
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(x[i], r["q"].back()[i].get<double>());
    EXPECT_EQ(x[3 + i], r["v"].back()[i].get<double>());
  }
}

TEST(Odeint, ContinuesFromItsOwnStateAndRestartsFromAChangedOne) {
  nhi::OdeintStepper<nhi::Mp06Stepper<Particle>> stepper{nhi::Mp06Stepper<Particle>(kParticle, default_options())};
  const State x0 = {1.0, 0.5, 0.0, 0.5, 1.0, 0.25};
  State x = x0;
  std::vector<State> first;
  for (int k = 0; k < 10; ++k) {
    stepper.do_step(nullptr, x, k * 0.2, 0.2);
    first.push_back(x);
  }
  x = x0;  // changed by the caller: a fresh start gives the same ten points
  for (int k = 0; k < 10; ++k) {
    State out;
    stepper.do_step(nullptr, x, k * 0.2, out, 0.2);  // the out-of-place form
    EXPECT_EQ(out, first[k]) << "step " << k;
    x = out;
  }
}

TEST(Odeint, BadStatesAndAChangedStepOfAFixedStepMethodAreRefused) {
  using Dla = nhi::DlaStepper<Particle, nhi::AlphaDiscretization>;
  nhi::OdeintStepper<Dla> dla{Dla(kParticle, nhi::AlphaDiscretization{0.5}, default_options())};
  State x = {1.0, 0.5, 0.0, 0.5, 1.0, 0.25};
  dla.do_step(nullptr, x, 0.0, 0.2);
  EXPECT_THROW(dla.do_step(nullptr, x, 0.2, 0.1), std::invalid_argument);
  std::vector<double> wrong(5, 0.0);
  EXPECT_THROW(dla.do_step(nullptr, wrong, 0.0, 0.2), std::invalid_argument);
  // A method without the rule takes any step, and a std::vector state.
  nhi::OdeintStepper<nhi::Mp06Stepper<Particle>, std::vector<double>> mp06{
      nhi::Mp06Stepper<Particle>(kParticle, default_options())};
  std::vector<double> y = {1.0, 0.5, 0.0, 0.5, 1.0, 0.25};
  mp06.do_step(nullptr, y, 0.0, 0.2);
  EXPECT_NO_THROW(mp06.do_step(nullptr, y, 0.2, 0.1));
}

}  // namespace
