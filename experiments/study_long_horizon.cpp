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
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr long kSteps = 1000000;
constexpr long kReferenceSteps = 100000;  // the default of --reference-steps
constexpr long kBlock = 1000;

template <class S>
class HorizonObserver {
 public:
  HorizonObserver(const S& sys, long steps, double h) : sys_(sys), h_(h) {
    for (double x = 0; x <= std::log10(double(steps)) + 1e-9; x += 1.0 / 40) {
      const long k = std::lround(std::pow(10.0, x));
      if (checkpoints_.empty() || k > checkpoints_.back()) checkpoints_.push_back(k);
    }
    if (checkpoints_.back() != steps) checkpoints_.push_back(steps);
  }
  bool operator()(const nhi::Sample<S::n, S::m>& s) {
    const double E = nhi::energy(sys_, s.q, s.v);
    if (s.k == 0) E0_ = E;
    const double dE = E - E0_;
    const double c = nhi::constraint_values(sys_, s.q, s.v).cwiseAbs().maxCoeff();
    if (!std::isfinite(dE) || !std::isfinite(c)) return false;  // a non-finite state ends the run
    if constexpr (nhi::has_first_integrals<S>::value) {
      const auto I = sys_.first_integrals(s.q, s.v);
      if (s.k == 0) I0_.assign(I.begin(), I.end()), max_dI_.assign(I.size(), 0.0);
      for (size_t i = 0; i < I.size(); ++i) max_dI_[i] = std::max(max_dI_[i], std::abs(I[i] - I0_[i]));
      last_I_.assign(I.begin(), I.end());
    }
    max_dE_ = std::max(max_dE_, std::abs(dE));
    max_c_ = std::max(max_c_, c);
    block_sum_ += dE;
    if (++block_n_ == kBlock) {
      block_t_.push_back((s.k - (kBlock - 1) / 2.0) * h_);
      block_mean_.push_back(block_sum_ / kBlock);
      block_sum_ = 0;
      block_n_ = 0;
    }
    if (next_ < checkpoints_.size() && s.k == checkpoints_[next_]) {
      t_.push_back(s.t);
      dE_.push_back(dE);
      env_dE_.push_back(max_dE_);
      c_.push_back(c);
      env_c_.push_back(max_c_);
      for (size_t i = 0; i < max_dI_.size(); ++i) env_dI_.resize(max_dI_.size()), env_dI_[i].push_back(max_dI_[i]);
      ++next_;
    }
    last_t_ = s.t;
    return true;
  }
  json to_json() const {
    // Drift rate: least-squares slope of the block means of E - E0 against t.
    double rate = std::nan(""), slope = std::nan("");
    if (block_t_.size() > 2) {
      double st = 0, sy = 0, stt = 0, sty = 0, n = double(block_t_.size());
      for (size_t i = 0; i < block_t_.size(); ++i) {
        st += block_t_[i];
        sy += block_mean_[i];
        stt += block_t_[i] * block_t_[i];
        sty += block_t_[i] * block_mean_[i];
      }
      rate = (n * sty - st * sy) / (n * stt - st * st);
    }
    // Growth exponent of the running max of |E - E0| over the last three decades of t.
    std::vector<double> x, y;
    for (size_t i = 0; i < t_.size(); ++i)
      if (t_[i] >= last_t_ / 1000 && env_dE_[i] > 0) {
        x.push_back(t_[i]);
        y.push_back(env_dE_[i]);
      }
    if (x.size() > 2) slope = nhi::loglog_slope(x, y);
    // Mean of E - E0 over the last 10 % of the blocks; time at which the running
    // max of |E - E0| first reached 90 % of its final value.
    double late = 0;
    const size_t from = block_mean_.size() - block_mean_.size() / 10;
    for (size_t i = from; i < block_mean_.size(); ++i) late += block_mean_[i];
    late = block_mean_.size() > from ? late / double(block_mean_.size() - from) : std::nan("");
    double t90 = std::nan("");
    for (size_t i = 0; i < t_.size(); ++i)
      if (env_dE_[i] >= 0.9 * max_dE_) {
        t90 = t_[i];
        break;
      }
    json j = {{"t", t_},
              {"energy_error", dE_},
              {"max_energy_error", env_dE_},
              {"constraint", c_},
              {"max_constraint", env_c_},
              {"block_t", block_t_},
              {"block_mean_energy_error", block_mean_},
              {"summary",
               {{"max_abs_energy_error", max_dE_},
                {"max_abs_constraint", max_c_},
                {"drift_rate", std::isfinite(rate) ? json(rate) : json(nullptr)},
                {"envelope_growth_exponent", std::isfinite(slope) ? json(slope) : json(nullptr)},
                {"late_mean_energy_error", std::isfinite(late) ? json(late) : json(nullptr)},
                {"t90", std::isfinite(t90) ? json(t90) : json(nullptr)},
                {"E0", E0_},
                {"last_t", last_t_}}}};
    if constexpr (nhi::has_first_integrals<S>::value) {
      const auto names = S::first_integral_names();
      for (size_t i = 0; i < names.size() && i < max_dI_.size(); ++i) {
        j["first_integrals"][names[i]] = {{"max_abs_error", env_dI_.size() > i ? json(env_dI_[i]) : json::array()},
                                          {"initial", I0_[i]},
                                          {"final_error", last_I_[i] - I0_[i]}};
        j["summary"]["max_abs_" + std::string(names[i]) + "_error"] = max_dI_[i];
      }
    }
    return j;
  }

 private:
  S sys_;
  double h_;
  std::vector<double> I0_, max_dI_, last_I_;
  std::vector<std::vector<double>> env_dI_;
  std::vector<long> checkpoints_;
  size_t next_ = 0;
  double E0_ = 0, max_dE_ = 0, max_c_ = 0, block_sum_ = 0, last_t_ = 0;
  long block_n_ = 0;
  std::vector<double> t_, dE_, env_dE_, c_, env_c_, block_t_, block_mean_;
};

// What happened to the energy, in words (the rule is in the result's config).
std::string fate(const json& run) {
  char buf[160];
  if (run["status"] != "ok") {
    std::snprintf(buf, sizeof buf, "blows up (failed at t = %.1f)", run["failure"]["time"].get<double>());
    return buf;
  }
  const json& s = run["summary"];
  const double late = s["late_mean_energy_error"].is_null() ? 0.0 : s["late_mean_energy_error"].get<double>();
  const double E0 = std::abs(s["E0"].get<double>());
  const double g = s["envelope_growth_exponent"].is_null() ? 0.0 : s["envelope_growth_exponent"].get<double>();
  if (std::abs(late) > 0.5 * E0) {
    std::snprintf(buf, sizeof buf, "%s (E - E0 = %.3g by t = %.0f)", late < 0 ? "dissipates" : "grows", late,
                  s["t90"].get<double>());
    return buf;
  }
  if (g >= 0.1) {
    std::snprintf(buf, sizeof buf, "drifts (max |E - E0| ~ t^%.2f)", g);
    return buf;
  }
  return "bounded";
}

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
  const std::vector<nhi::StudyMethod> methods = study::methods([](const nhi::StudyMethod& m) { return !m.external; });
  json result = {{"study", "long_horizon"},
                 {"config",
                  {{"h", "per scene: the scene file's h"},
                   {"steps", kSteps},
                   {"reference_steps", reference_steps},
                   {"block", kBlock},
                   {"drift_rate", "least-squares slope of block means of E - E0 against t"},
                   {"envelope_growth_exponent", "log-log slope of max_{s<=t} |E - E0| over t in [T/1000, T]"},
                   {"fate",
                    "blows up if a step solve failed or the state became non-finite; dissipates/grows if |mean of E - "
                    "E0 over the last 10% of blocks| > |E0|/2 (t: when max |E - E0| reached 90% of its final value); "
                    "drifts if the envelope growth exponent >= 0.1; else bounded"}}}};
  const std::vector<std::string> scenes = study::scene_names(opt);
  std::vector<json> scene_json;
  for (const auto& name : scenes) scene_json.push_back(study::scene(opt, name));
  study::Cells cells;
  cells.label = "long horizon";
  cells.count = scenes.size() * methods.size();
  // Steps of method m: reference_steps for the reference solution, else kSteps.
  auto steps_of = [&](const nhi::StudyMethod& m) { return m.spec.kind == "benchmark" ? reference_steps : kSteps; };
  // The longest runs first (map_cells orders them by this estimate).
  cells.cost = [&](size_t i) {
    const nhi::StudyMethod& m = methods[i % methods.size()];
    return steps_of(m) * study::step_weight(m.spec);
  };
  cells.name = [&](size_t i) { return scenes[i / methods.size()] + " " + methods[i % methods.size()].label(); };
  cells.run = [&](size_t i) {
    const nhi::StudyMethod& m = methods[i % methods.size()];
    return nhi::visit_scene(scene_json[i / methods.size()], [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      const double h = scene_json[i / methods.size()]["h"].get<double>();
      const long steps = steps_of(m);
      HorizonObserver<S> obs(sys, steps, h);
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
      j["fate"] = fate(j);
      return j;
    });
  };
  const std::vector<json> runs = study::map_cells(opt, cells);
  for (size_t s = 0; s < scenes.size(); ++s) {
    json ms = json::array();
    for (size_t k = 0; k < methods.size(); ++k) ms.push_back(runs[s * methods.size() + k]);
    result["scenes"][scenes[s]] = {{"scene", scene_json[s]},
                                   {"h", scene_json[s]["h"]},
                                   {"T", scene_json[s]["h"].get<double>() * kSteps},
                                   {"methods", ms}};
  }
  return study::finish(opt, result);
}
