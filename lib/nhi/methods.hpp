// Methods by name: the one table the runner, every study, the benchmarks and
// the tests go through, so a method means the same thing everywhere.
//
// A *method* is a plain type in the TypeList `Methods` below with
//   static constexpr const char* name;          // the scene's "method" value
//   static constexpr bool adaptive;             // h is the output interval, not its step
//   static std::vector<MethodKey> keys();       // its own scene keys (method_spec.hpp)
//   static bool symmetric(const MethodSpec&);   // self-adjoint: then it accepts a
//                                               // MethodSpec::composition (composition.hpp)
//   static constexpr bool reports_p;            // its samples carry p and lambda
//   template <class S, class F> static auto with_stepper(const S&, const MethodSpec&, F&& f);
//   static std::vector<StudyEntry> study_entries();   // what the studies run of it
//   static std::string label(const MethodSpec&);      // its label before "+composition",
//                                                     // the key of its style in plots/style.gp
//   static constexpr double step_cost;                // a step (one stage) in RK4 steps of the
//                                                     // same scene, for scheduling the studies' cells
// which builds the stepper the spec describes and returns f(stepper).  Adding a
// method is one header (its stepper and this small struct, e.g. mp06.hpp) and
// one entry in `Methods` (with its #include); it then runs through `nhi run`,
// every study (study_methods() below), bench_steps and the typed method-contract
// tests (tests/test_methods.cpp).
#pragma once

#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nhi/discrete_gradient.hpp"
#include "nhi/dla_composition.hpp"
#include "nhi/embedded_rk.hpp"
#include "nhi/integrate.hpp"
#include "nhi/method_spec.hpp"
#include "nhi/mp06.hpp"
#include "nhi/reference.hpp"
#include "nhi/rk4.hpp"
#include "nhi/run.hpp"
#include "nhi/spark.hpp"
#include "nhi/spec_options.hpp"
#include "nhi/typelist.hpp"

namespace nhi {

struct DlaMethod {
  static constexpr const char* name = "dla";
  static constexpr bool adaptive = false;
  // The paper's discretizations: L_d^alpha, omega_d^alpha (eqs. 9, 13) or the
  // symmetric L_d^{sym,alpha}, omega_d^{sym,alpha} (eqs. 10, 14); alpha in [0, 1].
  static std::vector<MethodKey> keys() {
    return {MethodKey::choice("discretization", &MethodSpec::discretization, {"alpha", "symmetric"}),
            MethodKey::range("alpha", &MethodSpec::alpha, 0.0, 1.0)};
  }
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 6.0;
  static std::string label(const MethodSpec& spec) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s a=%g", spec.discretization == "alpha" ? "dla" : "dla-sym", spec.alpha);
    return buf;
  }
  // Self-adjoint discretizations (alpha = 1/2, the symmetric family) compose:
  // dla_composition.hpp, README "Methods".
  static bool symmetric(const MethodSpec& spec) {
    return spec.discretization == "symmetric" || (spec.discretization == "alpha" && spec.alpha == 0.5);
  }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    const DlaOptions opt = solver_options(spec);
    if (spec.composition != "none") {
      if (!symmetric(spec)) throw std::invalid_argument("the DLA composes only with a self-adjoint discretization");
      const Composition& c = composition(spec.composition);
      if (spec.discretization == "alpha") {
        ComposedDla<S, AlphaDiscretization> st(sys, AlphaDiscretization{spec.alpha}, opt, c);
        return f(st);
      }
      ComposedDla<S, SymmetricDiscretization> st(sys, SymmetricDiscretization{spec.alpha}, opt, c);
      return f(st);
    }
    if (spec.discretization == "alpha") {
      DlaStepper<S, AlphaDiscretization> st(sys, AlphaDiscretization{spec.alpha}, opt);
      return f(st);
    }
    if (spec.discretization != "symmetric")
      throw std::invalid_argument("unknown discretization \"" + spec.discretization + "\"");
    DlaStepper<S, SymmetricDiscretization> st(sys, SymmetricDiscretization{spec.alpha}, opt);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() {
    auto dla = [](const char* disc, double alpha, const char* group, int style) {
      MethodSpec s;
      s.discretization = disc;
      s.alpha = alpha;
      return StudyEntry{s, group, style};
    };
    StudyEntry tj = dla("alpha", 0.5, "main", 12), tj_sym = dla("symmetric", 0.0, "variant", 14);
    tj.spec.composition = tj_sym.spec.composition = "triple_jump";
    return {dla("alpha", 0.5, "main", 11),
            dla("symmetric", 0.0, "main", 13),
            dla("alpha", 0.0, "variant", 15),
            dla("alpha", 0.25, "variant", 16),
            dla("alpha", 0.75, "variant", 17),
            dla("alpha", 1.0, "variant", 18),
            dla("symmetric", 0.25, "variant", 19),
            tj,
            tj_sym};
  }
};

struct Rk4Method {
  static constexpr const char* name = "rk4";
  static constexpr bool adaptive = false;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = false;
  static constexpr double step_cost = 1.0;
  static std::string label(const MethodSpec&) { return name; }
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec&, F&& f) {
    Rk4Stepper<S> st(sys);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", 51}}; }
};

// The reference solution (scene value "benchmark", kept for the runner's contract).
struct ReferenceMethod {
  static constexpr const char* name = "benchmark";
  static constexpr bool adaptive = true;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = false;
  static constexpr double step_cost = 30.0;  // per output interval h
  static std::string label(const MethodSpec&) { return "reference"; }
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    ReferenceOptions opt;
    opt.rtol = opt.atol = spec.tolerance;
    ReferenceStepper<S> st(sys, opt);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", 10}}; }
};

// The adaptive explicit pairs rkf78 and dopri5 (embedded_rk.hpp): the
// scene's tolerance is atol = rtol, h the output interval.  Only the
// work-precision study runs them (study_methods() lists them there).
template <class P>
struct EmbeddedRkMethod {
  using Pair = P;
  static constexpr const char* name = Pair::name;
  static constexpr bool adaptive = true;
  static std::vector<MethodKey> keys() { return {}; }
  static constexpr bool reports_p = false;
  static constexpr double step_cost = 10.0;  // per output interval h
  static std::string label(const MethodSpec&) { return name; }
  static bool symmetric(const MethodSpec&) { return false; }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    EmbeddedRkOptions opt;
    opt.atol = opt.rtol = spec.tolerance;
    EmbeddedRkStepper<S, Pair> st(sys, opt);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() { return {{spec_of(name), "main", Pair::style, true}}; }
};
template <class M>
struct is_embedded_rk : std::false_type {};
template <class P>
struct is_embedded_rk<EmbeddedRkMethod<P>> : std::true_type {};
using Rkf78Method = EmbeddedRkMethod<Rkf78Pair>;
using Dopri5Method = EmbeddedRkMethod<Dopri5Pair>;

// Every method the library has.
using Methods = TypeList<DlaMethod, Rk4Method, ReferenceMethod, Mp06Method, DiscreteGradientMethod, SparkMethod,
                         Rkf78Method, Dopri5Method>;

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
inline std::vector<MethodKey> all_method_keys() {
  std::vector<MethodKey> out;
  for_each_type(Methods{}, [&](auto tag) {
    for (MethodKey k : decltype(tag)::type::keys()) {
      bool seen = false;
      for (const MethodKey& o : out) seen = seen || std::string(o.name) == k.name;
      if (!seen) out.push_back(std::move(k));
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
  std::string group;  // "main", "variant" or "costly"
  bool external = false;  // the work-precision study's adaptive pairs
  int style = 99;         // its line style in the figures (StudyEntry)
  std::string label() const { return spec.label(); }
  // An adaptive method (the reference, the pairs): h is its output interval.
  bool adaptive() const { return method_flags(spec.kind).adaptive; }
  // A method with a fixed step (not the adaptive reference, not the pairs).
  bool fixed_step() const { return !external && !adaptive(); }
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
