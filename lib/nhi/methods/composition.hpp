// Composition: from a symmetric (self-adjoint) one-step method Phi of order 2,
// the method Phi_{gamma_s h} o ... o Phi_{gamma_1 h} of order 4 or 6 (Hairer,
// Lubich & Wanner, Geometric Numerical Integration, 2nd ed., section II.4 and
// V.3).  With symmetric coefficients (gamma_i = gamma_{s+1-i}) the composition
// is again symmetric.  Some gamma_i are negative: the inner method must accept
// negative steps.  One recorded point per full step h.
//
//   triple_jump  order 4, 3 stages: gamma_1 = gamma_3 = 1/(2 - 2^(1/3)),
//                gamma_2 = 1 - 2 gamma_1 (Yoshida 1990; HLW section II.4).
//   suzuki5      order 4, 5 stages: gamma_1 = gamma_2 = gamma_4 = gamma_5 = 1/(4 - 4^(1/3)),
//                gamma_3 = 1 - 4 gamma_1 (Suzuki 1990; HLW section II.4).
//   order6       order 6, 9 stages: Kahan & Li's s9odr6a (Math. Comp. 66, 1997;
//                HLW section V.3.2), symmetric, coefficients to 20 digits as published.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nhi/roles/stepper.hpp"

namespace nhi {

struct Composition {
  std::string name;
  int order = 2;
  std::vector<double> gamma;  // stage step fractions, summing to 1
};

inline const std::vector<Composition>& compositions() {
  static const std::vector<Composition> list = [] {
    // 2^(1/3) and 4^(1/3) correctly rounded, as literals: glibc's cbrt(2.0)
    // is one ulp above, and a compiler folds std::cbrt(2.0) at compile time
    // or not, so the coefficients (and every composed run) would depend on
    // the compiler and its options.
    constexpr double cbrt2 = 1.2599210498948731647672106, cbrt4 = 1.5874010519681994747517056;
    const double tj = 1.0 / (2.0 - cbrt2);
    const double sz = 1.0 / (4.0 - cbrt4);
    const std::array<double, 5> kl = {0.39216144400731413928, 0.33259913678935943860, -0.70624617255763935981,
                                      0.082213596293550800230, 0.79854399093482996340};
    return std::vector<Composition>{
        {"none", 2, {1.0}},
        {"triple_jump", 4, {tj, 1.0 - 2.0 * tj, tj}},
        {"suzuki5", 4, {sz, sz, 1.0 - 4.0 * sz, sz, sz}},
        {"order6", 6, {kl[0], kl[1], kl[2], kl[3], kl[4], kl[3], kl[2], kl[1], kl[0]}},
    };
  }();
  return list;
}

inline std::vector<std::string> composition_names() {
  std::vector<std::string> names;
  for (const auto& c : compositions()) names.push_back(c.name);
  return names;
}

// The composition of that name; an unknown name is an error.
inline const Composition& composition(const std::string& name) {
  for (const auto& c : compositions())
    if (c.name == name) return c;
  throw std::invalid_argument("unknown composition \"" + name + "\"");
}

// The one stage loop's bookkeeping, for Composed and ComposedDla
// (dla_composition.hpp): stage i's summary s into the step's total; a failed
// stage fails the step, its message naming the stage.  Returns s.ok().
inline bool add_stage(const Composition& c, size_t i, const StepSummary& s, StepSummary* total) {
  total->add_stage(s);
  if (s.ok()) return true;
  total->status = SolveStatus::kFailed;
  total->failure = s.failure;
  total->message = c.name + " stage " + std::to_string(i + 1) + " of " + std::to_string(c.gamma.size()) + ": " + s.message;
  return false;
}

// Does the inner stepper start each step from its multiplier alone
// (Inner::starts_from_multiplier, with lambda() and guess_lambda())?
template <class Inner, class = void>
struct starts_from_multiplier : std::false_type {};
template <class Inner>
struct starts_from_multiplier<Inner, std::void_t<decltype(Inner::starts_from_multiplier)>>
    : std::bool_constant<Inner::starts_from_multiplier> {};

// The composed stepper (stepper.hpp): each step(h) is the inner steps gamma_i h.
//   Stage memory: where the inner step starts from its multiplier alone
// (mp06 on a separable system, solved by Newton where it is not explicit:
// the sleigh), stage i starts from its own multiplier of the last composed
// step (one of the same sign of h), not from that of stage i - 1, which
// acts over a step of another size and, for a backward stage, in the other
// direction.  Once the sleigh runs straight its multiplier is round-off
// (~1e-15), and each stage's own round-off value is a fixed point of that
// stage, which its own memory hits exactly, while the previous stage's
// differs by a few ulps of the residual's terms.  With the solver's rounding
// terms (solver.hpp, mp06.hpp) stages started from the previous stage's
// multiplier lock in too; the memory still saves residual evaluations on
// the triple jump and order 6 (its starts need the rounding terms less
// often; not on Suzuki 5) and time on all three (the counts:
// tests/test_composition.cpp, Composition.Mp06StagesStartFromTheirOwnMultipliers).
template <class Inner>
class Composed {
 public:
  static constexpr int n = Inner::n, m = Inner::m;
  static constexpr int lag = 0;
  static_assert(Inner::lag == 0, "composition needs a one-step method on (q, p) (lag 0)");

  Composed(Inner inner, const Composition& c) : inner_(std::move(inner)), c_(c) {}

  const Inner& inner() const { return inner_; }
  const auto& system() const { return inner_.system(); }

  MethodTraits traits() const {
    MethodTraits t = inner_.traits();
    const int inner_velocity_order = t.velocity_order ? t.velocity_order : t.order;
    // A method that holds the velocity constraint only in an averaged form
    // (the discrete gradient) is not a smooth near-identity map of one
    // manifold: each stage ends O(stage^2) off the constraint manifold and the
    // next one pulls it back through its multiplier.  The classical order
    // conditions then do not tell the whole story: measured on both paper
    // scenes, its triple jump and Suzuki compositions are of order 4 but
    // Kahan-Li's order-6 one is of order 4 too (tests/test_methods.cpp,
    // README "Methods").  We declare what we measured.
    t.order = t.holds_velocity_constraint ? c_.order : std::min(c_.order, 4);
    // For the same reason its reported v keeps the inner order: the O(stage^2)
    // constraint violation at every grid point is in v.
    t.velocity_order = t.holds_velocity_constraint ? 0 : inner_velocity_order;
    t.stages = static_cast<int>(c_.gamma.size()) * t.stages;
    return t;
  }

  void start(const Vec<double, n>& q0, const Vec<double, n>& v0) {
    inner_.start(q0, v0);
    h_last_ = 0;
  }

  // Written so that a stage pays for the memory only two copies of the
  // multiplier (its start and its result): the retry out of line, each
  // stage's summary constructed in place.  A default summary move-assigned
  // from the step, with the retry inline, would cost a noticeable share of a
  // composed step where the inner step is cheap and needs no memory.
  StepSummary step(double h) {
    StepSummary total;
    // Stage memory (above): the last composed step was one of h's sign.
    [[maybe_unused]] bool remember = false;
    if constexpr (kStageMemory) {
      remember = h * h_last_ > 0;
      h_last_ = 0;  // (set again once this step has succeeded)
    }
    for (size_t i = 0; i < c_.gamma.size(); ++i) {
      if constexpr (kStageMemory) {
        if (remember) inner_.guess_lambda(stage_lambda_[i]);
      }
      StepSummary s = inner_.step(c_.gamma[i] * h);
      if constexpr (kStageMemory) {
        // The previous stage's multiplier (the last stage's of the last
        // composed step, for the first) is the one the memory holds for it.
        if (remember && !s.ok()) retry(c_.gamma[i] * h, stage_lambda_[i == 0 ? c_.gamma.size() - 1 : i - 1], &s);
        stage_lambda_[i] = inner_.lambda();
      }
      if (!add_stage(c_, i, s, &total)) return total;
    }
    total.status = SolveStatus::kConverged;
    if constexpr (kStageMemory) h_last_ = h;
    return total;
  }

  void sample(Sample<n, m>* s) const { inner_.sample(s); }
  Vec<double, 2 * n> phase() const { return inner_.phase(); }

 private:
  static constexpr bool kStageMemory = starts_from_multiplier<Inner>::value;

  // A stage that failed from its own multiplier is retried from the
  // previous stage's, the start it would have without the memory: at large h
  // the last composed step's multiplier can be the farther one.  A defensive
  // fallback, not shown to pay: the runs where the memory changes which steps
  // fail (the sleigh at h >= 1.26, beyond every largest stable h) are decided
  // by round-off, with or without the retry.  The inner stepper's failure
  // messages count the retry as a step.  *s: the failed attempt, then the
  // retry's, with both attempts' counts.
  [[gnu::noinline, gnu::cold]] void retry(double h, const Vec<double, m>& previous, StepSummary* s) {
    inner_.guess_lambda(previous);
    StepSummary again = inner_.step(h);
    again.add_cost(*s);
    *s = std::move(again);
  }

  Inner inner_;
  Composition c_;
  // Stage memory: each stage's multiplier after the last composed step, and
  // that step's h (0: none, or it failed).
  std::vector<Vec<double, m>> stage_lambda_ = std::vector<Vec<double, m>>(c_.gamma.size(), Vec<double, m>::Zero());
  double h_last_ = 0;
};

// f(stepper) for `inner` composed as spec.composition says ("none": inner itself).
template <class Inner, class F>
auto with_composition(Inner&& inner, const std::string& name, F&& f) {
  const Composition& c = composition(name);
  if (c.name == "none") return f(inner);
  Composed<std::decay_t<Inner>> composed(std::forward<Inner>(inner), c);
  return f(composed);
}

}  // namespace nhi
