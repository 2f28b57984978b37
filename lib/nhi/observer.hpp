// The *observer* role: what gets recorded of a run.
//
// Recorder keeps the diagnostics of every s-th time point (0, s, 2s, ... and
// always the last one reached) and, over *every* point, the running maxima
// max_k |E_k - E_0| and max_k max_a |omega(q_k) v_k|_a, so a long run with a
// stride holds O(steps / s) numbers and still reports exact maxima.
#pragma once

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "nhi/integrate.hpp"

namespace nhi {

template <class S>
class Recorder {
 public:
  static constexpr int n = S::n, m = S::m;

  Recorder(const S& sys, long every, long last) : sys_(sys), every_(every), last_(last) {}

  bool operator()(const Sample<n, m>& s) {
    const double E = energy(sys_, s.q, s.v);
    const Vec<double, m> c = constraint_values(sys_, s.q, s.v);
    if (s.k == 0) E0_ = E;
    // NaN-propagating maxima: a non-finite diagnostic must show in the summary.
    const double dE = std::abs(E - E0_);
    max_dE_ = (std::isnan(dE) || dE > max_dE_) ? dE : max_dE_;
    for (int a = 0; a < m; ++a) {
      const double ca = std::abs(c[a]);
      max_c_ = (std::isnan(ca) || ca > max_c_) ? ca : max_c_;
    }
    pending_ = s;
    pending_E_ = E;
    pending_c_ = c;
    have_pending_ = true;
    if (s.k % every_ == 0 || s.k == last_) flush();
    return true;
  }

  // Write t, q, v, energy, constraint (and p, lambda, discrete_constraint for the DLA) and summary.
  void write(nlohmann::json* out) {
    flush();  // the last point reached, if it was not on the stride
    auto& o = *out;
    o["t"] = t_;
    o["q"] = rows(q_, n);
    o["v"] = rows(v_, n);
    o["energy"] = E_;
    o["constraint"] = rows(c_, m);
    if (has_p_) {
      o["p"] = rows(p_, n);
      o["lambda"] = rows(lambda_, m);
      o["discrete_constraint"] = rows(wd_, m);
    }
    o["summary"] = {{"points", static_cast<long>(t_.size())},
                    {"max_abs_energy_error", max_dE_},
                    {"max_abs_constraint", max_c_}};
  }

 private:
  void flush() {
    if (!have_pending_) return;
    have_pending_ = false;
    const auto& s = pending_;
    t_.push_back(s.t);
    q_.insert(q_.end(), s.q.data(), s.q.data() + n);
    v_.insert(v_.end(), s.v.data(), s.v.data() + n);
    E_.push_back(pending_E_);
    c_.insert(c_.end(), pending_c_.data(), pending_c_.data() + m);
    if (s.has_p) {
      has_p_ = true;
      p_.insert(p_.end(), s.p.data(), s.p.data() + n);
      lambda_.insert(lambda_.end(), s.lambda.data(), s.lambda.data() + m);
      wd_.insert(wd_.end(), s.discrete_constraint.data(), s.discrete_constraint.data() + m);
    }
  }
  static nlohmann::json rows(const std::vector<double>& flat, int width) {
    nlohmann::json a = nlohmann::json::array();
    for (size_t i = 0; i + width <= flat.size(); i += width)
      a.push_back(std::vector<double>(flat.begin() + i, flat.begin() + i + width));
    return a;
  }

  S sys_;
  long every_, last_;
  double E0_ = 0, max_dE_ = 0, max_c_ = 0;
  Sample<n, m> pending_;
  double pending_E_ = 0;
  Vec<double, m> pending_c_;
  bool have_pending_ = false, has_p_ = false;
  std::vector<double> t_, q_, v_, E_, c_, p_, lambda_, wd_;
};

}  // namespace nhi
