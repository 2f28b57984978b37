// A method as a scene or a study names it (MethodSpec), and the entries a method
// contributes to the studies (StudyEntry).  Kept apart from methods.hpp so that
// each method's header can declare its own table entry (see methods.hpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace nhi {

// The default tolerance of every method that has one (the implicit methods'
// relative residual, the adaptive methods' rtol = atol): the scene's default.
inline constexpr double kDefaultTolerance = 1e-12;

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

  // The one label scheme, the key of a method's style in plots/style.gp:
  // the method's own label (its struct's label(spec): "dla a=0.5", "dla-sym a=0",
  // "rk4", "reference", "mp06", ...), then "+composition" when composed, e.g.
  // "mp06+triple_jump".  A kind no method has is labelled by its name ("rkf78").
  // Defined in lib/src/methods.cpp, where the method list is.
  std::string label() const;
  // The scene keys that select this method, as `nhi run --set` takes them,
  // defaults left out: "method=mp06 composition=triple_jump",
  // "method=dla discretization=symmetric alpha=0" (lib/src/methods.cpp).
  std::string scene_keys() const;
};

// A scene key of one method's own (its struct's keys(), methods.hpp): the
// MethodSpec member it sets and the check a scene's value must pass.  Its
// default is the member's default in MethodSpec.  The scene validator, the
// catalog (`nhi list`, the Python module) and MethodSpec::scene_keys() read
// the keys from the methods; no method's key is written anywhere else.
struct MethodKey {
  const char* name = "";
  std::string MethodSpec::*text = nullptr;  // a choice among `choices`
  std::vector<std::string> choices;
  double MethodSpec::*number = nullptr;  // a finite number in [lo, hi]
  int MethodSpec::*whole = nullptr;      // an integer in [lo, hi]
  double lo = 0, hi = 0;

  static MethodKey choice(const char* name, std::string MethodSpec::*m, std::vector<std::string> choices) {
    MethodKey k;
    k.name = name;
    k.text = m;
    k.choices = std::move(choices);
    return k;
  }
  static MethodKey range(const char* name, double MethodSpec::*m, double lo, double hi) {
    MethodKey k;
    k.name = name;
    k.number = m;
    k.lo = lo;
    k.hi = hi;
    return k;
  }
  static MethodKey integer(const char* name, int MethodSpec::*m, int lo, int hi) {
    MethodKey k;
    k.name = name;
    k.whole = m;
    k.lo = lo;
    k.hi = hi;
    return k;
  }
};

// A method's entry in the studies: "main" methods are in every study;
// "variant"s (the paper's other alphas, ...) in those that sweep them;
// "costly" ones only in the studies of short runs (methods.hpp, study_methods()).
struct StudyEntry {
  MethodSpec spec;
  std::string group = "main";
};

// A spec with only its kind and composition set.
inline MethodSpec spec_of(std::string kind, std::string composition = "none") {
  MethodSpec s;
  s.kind = std::move(kind);
  s.composition = std::move(composition);
  return s;
}

}  // namespace nhi
