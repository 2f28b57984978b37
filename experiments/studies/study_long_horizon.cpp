// Study 2: energy and constraints over long horizons.
// 10^6 steps of the scene file's h (0.2 on the paper's scenes, T = 2e5; 2 sin(pi/40)
// on the contact oscillators, as McLachlan & Perlmutter and Modin & Verdier;
// 0.1 on the chaotic oscillator and the sleigh) on every registered scene, for every library
// method of nhi::study_methods(): the "main" ones (DLA alpha = 1/2, symmetric
// DLA alpha = 0, RK4, the reference solution) and the "variant"s (alpha = 0,
// 1/4, 3/4, 1; symmetric alpha = 1/4), whose energy fate the table states.
// Nothing holds every step: the observer keeps, at ~40 log-spaced checkpoints
// per decade, the instantaneous energy error and constraint value and their
// running maxima over every step (and the same for the system's other first
// integrals, H_y and R of the contact oscillators), plus block means of E - E0 over blocks of
// 1000 steps for the drift rate.
//   The reference solution (CVODE) runs 10^5 steps of h (--reference-steps):
// CVODE makes ~12 internal steps per step of h, so 10^6 steps of it would be
// about half of the study's CPU time, and over 10^5 it already shows its
// energy drifting (README, "Studies").
#include "horizon.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr long kSteps = 1000000;
constexpr long kReferenceSteps = 100000;  // the default of --reference-steps

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Energy and constraints over long horizons, every scene"};
  study::Options opt;
  study::add_options(app, opt);
  long reference_steps = kReferenceSteps;
  app.add_option("--reference-steps", reference_steps,
                 "Steps of h for the reference solution (the other methods: 10^6)")
      ->check(CLI::Range(1000L, kSteps));
  study::parse(app, argc, argv);
  const nhi::FateLevels levels;
  const std::vector<nhi::StudyMethod> methods = study::methods([](const nhi::StudyMethod& m) { return !m.external && m.group != "costly"; });
  json result = {{"study", "long_horizon"},
                 {"config",
                  {{"h", "per scene: the scene file's h"},
                   {"steps", kSteps},
                   {"reference_steps", reference_steps},
                   {"block", study::kBlock},
                   {"drift_rate", "least-squares slope of block means of E - E0 against t"},
                   {"envelope_growth_exponent", "log-log slope of max_{s<=t} |E - E0| over t in [T/1000, T]"},
                   {"fate",
                    "read from the last decade [T/10, T] (lib/nhi/readings/fate.hpp): blows up if a step solve failed or the "
                    "state became non-finite; dissipates/grows if |mean of the last decade's block means of E - E0| > "
                    "runaway_relative |E0|; drifts up/down, wanders or drifts if growing (the running max's log-log "
                    "slope >= grows_slope, a systematic block-mean trend, or block means that wander); large, not "
                    "growing if max |E - E0| > bounded_relative |E0|; else bounded. First integrals: offset if the "
                    "last decade's slope of their running max error < grows_slope, else drift"},
                   {"fate_levels", study::levels_json(levels)}}}};
  const std::vector<std::string> scenes = study::scene_names(opt);
  std::vector<json> scene_json;
  for (const auto& name : scenes) scene_json.push_back(study::scene(opt, name));
  study::Cells cells;
  cells.label = "long horizon";
  cells.count = scenes.size() * methods.size();
  // Steps of method m: reference_steps for the reference solution, else kSteps.
  auto steps_of = [&](const nhi::StudyMethod& m) { return m.adaptive() ? reference_steps : kSteps; };
  // The longest runs first (map_cells orders them by this estimate).
  cells.cost = [&](size_t i) {
    const nhi::StudyMethod& m = methods[i % methods.size()];
    if (!study::studied_on_scene(m, scene_json[i / methods.size()])) return 0.0;
    return steps_of(m) * study::step_weight(m.spec);
  };
  cells.name = [&](size_t i) { return scenes[i / methods.size()] + " " + methods[i % methods.size()].label(); };
  cells.run = [&](size_t i) {
    const nhi::StudyMethod& m = methods[i % methods.size()];
    if (!study::studied_on_scene(m, scene_json[i / methods.size()])) return study::not_studied();
    return nhi::visit_scene(scene_json[i / methods.size()], [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      const double h = scene_json[i / methods.size()]["h"].get<double>();
      const long steps = steps_of(m);
      study::HorizonObserver<S> obs(sys, steps, h);
      const double c0 = study::thread_cpu_seconds();
      const nhi::RunReport rep = nhi::run_method(sys, m.spec, q0, v0, h, steps, obs);
      json j = obs.to_json();
      j["cpu_seconds"] = study::thread_cpu_seconds() - c0;
      j["label"] = m.label();
      j["steps"] = steps;
      j["T"] = h * double(steps);
      j["group"] = m.group;
      j.update(study::report_json(rep, h));
      if (rep.failure == nhi::FailureKind::kObserver) j["failure"]["reason"] = "non-finite energy or constraint";
      j["fate"] = study::fate(j, levels);
      return j;
    });
  };
  const std::vector<json> runs = study::map_cells(opt, cells);
  for (size_t s = 0; s < scenes.size(); ++s) {
    json ms = json::array();
    for (size_t k = 0; k < methods.size(); ++k)
      if (!study::is_not_studied(runs[s * methods.size() + k])) ms.push_back(runs[s * methods.size() + k]);
    result["scenes"][scenes[s]] = {{"scene", scene_json[s]},
                                   {"h", scene_json[s]["h"]},
                                   {"T", scene_json[s]["h"].get<double>() * kSteps},
                                   {"methods", ms}};
  }
  return study::finish(opt, result);
}
