// Study 4: speed against accuracy (work-precision) on both scenes.
// (a) error max_i |q_i(T) - q_ref,i(T)| at T = 10 against CPU time;
// (b) max |E - E0| over T = 10^4 (and over its first 100 time units) against CPU time;
// for the "main" fixed-step methods of nhi::study_methods() (DLA alpha = 1/2,
// symmetric alpha = 0, RK4, mp06, the discrete gradient and their compositions)
// and SPARK of orders 4 and 6 over h = 0.4 / 2^j, and for adaptive methods over
// tolerances: CVODE Adams (the reference solution) and the
// explicit embedded Runge-Kutta pairs a C++ user would reach for, Boost.Odeint's
// runge_kutta_fehlberg78 and runge_kutta_dopri5 (controlled, atol = rtol = tol),
// all on the same index-reduced ODE.  CPU time is per-thread time of a run
// without diagnostics, repeated until 50 ms have accumulated, the median of
// three such timings with their range (for fixed-step
// methods, the T = 10^4 cost is the T = 100 cost times 100; for CVODE the
// diagnosed T = 10^4 run itself when it takes >= 0.5 s, its observer (~1e5
// energies, a few ms) then under 1 % of it; over T = 10^6 on the particle a fixed-step cost is
// scaled by steps and an explicit pair's by right-hand sides counted); the
// error comes from a separate identical run with diagnostics.  For the adaptive methods the
// energy error is taken at every accepted step (odeint) or every output point
// (CVODE, output every 0.1).
#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <string>

#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;
namespace odeint = boost::numeric::odeint;

constexpr double kT_final = 10.0;
constexpr double kT_energy = 10000.0;
constexpr double kT_energy_short = 100.0;  // the same run's max |E - E0| over [0, 100]
// Measured (not extrapolated) energy error over T = 10^6 on these scenes, for
// the configurations long_run() selects: fixed steps h >= 0.1 (h = 0.4 only for
// an energy-preserving method, whose steps cost the most and whose energy
// error does not depend on h), and the explicit adaptive pairs at every
// tolerance down to kTightestTolLongDopri5 for dopri5.  About a minute on two
// cores for the particle.
constexpr double kT_long = 1e6;
// dopri5's 10^6-unit runs stop at this tolerance: each tighter one costs
// more CPU time than rkf78's run at the same tolerance and ends with a
// larger energy error, so none is on the particle's 10^6 front, and their
// cells would be a large share of the study's cell time.
constexpr double kTightestTolLongDopri5 = 1e-10;
const std::vector<std::string> kLongScenes = {"particle"};
constexpr double kSelfTimed = 0.5;  // s (see cpu_energy below)
// Fixed steps h = 0.4 / 2^j, j = 0 ... kFinestJ; tolerances 10^-e, e = kLoosestTol
// ... kTightestTolReference (CVODE) or kTightestTolPairs (the explicit pairs).
// Finer h (to j = 9 for second-order methods, j = 6 for order 4 and the
// energy-preserving ones) puts no point on any scene's cost-error front
// (either error measure, any horizon) and changes no row of summarize.sh's
// which-method-when table, while it would take about a third of the study's
// CPU time (a second-order method's run at h = 0.4/2^9 over T = 10^4 is
// 1.3e7 steps).  Order 6 reaches the round-off floor by j = 5.
constexpr int kFinestJ = 5;
// SPARK with 3 and 4 stages ("costly", orders 4 and 6), for its cost at
// orders 4 and 6 against mp06's compositions: h = 0.4 / 2^j to j = 3 and no
// 10^6 run (its step costs 20-560 RK4 steps; the rows follow the others').
constexpr int kFinestJCostly = 3;
constexpr int kCostlyMinStages = 3;
constexpr int kLoosestTol = 3, kTightestTolReference = 12, kTightestTolPairs = 13;
volatile double g_sink = 0;  // keeps timed runs from being optimized away

// "1e-3 ... 1e-12": the tolerances 10^-e, e = kLoosestTol ... tightest.
std::string tol_range(int tightest) {
  return "1e-" + std::to_string(kLoosestTol) + " ... 1e-" + std::to_string(tightest);
}

template <class S>
using State = nhi::OdeState<S>;

// Adaptive Boost.Odeint run on (q, v) with the library's right-hand side
// (embedded_rk.hpp); obs(t, q, v) at every accepted step.
template <class S, class Stepper, class Obs>
long odeint_run(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double T, double tol,
                Obs&& obs) {
  constexpr int n = S::n;
  State<S> x;
  for (int i = 0; i < n; ++i) {
    x[i] = q0[i];
    x[n + i] = v0[i];
  }
  long rhs = 0;
  const nhi::OdeRhs<S> f{&sys, &rhs};
  auto o = [&](const State<S>& y, double t) {
    obs(t, Vec<double, n>(Eigen::Map<const Vec<double, n>>(y.data())),
        Vec<double, n>(Eigen::Map<const Vec<double, n>>(y.data() + n)));
  };
  odeint::integrate_adaptive(odeint::make_controlled<Stepper>(tol, tol), f, x, 0.0, T,
                             nhi::EmbeddedRkOptions{}.first_step, o);
  return rhs;
}

struct Config {
  nhi::StudyMethod method;
  double param;  // h (fixed-step methods) or tolerance (adaptive ones)
};

// Is this configuration also run to kT_long (see there)?
template <class S>
bool long_run(const S& sys, const Config& c) {
  if (c.method.external)
    return c.method.spec.kind != nhi::Dopri5Method::name || c.param >= kTightestTolLongDopri5 * (1 - 1e-9);
  if (c.method.adaptive()) return false;  // the reference (CVODE): many times rkf78's cost per step here
  if (c.method.group == "costly") return false;
  const nhi::MethodTraits t = nhi::method_traits(sys, c.method.spec);
  return t.preserves_energy ? c.param >= 0.4 * (1 - 1e-12) : c.param >= 0.1 * (1 - 1e-12);
}

// The energy limit of every run here (the runs' guard, guard.hpp): a run whose
// |E - E0| passes max(|E0|, 1) is stopped there and failed (it can meet none
// of the targets, <= 1e-2): on a non-conservative method the energy can then
// grow without bound and the adaptive step shrink with it (dopri5 at tol 1e-3
// on contact_oscillator: E = 1e19 by t = 5500 after 3e7 steps), so the run
// would not end.
const nhi::EnergyLimit kLimit = nhi::EnergyLimit::runner_default();

// The library methods run through run_method: the adaptive ones at
// tolerance param, the reference solution output every 0.1, an adaptive pair
// over one output interval T.
template <class S, class Sampler>
bool run_library(const S& sys, const Config& c, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double T,
                 Sampler&& sample, bool guard) {
  const nhi::StudyMethod& m = c.method;
  const nhi::EnergyLimit limit = guard ? kLimit : nhi::EnergyLimit::off();
  if (m.adaptive()) {
    nhi::MethodSpec spec = m.spec;
    spec.tolerance = c.param;
    const double out = m.external ? T : 0.1;
    return nhi::run_method(sys, spec, q0, v0, out, std::lround(T / out), sample, limit).ok;
  }
  return nhi::run_method(sys, m.spec, q0, v0, c.param, std::lround(T / c.param), sample, limit).ok;
}

// Run method `c` to T; obs(t, q, v) sees the trajectory (every step, or every
// accepted/output step for adaptive methods).  Returns false on failure; with
// `guard` also when the energy passes kLimit (the timed runs have no guard and
// run only configurations whose guarded run succeeded).  An adaptive pair runs
// through Boost.Odeint's loop here, observed at every accepted step (the
// energy runs), or with `whole` as the library method over one output
// interval T (the final-error run: `nhi run` with h = T, steps = 1, gives the
// same q(T)).  With `rhs`, an external pair's run counts its right-hand-side
// evaluations there (rejected steps included).
template <class S, class Obs>
bool run(const S& sys, const Config& c, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double T, Obs&& obs,
         bool guard = false, long* rhs = nullptr, bool whole = false) {
  auto sample = [&](const nhi::Sample<S::n, S::m>& s) {
    obs(s.t, s.q, s.v);
    return true;
  };
  const nhi::StudyMethod& m = c.method;
  if (m.external && !whole) {
    struct Runaway {};
    const double E0 = nhi::energy(sys, q0, v0);
    auto checked = [&](double t, const Vec<double, S::n>& q, const Vec<double, S::n>& v) {
      if (guard && kLimit.exceeded(std::abs(nhi::energy(sys, q, v) - E0), E0)) throw Runaway{};
      obs(t, q, v);
    };
    try {
      long f = 0;
      nhi::with_method_type(m.spec.kind, [&](auto tag) {
        using M = typename decltype(tag)::type;
        if constexpr (nhi::is_embedded_rk<M>::value)
          f = odeint_run<S, typename M::Pair::template stepper<State<S>>>(sys, q0, v0, T, c.param, checked);
      });
      if (rhs) *rhs = f;
      return true;
    } catch (const Runaway&) {
      return false;
    }
  }
  return run_library(sys, c, q0, v0, T, sample, guard);
}

// A CPU time: the median of kRepetitions timings and their range (the
// decision tables call two methods a tie where their ranges overlap).
constexpr int kRepetitions = 3;
struct Timing {
  double median = 0, lo = 0, hi = 0;
  Timing scaled(double f) const { return {median * f, lo * f, hi * f}; }
};
Timing timing_of(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return {t[t.size() / 2], t.front(), t.back()};
}
void put(json* row, const std::string& key, const Timing& t) {
  (*row)[key] = t.median;
  (*row)[key + "_range"] = {t.lo, t.hi};
}

// One timing: CPU seconds per run of a run without diagnostics, averaged over
// repeats totalling >= 50 ms.
template <class S>
double cpu_once(const S& sys, const Config& c, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double T) {
  long reps = 0;
  const double t0 = study::thread_cpu_seconds();
  double t = t0;
  do {
    Vec<double, S::n> sink = Vec<double, S::n>::Zero();
    run(sys, c, q0, v0, T, [&](double, const Vec<double, S::n>& q, const Vec<double, S::n>&) { sink = q; });
    g_sink = sink[0];
    ++reps;
    t = study::thread_cpu_seconds();
  } while (t - t0 < 0.05 && reps < 1000);
  return (t - t0) / reps;
}

// kRepetitions timings, the first one `first` when given (a run already timed).
template <class S>
Timing cpu_per_run(const S& sys, const Config& c, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0, double T,
                   double first = -1) {
  std::vector<double> t;
  if (first >= 0) t.push_back(first);
  while (int(t.size()) < kRepetitions) t.push_back(cpu_once(sys, c, q0, v0, T));
  return timing_of(t);
}

// The configurations of every scene: the fixed-step "main" methods over h,
// the reference solution and the external adaptive pairs over tolerances,
// the costliest SPARK over its own h range.
std::vector<Config> all_configs() {
  // Fixed-step "main" methods over h; the reference solution and the external
  // adaptive pairs over tolerances.
  const auto fixed =
      study::methods([](const nhi::StudyMethod& m) { return study::fixed_step(m) && m.group == "main"; });
  const auto reference = study::methods([](const nhi::StudyMethod& m) { return m.adaptive() && !m.external; });
  const auto external = study::methods([](const nhi::StudyMethod& m) { return m.external; });
  const auto costly = study::methods([](const nhi::StudyMethod& m) {
    return study::fixed_step(m) && m.group == "costly" && m.spec.stages >= kCostlyMinStages;
  });
  // Every fixed-step method over the same h (see kFinestJ).
  std::vector<Config> configs;
  for (int j = 0; j <= kFinestJ; ++j)
    for (const auto& m : fixed) configs.push_back({m, 0.4 / (1 << j)});
  for (int e = kLoosestTol; e <= kTightestTolReference; ++e)
    for (const auto& m : reference) configs.push_back({m, std::pow(10.0, -e)});
  for (int e = kLoosestTol; e <= kTightestTolPairs; ++e)
    for (const auto& m : external) configs.push_back({m, std::pow(10.0, -e)});
  for (int j = 0; j <= kFinestJCostly; ++j)
    for (const auto& m : costly) configs.push_back({m, 0.4 / (1 << j)});
  return configs;
}

// What the result's numbers mean.
json study_config() {
  return json{{"T_final_error", kT_final},
              {"T_energy", kT_energy},
              {"T_energy_short", kT_energy_short},
              {"reference", "CVODE Adams rtol = atol = 1e-13 at T_final_error"},
              {"h_fixed", "0.4 / 2^j, j = 0 ... " + std::to_string(kFinestJ) + " (fixed-step methods), j = 0 ... " +
                              std::to_string(kFinestJCostly) +
                              " (SPARK, stages >= " + std::to_string(kCostlyMinStages) + ", no T_long run)"},
              {"tolerances", tol_range(kTightestTolReference) + " (the reference solution), " +
                                 tol_range(kTightestTolPairs) + " (the explicit pairs)"},
              {"cpu",
               "per-thread CPU seconds of a run without diagnostics, averaged over repeats totalling >= 50 ms, "
               "the median of 3 such timings (each cpu_* has its range [min, max] of the 3 in cpu_*_range); "
               "for fixed-step methods cpu_energy is cpu_energy_short times T_energy / T_energy_short (the same "
               "steps, 100 times as many); for the reference solution (CVODE, output every 0.1) the diagnosed run "
               "itself is the first of the 3 timings of cpu_energy when it took >= 0.5 s"},
              {"energy_error",
               "max |E - E0| over [0, T_energy], at every step (fixed-step), accepted step (odeint) or output "
               "point every 0.1 (CVODE)"},
              {"energy_error_short", "the same over [0, T_energy_short]"},
              {"T_long", kT_long},
              {"long_scenes", kLongScenes},
              {"energy_error_long",
               "max |E - E0| over [0, T_long] (a separate run), on long_scenes only, for fixed steps h >= 0.1 (h "
               "= 0.4 for energy-preserving methods) and the explicit adaptive pairs at every tolerance (dopri5 "
               "down to 1e-10); cpu_energy_long is cpu_energy scaled by the ratio of steps (fixed-step) or of "
               "right-hand-side evaluations counted in the two runs (the adaptive pairs); status_long = failed "
               "(and no max_energy_error_long) when that run failed"},
              {"failed",
               "a run is stopped and failed (status = failed, not timed) at a step failure or where |E - E0| "
               "passes max(|E0|, 1): no target is met then, and a non-conservative method's energy, and with it "
               "an adaptive method's step count, can grow without bound"}};
}

// A finished run's timings (cpu_final, cpu_energy_short, cpu_energy, and
// on the long scenes the T_long run's error and cost) into row.
template <class S>
void add_timings(const S& sys, const Config& c, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                 double cpu_diagnosed, long rhs_energy, bool long_scene, json* out) {
  constexpr int n = S::n;
  json& row = *out;
  const double E0 = nhi::energy(sys, q0, v0);
  long rhs_long = 0;
  put(out, "cpu_final", cpu_per_run(sys, c, q0, v0, kT_final));
  const Timing cpu_short = cpu_per_run(sys, c, q0, v0, kT_energy_short);
  put(out, "cpu_energy_short", cpu_short);
  // A fixed-step run costs its number of steps times the cost of a step,
  // so its T_energy cost is the T_energy_short cost scaled by the ratio of
  // steps (measured, repeated to >= 50 ms); an adaptive run is timed whole.
  // The reference solution's diagnosed run is its first timing when it
  // took >= kSelfTimed: its observer sees one point per 0.1 time units
  // (~1e5 energies, a few ms: under 1 % of such a run).
  const bool self_timed = c.method.adaptive() && !c.method.external && cpu_diagnosed >= kSelfTimed;
  const Timing cpu_energy = row["adaptive"].get<bool>()
                                ? cpu_per_run(sys, c, q0, v0, kT_energy, self_timed ? cpu_diagnosed : -1)
                                : cpu_short.scaled(kT_energy / kT_energy_short);
  put(out, "cpu_energy", cpu_energy);
  if (long_scene && long_run(sys, c)) {
    double maxE_long = 0;
    const bool ok3 = run(
        sys, c, q0, v0, kT_long,
        [&](double, const Vec<double, n>& q, const Vec<double, n>& v) {
          maxE_long = std::max(maxE_long, std::abs(nhi::energy(sys, q, v) - E0));
        },
        true, &rhs_long);
    if (ok3) {
      // Scaled, not timed again: a fixed-step run by its steps, an
      // external pair (the only adaptive methods run to T_long) by its
      // right-hand-side evaluations, counted in the two runs; a timed
      // rerun of the pairs to 10^6 would double the particle's cost.
      put(out, "cpu_energy_long",
          c.method.external ? cpu_energy.scaled(double(rhs_long) / double(rhs_energy))
                            : cpu_short.scaled(kT_long / kT_energy_short));
      row["max_energy_error_long"] = maxE_long;
    } else {  // not ranked at T_long (summarize.sh needs max_energy_error_long)
      row["status_long"] = "failed";
      row["max_energy_error_long_before_failure"] = maxE_long;
    }
  }
}

// One configuration's row: its errors (final, energy over the horizons, at
// the limit), then its timings where it ran to the end.
template <class S>
json run_row(const S& sys, const Config& c, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
             const Vec<double, S::n>& qref, bool long_scene) {
  constexpr int n = S::n;
  const double E0 = nhi::energy(sys, q0, v0);
  const bool adaptive = c.method.adaptive();
  char param[32];
  std::snprintf(param, sizeof param, "%g", c.param);
  json row = {{"label", c.method.label()},
              {"keys", c.method.spec.scene_keys() + (adaptive ? " tolerance=" : " h=") + param},
              {"adaptive", adaptive},
              {"param", c.param}};
  Vec<double, n> qT = q0;
  const bool ok1 = run(
      sys, c, q0, v0, kT_final, [&](double, const Vec<double, n>& q, const Vec<double, n>&) { qT = q; }, true, nullptr,
      true);
  double maxE = 0, maxE_short = 0, t_end = 0;
  Vec<double, n> q_end = q0, v_end = v0;
  long rhs_energy = 0;  // right-hand sides of an external pair's runs
  const double cpu0 = study::thread_cpu_seconds();
  const bool ok2 = run(
      sys, c, q0, v0, kT_energy,
      [&](double t, const Vec<double, n>& q, const Vec<double, n>& v) {
        maxE = std::max(maxE, std::abs(nhi::energy(sys, q, v) - E0));
        if (t <= kT_energy_short * (1 + 1e-12)) maxE_short = maxE;
        t_end = t;
        q_end = q;
        v_end = v;
      },
      true, &rhs_energy);
  const double cpu_diagnosed = study::thread_cpu_seconds() - cpu0;
  row["status"] = ok1 && ok2 ? "ok" : "failed";
  row["final_error"] = (qT - qref).cwiseAbs().maxCoeff();
  row["max_energy_error"] = maxE;
  row["max_energy_error_short"] = maxE_short;
  if (ok1 && ok2) study::add_limit_errors(sys, q0, v0, t_end, q_end, v_end, &row);
  if (!(ok1 && ok2)) {  // not timed: it is never ranked (and might not end unguarded)
    row["failure"] = "stopped at t = " + std::to_string(t_end) +
                     ": step failure, or |E - E0| above max(|E0|, 1) (the energy ran away)";
    return row;
  }
  add_timings(sys, c, q0, v0, cpu_diagnosed, rhs_energy, long_scene, &row);
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const study::Options opt = study::parse(argc, argv, "Work-precision: CPU time against accuracy, every scene");
  const std::vector<Config> all = all_configs();
  json result = {{"study", "work_precision"}, {"config", study_config()}};
  for (const std::string& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    result["scenes"][name] = nhi::visit_scene(sc, [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      std::vector<Config> configs;  // the configurations of the methods studied on this scene
      for (const Config& c : all)
        if (c.method.template on<S>()) configs.push_back(c);
      const auto qref = study::reference_q(sys, q0, v0, kT_final, 1e-13);
      const bool long_scene = std::find(kLongScenes.begin(), kLongScenes.end(), name) != kLongScenes.end();
      study::Cells cells;
      cells.label = "work-precision " + name;
      cells.count = configs.size();
      // Per-thread CPU time is what is measured, so --threads 2 on two cores is
      // fair; under MPI only one rank per node runs cells (timed).
      cells.timed = true;
      cells.name = [&](size_t i) { return configs[i].method.label() + " at " + std::to_string(configs[i].param); };
      // Steps times step_weight for a fixed step; an adaptive run's steps per
      // unit time grow like tol^(-1/5) (about 10 at tol = 1e-5).
      cells.cost = [&](size_t i) {
        const Config& c = configs[i];
        const double T = kT_final + kT_energy + (long_scene && long_run(sys, c) ? kT_long : 0.0);
        return c.method.adaptive() ? T * std::pow(c.param, -0.2) : T / c.param * study::step_weight(c.method.spec);
      };
      cells.run = [&](size_t i) { return run_row(sys, configs[i], q0, v0, qref, long_scene); };
      return json{{"scene", sc}, {"runs", study::map_cells(opt, cells)}};
    });
  }
  return study::finish(opt, result);
}
