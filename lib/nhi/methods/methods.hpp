// Methods by name: the one table the runner, every study, the benchmarks and
// the tests go through, so a method means the same thing everywhere.
//
// A *method* is a plain type in the TypeList `Methods` below, declared once in
// its own header beside its stepper (DlaMethod in dla_composition.hpp,
// Rk4Method in rk4.hpp, ReferenceMethod in reference.hpp, the pairs in
// embedded_rk.hpp, Mp06Method, DiscreteGradientMethod, SparkMethod in theirs):
//   static constexpr const char* name;          // the scene's "method" value
//   static std::vector<MethodKey> keys();       // its own scene keys, checks, defaults (method_spec.hpp)
//   static constexpr bool adaptive;             // h is the output interval, not its step
//   static bool symmetric(const MethodSpec&);   // self-adjoint: then it accepts a
//                                               // MethodSpec::composition (composition.hpp)
//   static constexpr bool reports_p;            // its samples carry p and lambda
//   static std::string label(const MethodSpec&);      // its label before "+composition"
//   static constexpr double step_cost;                // a step (one stage) in RK4 steps of the
//                                                     // same scene, for scheduling the studies' cells
//   static std::vector<StudyEntry> study_entries();   // what the studies run of it: group,
//                                                     // line style in the figures, external or not
//   template <class S, class F> static auto with_stepper(const S&, const MethodSpec&, F&& f);
// where with_stepper builds the stepper the spec describes and returns
// f(stepper); its order, symmetry and the rest are the stepper's traits().
// Adding a method is its header (and body), one entry in `Methods` (with its
// #include), and a file in lib/src/methods/ that compiles it for every
// registered system (its `template class` and MethodRun lines); it then runs
// through `nhi run`, `nhi list`, the Python module, every study
// (study_methods() below), bench_steps, the figures and the typed
// method-contract tests (tests/test_methods.cpp, which print its pinned numbers).
#pragma once

#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nhi/methods/discrete_gradient/discrete_gradient.hpp"
#include "nhi/methods/dla/dla_composition.hpp"
#include "nhi/methods/explicit/embedded_rk.hpp"
#include "nhi/methods/explicit/rk4.hpp"
#include "nhi/methods/group/dla_group.hpp"
#include "nhi/methods/group/eps_cayley.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/mp06/mp06.hpp"
#include "nhi/methods/reference/reference.hpp"
#include "nhi/methods/spark/spark.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/integrate.hpp"
#include "nhi/roles/typelist.hpp"

namespace nhi {

// Every method the library has.
using Methods = TypeList<DlaMethod, Rk4Method, ReferenceMethod, Mp06Method, DiscreteGradientMethod, SparkMethod,
                         Rkf78Method, Dopri5Method, GroupDlaMethod, EpsCayleyMethod>;

inline std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for_each_type(Methods{}, [&](auto tag) { names.push_back(decltype(tag)::type::name); });
  return names;
}

// f(M{}) for the method type named `kind` (throws for an unknown name).
template <class F>
void with_method_type(const std::string& kind, F&& f) {
  bool found = false;
  for_each_type(Methods{}, [&](auto tag) {
    if (!found && kind == decltype(tag)::type::name) {
      found = true;
      f(tag);
    }
  });
  if (!found) throw std::invalid_argument("unknown method \"" + kind + "\"");
}

// Is the method of `spec` studied on the system S?  A method may declare
//   template <class S> static constexpr bool studied_on();
// (the group DLA: on the systems with a quaternion only; elsewhere it is the
// alpha DLA, which the studies already run); without it, on every system.
// The studies and the typed method tests run a method only where it is.
template <class M, class S, class = void>
struct declares_studied_on : std::false_type {};
template <class M, class S>
struct declares_studied_on<M, S, std::void_t<decltype(M::template studied_on<S>())>> : std::true_type {};
template <class S>
inline bool studied_on(const MethodSpec& spec) {
  bool out = true;
  with_method_type(spec.kind, [&](auto tag) {
    using M = typename decltype(tag)::type;
    if constexpr (declares_studied_on<M, S>::value) out = M::template studied_on<S>();
  });
  return out;
}

// The method's declared flags and keys, by name.
struct MethodFlags {
  bool adaptive = false, reports_p = false;
  std::vector<MethodKey> keys;
};
inline MethodFlags method_flags(const std::string& kind) {
  MethodFlags fl;
  with_method_type(kind, [&](auto tag) {
    using M = typename decltype(tag)::type;
    fl = {M::adaptive, M::reports_p, M::keys()};
  });
  return fl;
}

// Every method's own keys, each once (the first method to declare a name
// gives its check), in the order of Methods.
// Two methods may share a key only with one contract (kind, choices, range,
// where it is held and its default); anything else is a mistake in the list,
// refused here rather than validated by whichever method comes first.
inline std::vector<MethodKey> all_method_keys() {
  std::vector<MethodKey> out;
  for_each_type(Methods{}, [&](auto tag) {
    for (MethodKey k : decltype(tag)::type::keys()) {
      const MethodKey* seen = nullptr;
      for (const MethodKey& o : out)
        if (std::string(o.name) == k.name) seen = &o;
      if (!seen) {
        out.push_back(std::move(k));
      } else if (!seen->same_contract(k)) {
        throw std::logic_error(std::string("methods.hpp: two methods declare the scene key '") + k.name +
                               "' with different contracts");
      }
    }
  });
  return out;
}

// The estimated cost of a step of the method spec names, in RK4 steps of the
// same scene: its step_cost times the composition's stages.  Only the balance
// of the studies' threads and ranks depends on it.
// A kind no method has counts as one RK4 step.
inline double method_step_cost(const MethodSpec& spec) {
  double w = 1.0;
  bool adaptive = false;
  for_each_type(Methods{}, [&](auto tag) {
    using M = typename decltype(tag)::type;
    if (spec.kind == M::name) w = M::step_cost, adaptive = M::adaptive;
  });
  return adaptive ? w : w * static_cast<double>(composition(spec.composition).gamma.size());
}

// Is the method the spec names self-adjoint (and so composable)?
inline bool method_is_symmetric(const MethodSpec& spec) {
  bool sym = false;
  with_method_type(spec.kind, [&](auto tag) { sym = decltype(tag)::type::symmetric(spec); });
  return sym;
}

// f(stepper) for the stepper spec names; an unknown name is an error, never a fallback.
template <class S, class F>
auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
  using R = decltype(Rk4Method::with_stepper(sys, spec, f));
  std::optional<R> out;
  for_each_type(Methods{}, [&](auto tag) {
    using M = typename decltype(tag)::type;
    if (!out && spec.kind == M::name) out.emplace(M::with_stepper(sys, spec, f));
  });
  if (!out) throw std::invalid_argument("unknown method \"" + spec.kind + "\"");
  return std::move(*out);
}

// The methods the studies run, in a fixed order: every method's "main"
// study_entries() in the order of `Methods`, then every "variant", every
// "costly" one, then the external ones.  A method's style (colour and point type) in every figure is
// keyed by its label in plots/style.gp.  "main" methods are in every
// study; "variant"s (the paper's other alphas, the costlier compositions) in
// those that sweep them; "costly" ones (a step of 25 to 1000 RK4 steps: SPARK's
// dense solve) in the studies of short runs only (convergence, stability,
// geometry, bench_steps), not in the long-horizon, timed and many-state ones.
// Entries with external = true (the adaptive pairs rkf78 and dopri5) are run
// by the work-precision study only, over tolerances.
struct StudyMethod {
  MethodSpec spec;
  std::string group;      // "main", "variant" or "costly"
  bool external = false;  // the work-precision study's adaptive pairs
  int style = 99;         // its line style in the figures (StudyEntry)
  std::string label() const { return spec.label(); }
  // An adaptive method (the reference, the pairs): h is its output interval.
  bool adaptive() const { return method_flags(spec.kind).adaptive; }
  // A method with a fixed step (not the adaptive reference, not the pairs).
  bool fixed_step() const { return !adaptive(); }
  // Is it studied on the system S (studied_on above)?
  template <class S>
  bool on() const {
    return studied_on<S>(spec);
  }
};

inline const std::vector<StudyMethod>& study_methods() {
  static const std::vector<StudyMethod> list = [] {
    std::vector<StudyMethod> out;
    for (const bool external : {false, true})
      for (const char* group : {"main", "variant", "costly"})
        for_each_type(Methods{}, [&](auto tag) {
          for (const StudyEntry& e : decltype(tag)::type::study_entries())
            if (e.group == group && e.external == external) out.push_back({e.spec, e.group, e.external, e.style});
        });
    return out;
  }();
  return list;
}

}  // namespace nhi
