// Methods by name: the one table the runner, every study, the benchmarks and
// the tests go through, so a method means the same thing everywhere.
//
// A *method* is a plain type in the TypeList `Methods` below with
//   static constexpr const char* name;          // the scene's "method" value
//   static constexpr bool uses_discretization;  // reads MethodSpec::discretization, alpha
//   template <class S, class F> static auto with_stepper(const S&, const MethodSpec&, F&& f);
// which builds the stepper the spec describes and returns f(stepper).  Adding a
// method is one header (its stepper and this small struct) and one entry in
// `Methods`; it then runs through `nhi run`, and through every study that
// takes its methods from study_methods() once it has an entry there.
#pragma once

#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "nhi/integrate.hpp"
#include "nhi/typelist.hpp"

namespace nhi {

// A method as a scene or a study names it.
struct MethodSpec {
  std::string kind = "dla";              // a Methods name: "dla", "rk4", "benchmark"
  std::string discretization = "alpha";  // DLA: "alpha" or "symmetric"
  double alpha = 0.5;
  double tolerance = 1e-12;  // implicit methods: relative residual; the reference: CVODE rtol = atol

  // The one label scheme: "dla a=0.5", "dla-sym a=0", "rk4", "reference".
  std::string label() const {
    char buf[64];
    if (kind == "dla")
      std::snprintf(buf, sizeof buf, "%s a=%g", discretization == "alpha" ? "dla" : "dla-sym", alpha);
    else if (kind == "benchmark")
      std::snprintf(buf, sizeof buf, "reference");
    else
      std::snprintf(buf, sizeof buf, "%s", kind.c_str());
    return buf;
  }
};

struct DlaMethod {
  static constexpr const char* name = "dla";
  static constexpr bool uses_discretization = true;
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    DlaOptions opt;
    opt.tolerance = spec.tolerance;
    if (spec.discretization == "alpha") {
      DlaStepper<S, AlphaDiscretization> st(sys, AlphaDiscretization{spec.alpha}, opt);
      return f(st);
    }
    if (spec.discretization != "symmetric")
      throw std::invalid_argument("unknown discretization \"" + spec.discretization + "\"");
    DlaStepper<S, SymmetricDiscretization> st(sys, SymmetricDiscretization{spec.alpha}, opt);
    return f(st);
  }
};

struct Rk4Method {
  static constexpr const char* name = "rk4";
  static constexpr bool uses_discretization = false;
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec&, F&& f) {
    Rk4Stepper<S> st(sys);
    return f(st);
  }
};

// The reference solution (scene value "benchmark", kept for the runner's contract).
struct ReferenceMethod {
  static constexpr const char* name = "benchmark";
  static constexpr bool uses_discretization = false;
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    ReferenceOptions opt;
    opt.rtol = opt.atol = spec.tolerance;
    ReferenceStepper<S> st(sys, opt);
    return f(st);
  }
};

// Every method the library has.
using Methods = TypeList<DlaMethod, Rk4Method, ReferenceMethod>;

inline std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for_each_type(Methods{}, [&](auto tag) { names.push_back(decltype(tag)::type::name); });
  return names;
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

// Run spec on sys from (q0, v0) with step h for `steps` steps.
template <class S, class Observer>
RunReport run_method(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0,
                     const Vec<double, S::n>& v0, double h, long steps, Observer&& observe) {
  return with_stepper(sys, spec, [&](auto& stepper) { return integrate(stepper, q0, v0, h, steps, observe); });
}

// The method's declared traits (order, symmetry, ...), for tests and studies.
template <class S>
MethodTraits method_traits(const S& sys, const MethodSpec& spec) {
  return with_stepper(sys, spec, [](auto& stepper) { return stepper.traits(); });
}

// The methods the studies run, in a fixed order: the position in this list is
// the method's style (colour and point type) in plots/style.gp, in every figure.
// "main" methods are in every study; "variant"s (the paper's other alphas) in
// those that sweep alpha.  Entries with external = true are not library methods
// (Boost.Odeint's adaptive pairs, run by the work-precision study only); they
// are listed here so that their label and style are fixed in the same place.
struct StudyMethod {
  MethodSpec spec;
  std::string group;  // "main" or "variant"
  bool external = false;
  std::string external_label;
  std::string label() const { return external ? external_label : spec.label(); }
  int style() const;
};

inline const std::vector<StudyMethod>& study_methods() {
  static const std::vector<StudyMethod> list = {
      {{"dla", "alpha", 0.5}, "main", false, ""},
      {{"dla", "symmetric", 0.0}, "main", false, ""},
      {{"rk4"}, "main", false, ""},
      {{"benchmark", "alpha", 0.5, 1e-12}, "main", false, ""},
      {{"dla", "alpha", 0.0}, "variant", false, ""},
      {{"dla", "alpha", 0.25}, "variant", false, ""},
      {{"dla", "alpha", 0.75}, "variant", false, ""},
      {{"dla", "alpha", 1.0}, "variant", false, ""},
      {{"dla", "symmetric", 0.25}, "variant", false, ""},
      {{}, "main", true, "rkf78"},
      {{}, "main", true, "dopri5"},
  };
  return list;
}

// 1-based style of a label (0 if it is not in study_methods()).
inline int method_style(const std::string& label) {
  const auto& list = study_methods();
  for (size_t i = 0; i < list.size(); ++i)
    if (list[i].label() == label) return static_cast<int>(i) + 1;
  return 0;
}
inline int StudyMethod::style() const { return method_style(label()); }

}  // namespace nhi
