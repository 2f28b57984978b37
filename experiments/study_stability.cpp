// Study 3: where each method fails.
// h on a geometric grid from 0.01 to 10 (10 per decade), T = 200 (--T), every
// registered scene, for every fixed-step method of nhi::study_methods() (the DLA
// with alpha = 0, 1/4, 1/2, 3/4, 1 and symmetric alpha = 0, 1/4; RK4).
// A run fails when a step solve does not converge, the state stops being
// finite, or |E - E0| exceeds |E0| (an energy error as large as the energy
// itself).  A run that exceeds the energy threshold goes on to T, so that
// "stable within the threshold" and "survives at all" are both measured.
// The reference solution is adaptive (its h is only the output interval), so it
// has no stability limit in h and is not swept.
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr double kEnergyThreshold = 1.0;  // relative to |E0|

template <class S>
json run_one(const S& sys, const nhi::MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
             const Vec<double, S::n>& qref, double h, double T) {
  const long steps = std::max(1L, std::lround(T / h));
  const double E0 = nhi::energy(sys, q0, v0);
  double max_dE = 0, exceeded_at = -1;
  bool nonfinite = false;
  Vec<double, S::n> q_last = q0;
  const nhi::RunReport rep = nhi::run_method(sys, spec, q0, v0, h, steps, [&](const nhi::Sample<S::n, S::m>& s) {
    const double dE = std::abs(nhi::energy(sys, s.q, s.v) - E0);
    if (!std::isfinite(dE)) {
      nonfinite = true;
      return false;
    }
    max_dE = std::max(max_dE, dE);
    if (exceeded_at < 0 && dE > kEnergyThreshold * std::abs(E0)) exceeded_at = s.t;
    q_last = s.q;
    return true;
  });
  json j = {{"h", h},
            {"steps", steps},
            {"max_abs_energy_error", max_dE},
            {"fallback_steps", rep.fallbacks},
            {"newton_iterations", rep.newton_iterations}};
  if (rep.ok) j["error_at_T"] = (q_last - qref).cwiseAbs().maxCoeff();
  if (!rep.ok) {
    const std::string kind = nonfinite || rep.failure == nhi::FailureKind::kNonFinite ? "non-finite" : "solve";
    j["status"] = "failed";
    j["failure"] = {{"kind", kind},
                    {"step", rep.failure_step},
                    {"time", rep.failure_step * h},
                    {"reason", nonfinite ? "non-finite energy" : rep.reason}};
  } else if (exceeded_at >= 0) {
    j["status"] = "failed";
    j["failure"] = {{"kind", "energy"},
                    {"step", std::lround(exceeded_at / h)},
                    {"time", exceeded_at},
                    {"reason", "|E - E0| > |E0|"}};
  } else {
    j["status"] = "ok";
  }
  // Survived: no solve failure and a finite state to T (energy threshold aside).
  j["survived"] = rep.ok;
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Stability: where each method fails, every scene"};
  study::Options opt;
  study::add_options(app, opt);
  double T = 200.0;
  app.add_option("--T", T, "Final time of every run")->check(CLI::PositiveNumber);
  study::parse(app, argc, argv);
  std::vector<double> hs;
  for (int i = 0; i <= 30; ++i) hs.push_back(0.01 * std::pow(10.0, i / 10.0));
  const std::vector<nhi::StudyMethod> methods = study::methods(study::fixed_step);
  json result = {
      {"study", "stability"},
      {"config",
       {{"T", T},
        {"h", hs},
        {"failure", "step solve not converged (solve), non-finite state (non-finite), or |E - E0| > |E0| (energy)"},
        {"largest_stable_h", "largest grid h such that every grid h up to it completed within the energy threshold"},
        {"largest_surviving_h",
         "largest grid h such that every grid h up to it reached T with converged solves and a finite state"},
        {"reference", "not swept: the reference solution (CVODE) is adaptive, its h is only the output interval"}}}};
  for (const auto& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    result["scenes"][name] = nhi::visit_scene(sc, [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      const Vec<double, S::n> qref = study::reference_q(sys, q0, v0, T, 1e-12);
      study::Cells cells;
      cells.label = "stability " + name;
      cells.count = methods.size() * hs.size();
      cells.run = [&](size_t i) {
        return run_one(sys, methods[i / hs.size()].spec, q0, v0, qref, hs[i % hs.size()], T);
      };
      cells.cost = [&](size_t i) { return T / hs[i % hs.size()] * study::step_weight(methods[i / hs.size()].spec); };
      cells.name = [&](size_t i) {
        return methods[i / hs.size()].label() + " at h = " + std::to_string(hs[i % hs.size()]);
      };
      const std::vector<json> runs = study::map_cells(opt, cells);
      json ms = json::array();
      for (size_t m = 0; m < methods.size(); ++m) {
        json rs = json::array();
        double largest = 0, survivor = 0;
        bool broken = false, dead = false;
        json first_failure = nullptr;
        for (size_t j = 0; j < hs.size(); ++j) {
          const json& r = runs[m * hs.size() + j];
          rs.push_back(r);
          if (r["status"] == "ok" && !broken) largest = hs[j];
          if (r["status"] != "ok" && !broken) {
            broken = true;
            first_failure = {{"h", hs[j]}, {"failure", r["failure"]}};
          }
          if (r["survived"] && !dead) survivor = hs[j];
          if (!r["survived"]) dead = true;
        }
        ms.push_back({{"label", methods[m].label()},
                      {"runs", rs},
                      {"largest_stable_h", largest > 0 ? json(largest) : json(nullptr)},
                      {"largest_surviving_h", survivor > 0 ? json(survivor) : json(nullptr)},
                      {"first_failure", first_failure}});
      }
      return json{{"scene", sc}, {"reference_q", study::to_json<S::n>(qref)}, {"methods", ms}};
    });
  }
  return study::finish(opt, result);
}
