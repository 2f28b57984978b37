// Study: long runs from a family of initial states, at two steps and two
// couplings: whether a method's energy drifts on a scene, counted over states
// rather than read from one run.
// For every registered scene whose system declares a section family
// (has_section_states: the contact oscillators), the family's 10 states on one
// energy level (H = 3/2, H_y = 1/2, zd0 = 0, z0 = 0.9 sqrt 2 linspace(-1, 1, 10),
// Modin & Verdier 2020), at epsilon = the scene file's and 0 (odelab's
// non-reversible test uses epsilon = 0), and at h = the scene file's
// (2 sin(pi/40): a leapfrog-type method samples y's oscillation every 40 steps)
// and h = 0.15 (41.9 steps a y period: no such resonance), every fixed-step
// "main" method runs --steps steps; its fate is read from the last decade of
// its record as in the long-horizon study (horizon.hpp, lib/nhi/readings/fate.hpp).
// Per scene, epsilon, h and method: how many states drift (growing or failed),
// the median and range of the running max's last-decade log-log slope, and the
// energy error at T relative to |E0|.
#include <algorithm>

#include "horizon.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr int kStates = 10;
constexpr long kSteps = 100000;
constexpr double kOtherH = 0.15;

struct Case {
  std::string scene;
  json scene_json;  // with the case's epsilon and h
  double epsilon = 0, h = 0;
};

double median(std::vector<double> x) {
  if (x.empty()) return std::nan("");
  std::sort(x.begin(), x.end());
  const size_t k = x.size() / 2;
  return x.size() % 2 ? x[k] : 0.5 * (x[k - 1] + x[k]);
}

json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Long runs from a family of initial states, two steps and two couplings"};
  study::Options opt;
  study::add_options(app, opt);
  long steps = kSteps;
  app.add_option("--steps", steps, "Steps of h per run")->check(CLI::Range(10000L, 10000000L));
  study::parse(app, argc, argv);
  const nhi::FateLevels levels;
  const std::vector<nhi::StudyMethod> methods =
      study::methods([](const nhi::StudyMethod& m) { return m.fixed_step() && m.group == "main"; });

  std::vector<Case> cases;
  for (const std::string& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    const bool has_states = nhi::visit_scene(sc, [](const auto& sys, const auto&, const auto&) {
      return nhi::has_section_states<std::decay_t<decltype(sys)>>::value;
    });
    if (!has_states || !sc["params"].contains("epsilon")) continue;
    for (double eps : {sc["params"]["epsilon"].get<double>(), 0.0})
      for (double h : {sc["h"].get<double>(), kOtherH}) {
        json c = sc;
        c["params"]["epsilon"] = eps;
        c["h"] = h;
        cases.push_back({name, nhi::validate_scene(c), eps, h});
      }
  }
  const size_t per_case = methods.size() * kStates;
  study::Cells cells;
  cells.label = "states";
  cells.count = cases.size() * per_case;
  cells.cost = [&](size_t i) {
    const nhi::StudyMethod& m = methods[(i % per_case) / kStates];
    if (!study::studied_on_scene(m, cases[i / per_case].scene_json)) return 0.0;
    return double(steps) * study::step_weight(m.spec);
  };
  cells.name = [&](size_t i) {
    const Case& c = cases[i / per_case];
    char buf[96];
    std::snprintf(buf, sizeof buf, " eps %g h %g ", c.epsilon, c.h);
    return c.scene + buf + methods[(i % per_case) / kStates].label() + ", state " + std::to_string(i % kStates);
  };
  cells.run = [&](size_t i) {
    const Case& c = cases[i / per_case];
    const nhi::StudyMethod& m = methods[(i % per_case) / kStates];
    const int state = static_cast<int>(i % kStates);
    if (!study::studied_on_scene(m, c.scene_json)) return study::not_studied();
    return nhi::visit_scene(c.scene_json, [&](const auto& sys, const auto&, const auto&) -> json {
      using S = std::decay_t<decltype(sys)>;
      if constexpr (nhi::has_section_states<S>::value) {
        const auto z0 = sys.section_states(kStates)[state];
        study::HorizonObserver<S> obs(sys, steps, c.h);
        const double c0 = study::thread_cpu_seconds();
        const nhi::RunReport rep = nhi::run_method(sys, m.spec, z0.first, z0.second, c.h, steps, obs);
        json run = obs.to_json();
        run.update(study::report_json(rep, c.h));
        if (rep.failure == nhi::FailureKind::kObserver) run["failure"]["reason"] = "non-finite energy or constraint";
        const std::string words = study::fate(run, levels);
        const double E0 = run["summary"]["E0"].get<double>();
        const double last = run["energy_error"].empty() ? std::nan("") : run["energy_error"].back().get<double>();
        const json& tail = run["tail"];
        return {
            {"state", state},
            {"z0", z0.first[S::section_coordinate]},
            {"status", run["status"]},
            {"fate", words},
            {"drifting", run["status"] != "ok" || (tail["growing"].get<bool>() && !tail["at_roundoff"].get<bool>())},
            {"at_roundoff", tail["at_roundoff"]},
            {"last_decade_slope", tail["max_slope"]},
            {"max_relative_error", tail["relative"]},
            {"relative_error_at_T", num(std::abs(last) / std::abs(E0))},
            {"cpu_seconds", study::thread_cpu_seconds() - c0}};
      } else {
        return {{"status", "failed"}, {"reason", "no section states"}};
      }
    });
  };
  const std::vector<json> runs = study::map_cells(opt, cells);

  json result = {{"study", "states"},
                 {"config",
                  {{"states", kStates},
                   {"steps", steps},
                   {"h", "the scene file's and 0.15"},
                   {"epsilon", "the scene file's and 0"},
                   {"states_family", "the system's section_states(10): H = 3/2, H_y = 1/2, zd0 = 0, z0 spread"},
                   {"drifting",
                    "a run that failed or whose last decade grows above round-off (lib/nhi/readings/fate.hpp; at_roundoff: "
                    "growing, but max |E - E0| <= roundoff_relative |E0|)"},
                   {"fate_levels", study::levels_json(levels)}}}};
  for (size_t ci = 0; ci < cases.size(); ++ci) {
    const Case& c = cases[ci];
    json ms = json::array();
    for (size_t mi = 0; mi < methods.size(); ++mi) {
      if (study::is_not_studied(runs[ci * per_case + mi * kStates])) continue;
      json rs = json::array();
      int drifting = 0, failed = 0, roundoff = 0;
      std::vector<double> slopes, errors;
      for (int s = 0; s < kStates; ++s) {
        const json& r = runs[ci * per_case + mi * kStates + s];
        rs.push_back(r);
        drifting += r["drifting"].get<bool>() ? 1 : 0;
        roundoff += r["status"] == "ok" && r["at_roundoff"].get<bool>() ? 1 : 0;
        failed += r["status"] != "ok" ? 1 : 0;
        if (r["status"] == "ok" && !r["last_decade_slope"].is_null())
          slopes.push_back(r["last_decade_slope"].get<double>());
        if (r["status"] == "ok" && !r["relative_error_at_T"].is_null())
          errors.push_back(r["relative_error_at_T"].get<double>());
      }
      const bool any = !slopes.empty();
      ms.push_back({{"label", methods[mi].label()},
                    {"drifting", drifting},
                    {"failed", failed},
                    {"at_roundoff", roundoff},
                    {"median_slope", num(median(slopes))},
                    {"min_slope", any ? num(*std::min_element(slopes.begin(), slopes.end())) : json(nullptr)},
                    {"max_slope", any ? num(*std::max_element(slopes.begin(), slopes.end())) : json(nullptr)},
                    {"median_relative_error_at_T", num(median(errors))},
                    {"max_relative_error_at_T",
                     errors.empty() ? json(nullptr) : num(*std::max_element(errors.begin(), errors.end()))},
                    {"runs", rs}});
    }
    result["scenes"][c.scene]["cases"].push_back(
        {{"epsilon", c.epsilon}, {"h", c.h}, {"T", c.h * double(steps)}, {"methods", ms}});
  }
  return study::finish(opt, result);
}
