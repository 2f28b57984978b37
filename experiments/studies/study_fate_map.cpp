// The fate-map sweep (make sweep, not part of make reproduce): where each
// method's runs fail, over a fine grid of h, the coupling parameter (epsilon)
// and a family of initial conditions.
//   scenes      every registered scene whose system declares a section family
//               (system.hpp, has_section_states) and the swept parameter: the
//               contact oscillators (reversible and not)
//   parameter   epsilon in {0.1, 0.3, 1, 3} (--values)
//   h           geometric from 0.05 to 5, 20 per decade (--per-decade)
//   methods     every fixed-step "main" method of nhi::study_methods()
//   initial     sys.section_states(N) (N = 100, --states): one energy level,
//               z0 spread over +-0.9 sqrt 2 (as study_poincare with N = 10)
//   T           50 (--T)
// One cell is one run (scene, parameter, method, h, initial state).  Its fate:
//   s  stable: reached T with converged solves and |E - E0| <= |E0| throughout
//   e  energy: |E - E0| passed |E0| (the run is stopped there)
//   f  solve:  a step solve did not converge
//   n  non-finite state or energy
// Per scene, parameter value, method and h the result holds the fates of the
// N runs (a string, one letter per initial state), their counts, and the
// median over the runs of max |E - E0| / |E0|.  Sharded over MPI ranks by
// study::map_cells (cluster.hpp) like every study; stats.busy_seconds per rank.
//   --roots (results/fate_map_roots.json, over h >= 1): the implicit methods
// only, each cell run twice, with the method's own start (checking at every
// step whether the root it takes is the one continued from h -> 0,
// solver.hpp) and from that continued root, so that a limit can be told
// apart from its solver's start.  Per cell also a root letter:
//   c  every step took the continued root
//   o  some step took another root
//   x  some step had no root continued from h -> 0 (the branch folded)
#include <algorithm>
#include <cmath>

#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

struct Grid {
  std::vector<std::string> scenes;
  std::vector<std::vector<json>> scene_at;  // [scene][value]: validated scene with the parameter set
  std::vector<double> values, hs;
  std::vector<nhi::StudyMethod> methods;
  int states = 100;
  double T = 50;
  bool roots = false;
  size_t count() const { return scenes.size() * values.size() * methods.size() * hs.size() * states; }
  // Cell i as (scene, value, method, h, state) indices, the state varying fastest.
  std::array<size_t, 5> split(size_t i) const {
    std::array<size_t, 5> ix{};
    const size_t dims[5] = {scenes.size(), values.size(), methods.size(), hs.size(), size_t(states)};
    for (int d = 4; d >= 0; --d) {
      ix[d] = i % dims[d];
      i /= dims[d];
    }
    return ix;
  }
};

// One run: [fate letter, max |E - E0| / |E0|, steps taken]; *rep_out (may be
// null) gets its report.
json run_fate(const Grid& g, size_t i, const nhi::MethodSpec& spec, nhi::RunReport* rep_out) {
  const auto [s, e, m_, j, k_] = g.split(i);
  const double h = g.hs[j];
  const auto k = k_;  // a lambda may not capture a structured binding (C++17)
  (void)m_;
  return nhi::visit_scene(g.scene_at[s][e], [&](const auto& sys, const auto&, const auto&) -> json {
    using S = std::decay_t<decltype(sys)>;
    if constexpr (nhi::has_section_states<S>::value) {
      const auto st = sys.section_states(g.states)[k];
      const Vec<double, S::n> q0 = st.first, v0 = st.second;
      const double E0 = nhi::energy(sys, q0, v0), scale = std::abs(E0);
      const long steps = std::max(1L, std::lround(g.T / h));
      double max_dE = 0;
      long taken = 0;
      // The threshold |E - E0| > |E0| through the runs' guard (guard.hpp),
      // which also ends a run at a non-finite point, before the observer.
      const nhi::RunReport rep = nhi::run_method(
          sys, spec, q0, v0, h, steps,
          [&](const nhi::Sample<S::n, S::m>& smp) {
            max_dE = std::max(max_dE, std::abs(nhi::energy(sys, smp.q, smp.v) - E0));
            taken = smp.k;
            return true;
          },
          nhi::EnergyLimit::relative_to_E0(nhi::EnergyLimit::Mode::kStop));
      char fate = 's';
      if (rep.failure == nhi::FailureKind::kEnergy) {  // the point past the threshold counts
        fate = 'e';
        max_dE = std::max(max_dE, rep.energy_error_at_limit);
        taken = rep.failure_step;
      } else if (!rep.ok) {
        fate = rep.failure == nhi::FailureKind::kNonFinite ? 'n' : 'f';
      }
      if (rep_out) *rep_out = rep;
      return json::array({std::string(1, fate), max_dE / scale, taken});
    } else {
      throw std::logic_error("scene without a section family in the fate map");
    }
  });
}

// One cell: run_fate with the method's own start; with --roots also the root
// letter (above) and the run from the continued root:
// [fate, rel, taken, root letter, fate, rel, taken].
json run_cell(const Grid& g, size_t i) {
  nhi::MethodSpec spec = g.methods[g.split(i)[2]].spec;
  if (!g.roots) return run_fate(g, i, spec, nullptr);
  spec.root_check = true;
  nhi::RunReport rep;
  json r = run_fate(g, i, spec, &rep);
  r.push_back(rep.no_continued_root_steps > 0 ? "x" : rep.other_root_steps > 0 ? "o" : "c");
  spec.root_check = false;
  spec.start = "continuation";
  for (const json& x : run_fate(g, i, spec, nullptr)) r.push_back(x);
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The command line: the grid (h, parameter values, states, T, --roots) and
// the swept parameter's name.
Grid parse_grid(int argc, char** argv, study::Options* opt, std::string* param) {
  CLI::App app{"Fate map: stability over h x epsilon x methods x initial states (the contact oscillators)"};
  study::add_options(app, *opt);
  Grid g;
  *param = "epsilon";
  g.values = {0.1, 0.3, 1.0, 3.0};
  double h_min = 0.05, h_max = 5.0;
  int per_decade = 20;
  app.add_option("--param", *param, "The swept system parameter");
  app.add_option("--values", g.values, "Its values")->delimiter(',');
  app.add_option("--states", g.states, "Initial states per (scene, value, method, h)")->check(CLI::Range(2, 100000));
  app.add_option("--T", g.T, "Final time of every run")->check(CLI::PositiveNumber);
  app.add_option("--h-min", h_min, "Smallest h")->check(CLI::PositiveNumber);
  app.add_option("--h-max", h_max, "Largest h")->check(CLI::PositiveNumber);
  app.add_option("--per-decade", per_decade, "Grid points of h per decade")->check(CLI::Range(1, 1000));
  app.add_flag("--roots", g.roots, "Implicit methods only: check each step's root and run from the continued root too");
  study::parse(app, argc, argv);
  if (!(h_max > h_min)) {
    std::cerr << "study_fate_map: --h-max must exceed --h-min\n";
    study::Cluster::get().exit_all(2);
  }
  const int points = static_cast<int>(std::floor(per_decade * std::log10(h_max / h_min) + 1e-9));
  for (int i = 0; i <= points; ++i) g.hs.push_back(h_min * std::pow(10.0, double(i) / per_decade));
  return g;
}

// The fixed-step "main" methods; with --roots the implicit ones only
// (implicit or not is a method's trait for every system: asked of the first scene's).
std::vector<nhi::StudyMethod> grid_methods(const study::Options& opt, bool roots) {
  const auto methods =
      study::methods([](const nhi::StudyMethod& m) { return study::fixed_step(m) && m.group == "main"; });
  if (!roots) return methods;
  std::vector<nhi::StudyMethod> implicit;
  for (const auto& m : methods)
    if (nhi::visit_scene(
            nhi::validate_scene(study::scene(opt, study::scene_names(opt).front())),
            [&](const auto& sys, const auto&, const auto&) { return nhi::method_traits(sys, m.spec).implicit; }))
      implicit.push_back(m);
  return implicit;
}

// The scenes with a section family and the parameter, each validated at every value.
void grid_scenes(const study::Options& opt, const std::string& param, Grid* g) {
  try {
    for (const std::string& name : study::scene_names(opt)) {
      const json sc = study::scene(opt, name);
      const bool fits = nhi::visit_scene(sc, [&](const auto& sys, const auto&, const auto&) {
        using S = std::decay_t<decltype(sys)>;
        bool has = false;
        for (const auto& p : S::parameters()) has = has || param == p.name;
        return nhi::has_section_states<S>::value && has;
      });
      if (!fits) continue;
      std::vector<json> at;
      for (const double v : g->values) {
        json s = sc;
        s["params"][param] = v;
        at.push_back(nhi::validate_scene(s));
      }
      g->scenes.push_back(name);
      g->scene_at.push_back(at);
    }
  } catch (const std::exception& e) {
    std::cerr << "study_fate_map: error: " << e.what() << "\n";
    study::Cluster::get().exit_all(2);
  }
  if (g->scenes.empty()) {
    std::cerr << "study_fate_map: no scene has a section family and the parameter \"" << param << "\"\n";
    study::Cluster::get().exit_all(2);
  }
}

// Every run of the grid, one cell each.
study::Cells grid_cells(const Grid& g, const std::string& param) {
  study::Cells cells;
  cells.label = "fate map";
  cells.count = g.count();
  cells.run = [&g](size_t i) { return run_cell(g, i); };
  cells.cost = [&g](size_t i) {
    const auto ix = g.split(i);
    // (--roots: a checked step costs about 2 + h / continuation_dh solves, a continued one one fewer)
    const double solves = g.roots ? 3 + 2 * g.hs[ix[3]] / nhi::SolverOptions{}.continuation_dh : 1.0;
    return g.T / g.hs[ix[3]] * study::step_weight(g.methods[ix[2]].spec) * solves;
  };
  cells.name = [&g, param](size_t i) {
    const auto ix = g.split(i);
    return g.scenes[ix[0]] + " " + param + " = " + std::to_string(g.values[ix[1]]) + ", " + g.methods[ix[2]].label() +
           " at h = " + std::to_string(g.hs[ix[3]]) + ", initial state " + std::to_string(ix[4]);
  };
  return cells;
}

// The fates of one method over the grid of h (one scene and value), from the
// runs in index order starting at runs[*i] (advanced past them).
json method_fates(const Grid& g, size_t m, const std::vector<json>& runs, size_t* i, long* total_steps) {
  json fates = json::array(), stable = json::array(), energy = json::array(), solve = json::array(),
       nonfinite = json::array(), med = json::array();
  json largest_all = nullptr, largest_half = nullptr;
  bool all_broken = false, half_broken = false;
  // --roots: the root letters, the continued runs' fates and their limits.
  json root_letters = json::array(), other_root = json::array(), fates_c = json::array(), stable_c = json::array();
  json largest_all_c = nullptr, largest_half_c = nullptr;
  bool all_broken_c = false, half_broken_c = false;
  for (size_t j = 0; j < g.hs.size(); ++j) {
    std::string f, roots, fc;
    std::vector<double> rel;
    int c[4] = {0, 0, 0, 0}, others = 0, stable_cont = 0;
    for (int k = 0; k < g.states; ++k, ++*i) {
      const json& r = runs[*i];
      const char letter = r[0].get<std::string>()[0];
      f += letter;
      c[letter == 's' ? 0 : letter == 'e' ? 1 : letter == 'f' ? 2 : 3]++;
      if (std::isfinite(r[1].get<double>())) rel.push_back(r[1].get<double>());
      *total_steps += r[2].get<long>();
      if (g.roots) {
        roots += r[3].get<std::string>();
        others += r[3] != "c";
        fc += r[4].get<std::string>();
        stable_cont += r[4] == "s";
        *total_steps += r[6].get<long>();
      }
    }
    if (g.roots) {
      root_letters.push_back(roots);
      other_root.push_back(others);
      fates_c.push_back(fc);
      stable_c.push_back(stable_cont);
      if (stable_cont != g.states) all_broken_c = true;
      if (2 * stable_cont < g.states) half_broken_c = true;
      if (!all_broken_c) largest_all_c = g.hs[j];
      if (!half_broken_c) largest_half_c = g.hs[j];
    }
    fates.push_back(f);
    stable.push_back(c[0]);
    energy.push_back(c[1]);
    solve.push_back(c[2]);
    nonfinite.push_back(c[3]);
    const double md = median(rel);
    med.push_back(std::isfinite(md) ? json(md) : json(nullptr));
    if (c[0] != g.states) all_broken = true;
    if (2 * c[0] < g.states) half_broken = true;
    if (!all_broken) largest_all = g.hs[j];
    if (!half_broken) largest_half = g.hs[j];
  }
  json entry = {{"label", g.methods[m].label()},
                {"fates", fates},
                {"stable", stable},
                {"energy", energy},
                {"solve", solve},
                {"non_finite", nonfinite},
                {"median_max_rel_energy_error", med},
                {"largest_h_all_stable", largest_all},
                {"largest_h_half_stable", largest_half}};
  if (g.roots) {
    entry["roots"] = root_letters;
    entry["other_root"] = other_root;
    entry["fates_continued"] = fates_c;
    entry["stable_continued"] = stable_c;
    entry["largest_h_all_stable_continued"] = largest_all_c;
    entry["largest_h_half_stable_continued"] = largest_half_c;
  }
  return entry;
}

// What the result's numbers mean.
json grid_config(const Grid& g, const std::string& param) {
  return json{{"param", param},
              {"values", g.values},
              {"h", g.hs},
              {"states", g.states},
              {"T", g.T},
              {"initial_states", "sys.section_states(states): one energy level, z0 spread over +-0.9 sqrt 2"},
              {"fates",
               "s: stable (reached T, |E - E0| <= |E0| throughout); e: |E - E0| passed |E0| (stopped there); f: a "
               "step solve did not converge; n: non-finite state or energy"},
              {"largest_h_all_stable", "largest grid h such that at every grid h up to it every run is stable"},
              {"largest_h_half_stable", "the same with at least half the runs stable"},
              {"roots", g.roots},
              {"root_letters",
               "--roots: c every step took the root continued from h -> 0; o some step took another; x some step "
               "had no continued root. fates_continued: the runs whose every step starts from the continued root; "
               "other_root: states whose run with the method's own start left the continued root"}};
}

}  // namespace

int main(int argc, char** argv) {
  study::Options opt;
  std::string param;
  Grid g = parse_grid(argc, argv, &opt, &param);
  grid_scenes(opt, param, &g);
  // The methods studied on every scene of the map (StudyMethod::on).
  for (const nhi::StudyMethod& m : grid_methods(opt, g.roots)) {
    bool on_all = true;
    for (const std::string& name : g.scenes) on_all = on_all && study::studied_on_scene(m, study::scene(opt, name));
    if (on_all) g.methods.push_back(m);
  }
  const std::vector<json> runs = study::map_cells(opt, grid_cells(g, param));

  long total_steps = 0;
  json scenes = json::object();
  size_t i = 0;  // cells in index order: scene, value, method, h, state
  for (size_t s = 0; s < g.scenes.size(); ++s) {
    json by_value = json::array();
    for (size_t e = 0; e < g.values.size(); ++e) {
      json ms = json::array();
      for (size_t m = 0; m < g.methods.size(); ++m) ms.push_back(method_fates(g, m, runs, &i, &total_steps));
      by_value.push_back({{"value", g.values[e]}, {"methods", ms}});
    }
    scenes[g.scenes[s]] = {{"scene", g.scene_at[s][0]}, {"by_value", by_value}};
  }
  json result = {{"study", "fate_map"},
                 {"config", grid_config(g, param)},
                 {"size",
                  {{"runs", g.count()},
                   {"steps", total_steps},
                   {"scenes", g.scenes.size()},
                   {"values", g.values.size()},
                   {"methods", g.methods.size()},
                   {"h", g.hs.size()}}},
                 {"scenes", scenes}};
  return study::finish(opt, result);
}
