// A method as a scene or a study names it (MethodSpec), and the entries a method
// contributes to the studies (StudyEntry).  Kept apart from methods.hpp so that
// each method's header can declare its own table entry (see methods.hpp).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "nhi/roles/core.hpp"  // kDefaultTolerance

namespace nhi {

struct MethodSpec {
  std::string kind = "dla";              // a Methods name: "dla", "rk4", "benchmark", "mp06", ...
  std::string discretization = "alpha";  // DLA: "alpha" or "symmetric"
  double alpha = 0.5;
  double tolerance = kDefaultTolerance;  // implicit methods: relative residual; the reference: CVODE rtol = atol
  std::string composition = "none";  // symmetric methods: composition.hpp
  int stages = 2;                    // spark: Lobatto IIIA-IIIB stages, 2, 3 or 4 (spark.hpp)
  // discrete_gradient: where the velocity constraint holds, "midpoint" (the
  // averaged form, odelab's) or "endpoint" (at every grid point, with the
  // constraint force turned to do no discrete work; discrete_gradient.hpp).
  std::string constraint = "midpoint";
  // Implicit methods: the start of each step's solve.  "predictor": the
  // method's own (extrapolation, passes); "continuation": the root continued
  // from h -> 0 (solver.hpp, root following).  root_check: with the
  // predictor, also report whether each step's root is the continued one.
  std::string start = "predictor";
  bool root_check = false;
  // The keys of a method that MethodSpec has no member for (MethodKey), by name.
  std::map<std::string, double> own_numbers;
  std::map<std::string, std::string> own_texts;

  // The one label scheme, the key of a method's style in plots/style.gp:
  // the method's own label (its struct's label(spec): "dla a=0.5", "dla-sym a=0",
  // "rk4", "reference", "mp06", ...), then "+composition" when composed, e.g.
  // "mp06+triple_jump".  A kind no method has is labelled by its name ("rkf78").
  // Defined in lib/src/runner/methods.cpp, where the method list is.
  std::string label() const;
  // The scene keys that select this method, as `nhi run --set` takes them,
  // defaults left out: "method=mp06 composition=triple_jump",
  // "method=dla discretization=symmetric alpha=0" (lib/src/runner/methods.cpp).
  std::string scene_keys() const;
};

// A scene key of one method's own (its struct's keys(), methods.hpp): its
// kind and the check a scene's value must pass, and where the value lives: a
// MethodSpec member (its default then the member's), or, for a method that
// brings a key MethodSpec has no member for, MethodSpec::own_* (its default
// declared here).  The scene validator, the catalog (`nhi list`, the Python
// module) and MethodSpec::scene_keys() read the keys from the methods; no
// method's key is written anywhere else.
struct MethodKey {
  enum class Kind { kChoice, kNumber, kInteger };
  const char* name = "";
  Kind kind = Kind::kNumber;
  std::vector<std::string> choices;  // kChoice: the values
  double lo = 0, hi = 0;             // kNumber, kInteger: the closed range
  std::string MethodSpec::*text = nullptr;
  double MethodSpec::*number = nullptr;
  int MethodSpec::*whole = nullptr;
  std::string own_default_text;  // without a member: the default
  double own_default = 0;

  std::string text_of(const MethodSpec& s) const {
    if (text) return s.*text;
    const auto it = s.own_texts.find(name);
    return it == s.own_texts.end() ? own_default_text : it->second;
  }
  double number_of(const MethodSpec& s) const {
    if (number) return s.*number;
    if (whole) return s.*whole;
    const auto it = s.own_numbers.find(name);
    return it == s.own_numbers.end() ? own_default : it->second;
  }
  bool same_contract(const MethodKey& o) const {
    return kind == o.kind && choices == o.choices && lo == o.lo && hi == o.hi && text == o.text &&
           number == o.number && whole == o.whole && own_default_text == o.own_default_text &&
           own_default == o.own_default;
  }
  void set_text(MethodSpec* s, const std::string& v) const {
    if (text)
      s->*text = v;
    else
      s->own_texts[name] = v;
  }
  void set_number(MethodSpec* s, double v) const {
    if (number)
      s->*number = v;
    else if (whole)
      s->*whole = static_cast<int>(v);
    else
      s->own_numbers[name] = v;
  }

  // A choice among strings, a number in [lo, hi] or an integer in [lo, hi],
  // held by a MethodSpec member ...
  static MethodKey choice(const char* name, std::string MethodSpec::*m, std::vector<std::string> choices) {
    MethodKey k = choice(name, std::move(choices), "");
    k.text = m;
    return k;
  }
  static MethodKey range(const char* name, double MethodSpec::*m, double lo, double hi) {
    MethodKey k = range(name, lo, hi, 0.0);
    k.number = m;
    return k;
  }
  static MethodKey integer(const char* name, int MethodSpec::*m, int lo, int hi) {
    MethodKey k = range(name, lo, hi, 0.0);
    k.kind = Kind::kInteger;
    k.whole = m;
    return k;
  }
  // ... or by MethodSpec::own_*, with its default.
  static MethodKey choice(const char* name, std::vector<std::string> choices, std::string fallback) {
    MethodKey k;
    k.name = name;
    k.kind = Kind::kChoice;
    k.choices = std::move(choices);
    k.own_default_text = std::move(fallback);
    return k;
  }
  static MethodKey range(const char* name, double lo, double hi, double fallback) {
    MethodKey k;
    k.name = name;
    k.lo = lo;
    k.hi = hi;
    k.own_default = fallback;
    return k;
  }
  static MethodKey integer(const char* name, int lo, int hi, int fallback) {
    MethodKey k = range(name, lo, hi, fallback);
    k.kind = Kind::kInteger;
    return k;
  }
};

// A method's entry in the studies: "main" methods are in every study;
// "variant"s (the paper's other alphas, ...) in those that sweep them;
// "costly" ones only in the studies of short runs (methods.hpp, study_methods());
// external ones (the adaptive pairs) in the work-precision study only.  Its
// style is its line style in every figure (plots/style.gp defines the
// numbers, one range per family: reference 10, DLA 11-19, mp06 21-29,
// discrete gradient 31-39, SPARK 41-49, RK4 51, adaptive pairs 61-69;
// plots/method_styles.gp, written by `nhi list --gnuplot`, maps labels to them).
struct StudyEntry {
  MethodSpec spec;
  std::string group = "main";
  int style = 99;  // 99: grey, a method without a style of its own
  bool external = false;
};

// A spec with only its kind and composition set.
inline MethodSpec spec_of(std::string kind, std::string composition = "none") {
  MethodSpec s;
  s.kind = std::move(kind);
  s.composition = std::move(composition);
  return s;
}

}  // namespace nhi
