// Scenes in, results out: the JSON contract of the `nhi` runner.
//
// A scene is a JSON object with the keys
//   system         a registered system's name (nhi list)      (required)
//   params         object of system parameters                  (default: the system's)
//   q0, v0         arrays of n numbers; v0 must satisfy omega(q0) v0 = 0   (required)
//   method         a method's name (nhi list): "dla", "rk4", "benchmark" (the
//                  reference solution), "mp06", "rkf78", ...  (required)
//   composition    "none" | "triple_jump" | "suzuki5" | "order6"  (default "none");
//                  anything but "none" only with a symmetric method ("composable"
//                  in nhi list)
//   a method's own keys, declared with their checks and defaults by the method
//   (MethodKey, methods.hpp; other methods ignore them; nhi list shows them):
//   discretization "alpha" | "symmetric"  and  alpha, a number in [0, 1]: the
//                  DLA's (defaults "alpha", 0.5); stages 2, 3 or 4: spark's
//                  (default 2); constraint "midpoint" | "endpoint": discrete_gradient's
//   h              number > 0                                    (required)
//   steps          integer >= 1                                  (required)
//   tolerance      number in (0, 1): implicit methods' relative residual (default 1e-12),
//                  rtol = atol of the reference solution (CVODE), rkf78 and dopri5; unused by rk4
//   output_every   integer >= 1: record steps 0, s, 2s, ... and the last (default 1)
//   start          "predictor" | "continuation": where an implicit method's step
//                  solve starts, its own predictor or the root continued from
//                  h -> 0 (solver.hpp)                          (default "predictor")
//   energy_limit   "auto" | "off" | number > 0: a run whose |E - E0| passes
//                  max(|E0|, 1) ("auto"), or the number, ends "failed" there, as
//                  does a non-finite state (guard.hpp); "off": no check (default "auto")
// Every number must be finite and at most 1e100 in magnitude.
// Unknown keys are rejected (a misspelt key must not silently fall back to a default).
// validate_scene() returns the resolved scene with every default filled in, or
// throws SceneError naming the key and the problem.  run_scene() runs it and
// returns the result object (see README.md, "Result format").
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace nhi {

using json = nlohmann::json;

struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// What the library has, for `nhi list`: {"systems": [{name, n, m, params
// (name: default), q0, v0, reversible, separable}], "methods": [{label,
// keys, method, composition, order, symmetric, implicit, adaptive, composable,
// group, own (the method's own keys), and every method key (null where the
// method has none)}] (every method the studies run), "compositions":
// [{name, order, stages}]}.
json catalog();

// The deepest nesting of arrays and objects a scene or a --set value may have
// (a scene needs 3); deeper input is refused while it is parsed.
constexpr int kMaxSceneDepth = 64;

// Parse a scene file (throws SceneError on unreadable or malformed JSON).
json load_scene_file(const std::string& path);
// The same for scene text already in memory; `origin` names it in messages.
json parse_scene_text(const std::string& text, const std::string& origin);

// Apply one `--set key=value` override.  The value is parsed as JSON; if that
// fails it is taken as a string (so `--set method=rk4` works).  A dotted key
// `params.kx=2` sets one system parameter.
void apply_override(json* scene, const std::string& assignment);

// Check every key; return the scene with defaults filled in.
json validate_scene(const json& scene);

// Run a validated scene.  Never throws for a failed step: that is status "failed".
json run_scene(const json& resolved);

// Provenance of a result: git revision and dirtiness, compiler, library versions, time.
json meta();

// Names the runner knows (for messages and tests).
std::vector<std::string> system_names();
// The names of the registered methods (methods.hpp), for code that does not include the steppers.
std::vector<std::string> registered_method_names();

}  // namespace nhi
