// The long-horizon record of a run and its reading, shared by the studies that
// follow runs for 10^5-10^6 steps (study_long_horizon, study_states).
//   HorizonObserver: at ~40 log-spaced checkpoints per decade, the instantaneous
//   energy error and constraint value and their running maxima over every step
//   (and the same for the system's other first integrals), plus block means of
//   E - E0 over blocks of kBlock steps for the drift rate.
//   fate(): the run's fate in words, from the last decade (lib/nhi/readings/fate.hpp).
#pragma once

#include "nhi/readings/fate.hpp"
#include "study.hpp"

namespace study {

using nhi::Vec;

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

// The fate of a run's energy and first integrals, read from the last decade of
// its record (fate.hpp): the reading goes into the run ("tail", and "reading"
// per first integral) and the words are returned.
inline std::string fate(json& run, const nhi::FateLevels& levels) {
  auto series = [&](const json& j) { return j.get<std::vector<double>>(); };
  const std::vector<double> t = series(run["t"]);
  if (run.contains("first_integrals"))
    for (auto& [name, fi] : run["first_integrals"].items()) {
      const nhi::IntegralReading r = nhi::read_integral(t, series(fi["max_abs_error"]), levels);
      fi["reading"] = {{"early", r.early},
                       {"late", r.late},
                       {"last_decade_slope", r.slope},
                       {"drifting", r.drifting},
                       {"words", r.words}};
    }
  const nhi::TailReading r =
      nhi::read_tail(t, series(run["max_energy_error"]), series(run["block_t"]), series(run["block_mean_energy_error"]),
                     run["summary"]["E0"].get<double>(), levels);
  auto num = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
  run["tail"] = {{"max_slope", num(r.max_slope)},
                 {"max_slope_halves", {num(r.max_slope_first_half), num(r.max_slope_second_half)}},
                 {"block_trend", num(r.block_trend)},
                 {"block_rise", num(r.block_rise)},
                 {"block_scatter", num(r.block_scatter)},
                 {"wander_ratio", num(r.wander_ratio)},
                 {"late_mean", num(r.late_mean)},
                 {"max_early", num(r.max_early)},
                 {"t_early", num(r.t_early)},
                 {"max_late", num(r.max_late)},
                 {"relative", num(r.relative)},
                 {"growing", r.growing},
                 {"at_roundoff", r.at_roundoff},
                 {"accelerating", r.accelerating}};
  if (run["status"] != "ok") {
    char buf[160];
    std::snprintf(buf, sizeof buf, "blows up (failed at t = %.1f)", run["failure"]["time"].get<double>());
    return buf;
  }
  return nhi::fate_words(r, levels);
}

inline json levels_json(const nhi::FateLevels& l) {
  return {{"bounded_relative", l.bounded_relative}, {"grows_slope", l.grows_slope},
          {"runaway_relative", l.runaway_relative}, {"trend_scatters", l.trend_scatters},
          {"trend_of_max", l.trend_of_max},         {"wander_ratio", l.wander_ratio},
          {"wander_of_max", l.wander_of_max},       {"accelerate_gap", l.accelerate_gap},
          {"accelerate_slope", l.accelerate_slope}};
}

}  // namespace study
