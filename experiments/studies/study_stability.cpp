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
//   Roots.  At a large h an implicit step's equations can have several roots,
// and the start of the solve decides which one a run follows, so a limit
// found with the method's own start (its predictor) is partly the solver's.
// For every implicit method and every grid h >= --roots-from (default 0.1), the run
// with the predictor also checks at every step whether its root is the one
// continued from h -> 0 (solver.hpp, root following; the check moves no
// number of the run), and a second run starts every step's solve from that
// continued root instead.  Per method: the limits with either start, and
// the largest h up to which the predictor's runs took the continued root at
// every step.  Where no root can be continued to h (the branch from h -> 0
// folds), the continued run fails there ("solve", "no root continued"): that
// limit is the method's own; the predictor's is the method's together with
// its solver.  Below --roots-from the starts are not compared: checking the
// whole grid (--roots-from 0.01) costs about ten times the study, and on the
// registered scenes it finds every run below h = 0.1 on the continued root at
// every step, with the same limits either way.
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

template <class S>
json run_one(const S& sys, const nhi::MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
             const Vec<double, S::n>& qref, double h, double T) {
  const long steps = std::max(1L, std::lround(T / h));
  const double E0 = nhi::energy(sys, q0, v0);
  double max_dE = 0;
  Vec<double, S::n> q_last = q0;
  // The threshold through the runs' guard (guard.hpp): a non-finite point ends
  // the run, |E - E0| > |E0| is recorded and the run goes on to T.
  const nhi::RunReport rep = nhi::run_method(
      sys, spec, q0, v0, h, steps,
      [&](const nhi::Sample<S::n, S::m>& s) {
        max_dE = std::max(max_dE, std::abs(nhi::energy(sys, s.q, s.v) - E0));
        q_last = s.q;
        return true;
      },
      nhi::EnergyLimit::relative_to_E0(nhi::EnergyLimit::Mode::kRecord));
  json j = {{"h", h},
            {"steps", steps},
            {"max_abs_energy_error", max_dE},
            {"fallback_steps", rep.fallbacks},
            {"newton_iterations", rep.newton_iterations}};
  if (rep.ok) j["error_at_T"] = (q_last - qref).cwiseAbs().maxCoeff();
  if (!rep.ok) {
    const bool nonfinite_energy = rep.stopped_by_guard;
    const std::string kind = rep.failure == nhi::FailureKind::kNonFinite ? "non-finite" : "solve";
    j["status"] = "failed";
    j["failure"] = {{"kind", kind},
                    {"step", rep.failure_step},
                    {"time", rep.failure_step * h},
                    {"reason", nonfinite_energy ? "non-finite energy" : rep.reason}};
  } else if (rep.energy_exceeded_step >= 0) {
    j["status"] = "failed";
    j["failure"] = {{"kind", "energy"},
                    {"step", rep.energy_exceeded_step},
                    {"time", rep.energy_exceeded_step * h},
                    {"reason", "|E - E0| > |E0|"}};
  } else {
    j["status"] = "ok";
  }
  // Survived: no solve failure and a finite state to T (energy threshold aside).
  j["survived"] = rep.ok;
  if (spec.root_check)
    j["roots"] = {
        {"checked_steps", rep.root_checked_steps},
        {"other_root_steps", rep.other_root_steps},
        {"no_continued_root_steps", rep.no_continued_root_steps},
        {"first_departure_time", rep.first_root_departure >= 0 ? json(rep.first_root_departure * h) : json(nullptr)}};
  return j;
}

// The largest grid h such that every run up to it is ok (stable) or survived,
// from a list of runs in increasing h; null if the first is not.
json largest_h(const std::vector<json>& runs, const std::vector<double>& hs, const char* key, const json& ok_value) {
  double best = 0;
  for (size_t j = 0; j < runs.size(); ++j) {
    if (runs[j][key] != ok_value) break;
    best = hs[j];
  }
  return best > 0 ? json(best) : json(nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Stability: where each method fails, every scene"};
  study::Options opt;
  study::add_options(app, opt);
  double T = 200.0;
  app.add_option("--T", T, "Final time of every run")->check(CLI::PositiveNumber);
  double roots_from = 0.1;
  app.add_option("--roots-from", roots_from, "Smallest h at which the implicit methods' roots are followed")
      ->check(CLI::PositiveNumber);
  study::parse(app, argc, argv);
  std::vector<double> hs;
  for (int i = 0; i <= 30; ++i) hs.push_back(0.01 * std::pow(10.0, i / 10.0));
  size_t first_root_h = hs.size();  // the first grid h >= roots_from
  for (size_t j = hs.size(); j-- > 0;)
    if (hs[j] >= roots_from * (1 - 1e-12)) first_root_h = j;
  const std::vector<double> root_hs(hs.begin() + first_root_h, hs.end());
  const std::vector<nhi::StudyMethod> all_methods = study::methods(study::fixed_step);
  json result = {
      {"study", "stability"},
      {"config",
       {{"T", T},
        {"h", hs},
        {"failure", "step solve not converged (solve), non-finite state (non-finite), or |E - E0| > |E0| (energy)"},
        {"largest_stable_h", "largest grid h such that every grid h up to it completed within the energy threshold"},
        {"largest_surviving_h",
         "largest grid h such that every grid h up to it reached T with converged solves and a finite state"},
        {"reference", "not swept: the reference solution (CVODE) is adaptive, its h is only the output interval"},
        {"roots",
         {{"h_from", roots_from},
          {"check",
           "implicit methods, h >= h_from: each step of the predictor's run also solved by continuation in "
           "h from h -> 0 (solver.hpp); roots agree when within 1e-6 (1 + size)"},
          {"continued", "a second run whose every step starts from the root continued from h -> 0"},
          {"largest_stable_h_continued", "as largest_stable_h for the continued runs, over h >= h_from"},
          {"followed_continued_root_up_to",
           "largest grid h >= h_from up to which every predictor run took the continued root at every step"}}}}}};
  for (const auto& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    result["scenes"][name] = nhi::visit_scene(sc, [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      const std::vector<nhi::StudyMethod> methods = study::on<S>(all_methods);
      const Vec<double, S::n> qref = study::reference_q(sys, q0, v0, T, 1e-12);
      std::vector<bool> implicit(methods.size());
      for (size_t m = 0; m < methods.size(); ++m) implicit[m] = nhi::method_traits(sys, methods[m].spec).implicit;
      // Cells: methods x hs with the method's own start (root check at h >= roots_from
      // for the implicit ones), then methods x root_hs from the continued root.
      const size_t plain = methods.size() * hs.size();
      const auto spec_of = [&](size_t i) {
        nhi::MethodSpec spec = methods[i < plain ? i / hs.size() : (i - plain) / root_hs.size()].spec;
        if (i < plain) {
          spec.root_check = implicit[i / hs.size()] && i % hs.size() >= first_root_h;
        } else {
          spec.start = "continuation";
        }
        return spec;
      };
      const auto h_of = [&](size_t i) { return i < plain ? hs[i % hs.size()] : root_hs[(i - plain) % root_hs.size()]; };
      // A continued run costs about (|h| / continuation_dh + 1) solves a step, a checked one one more.
      const auto solves = [&](size_t i) {
        const nhi::MethodSpec spec = spec_of(i);
        return spec.root_check || spec.start == "continuation" ? 2 + h_of(i) / nhi::SolverOptions{}.continuation_dh
                                                               : 1.0;
      };
      study::Cells cells;
      cells.label = "stability " + name;
      cells.count = plain + methods.size() * root_hs.size();
      cells.run = [&](size_t i) {
        if (i >= plain && !implicit[(i - plain) / root_hs.size()]) return json(nullptr);
        return run_one(sys, spec_of(i), q0, v0, qref, h_of(i), T);
      };
      cells.cost = [&](size_t i) {
        if (i >= plain && !implicit[(i - plain) / root_hs.size()]) return 0.0;
        return T / h_of(i) * study::step_weight(spec_of(i)) * solves(i);
      };
      cells.name = [&](size_t i) {
        return spec_of(i).label() + (i < plain ? "" : " (continued)") + " at h = " + std::to_string(h_of(i));
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
        json entry = {{"label", methods[m].label()},
                      {"runs", rs},
                      {"largest_stable_h", largest > 0 ? json(largest) : json(nullptr)},
                      {"largest_surviving_h", survivor > 0 ? json(survivor) : json(nullptr)},
                      {"first_failure", first_failure}};
        if (implicit[m] && !root_hs.empty()) {
          std::vector<json> predictor(rs.begin() + first_root_h, rs.end()), continued;
          for (size_t j = 0; j < root_hs.size(); ++j) continued.push_back(runs[plain + m * root_hs.size() + j]);
          double followed = 0;
          for (size_t j = 0; j < root_hs.size(); ++j) {
            const json& r = predictor[j]["roots"];
            if (r["other_root_steps"] != 0 || r["no_continued_root_steps"] != 0) break;
            if (!predictor[j]["survived"]) break;  // (a failed run: its last step's root is unknown)
            followed = root_hs[j];
          }
          entry["roots"] = {{"continued_runs", continued},
                            {"largest_stable_h_continued", largest_h(continued, root_hs, "status", "ok")},
                            {"largest_surviving_h_continued", largest_h(continued, root_hs, "survived", true)},
                            {"followed_continued_root_up_to", followed > 0 ? json(followed) : json(nullptr)}};
        }
        ms.push_back(entry);
      }
      return json{{"scene", sc}, {"reference_q", study::to_json<S::n>(qref)}, {"methods", ms}};
    });
  }
  return study::finish(opt, result);
}
