// The *observer* role: what gets recorded of a run.
//
// Recorder keeps the diagnostics of every s-th time point (0, s, 2s, ... and
// always the last one reached) and, over *every* point, the running maxima
// max_k |E_k - E_0| and max_k max_a |omega(q_k) v_k|_a, so a long run with a
// stride holds O(steps / s) numbers and still reports exact maxima.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "nhi/roles/stepper.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

// The array first_integrals() returns (an empty one for systems without them).
template <class S, bool = has_first_integrals<S>::value>
struct FirstIntegralsOf {
  using type = std::array<double, 0>;
};
template <class S>
struct FirstIntegralsOf<S, true> {
  using type = decltype(std::declval<const S&>().first_integrals(std::declval<Vec<double, S::n>>(),
                                                                 std::declval<Vec<double, S::n>>()));
};
template <class S>
using FirstIntegrals = typename FirstIntegralsOf<S>::type;

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
    if constexpr (has_first_integrals<S>::value) pending_I_ = sys_.first_integrals(s.q, s.v);
    pending_ = s;
    pending_E_ = E;
    pending_c_ = c;
    have_pending_ = true;
    if (s.k % every_ == 0 || s.k == last_) flush();
    return true;
  }

  // Write t, q, v, energy, constraint (first_integrals for systems that have them; p, lambda, discrete_constraint for the DLA) and summary.
  void write(nlohmann::json* out) {
    flush();  // the last point reached, if it was not on the stride
    auto& o = *out;
    o["t"] = t_;
    o["q"] = rows(q_, n);
    o["v"] = rows(v_, n);
    o["energy"] = E_;
    o["constraint"] = rows(c_, m);
    if constexpr (has_first_integrals<S>::value) {
      const auto names = S::first_integral_names();
      for (size_t i = 0; i < names.size(); ++i) {
        std::vector<double> col;
        for (size_t k = i; k < I_.size(); k += names.size()) col.push_back(I_[k]);
        o["first_integrals"][names[i]] = col;
      }
    }
    if (has_p_) {
      o["p"] = rows(p_, n);
      o["lambda"] = rows(lambda_, m);
      o["discrete_constraint"] = rows(wd_, m);
    }
    o["summary"] = {
        {"points", static_cast<long>(t_.size())}, {"max_abs_energy_error", max_dE_}, {"max_abs_constraint", max_c_}};
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
    if constexpr (has_first_integrals<S>::value) I_.insert(I_.end(), pending_I_.begin(), pending_I_.end());
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
  FirstIntegrals<S> pending_I_{};
  std::vector<double> I_;  // the system's first integrals besides the energy, row-major
  std::vector<double> t_, q_, v_, E_, c_, p_, lambda_, wd_;
};

}  // namespace nhi
