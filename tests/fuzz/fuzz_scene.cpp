// libFuzzer target for the scene loader and validator (the input side of
// `nhi run`), built by `make fuzz` with clang -fsanitize=fuzzer,address,undefined.
//
// Input: scene text, optionally followed by lines "--set key=value" style
// assignments (everything after the first line that starts with "\n--set ").
// Contract checked on every input:
//   - parsing, overrides and validation either succeed or throw nhi::SceneError;
//     any other exception, a crash or undefined behaviour is a finding;
//   - a scene that validates satisfies the documented invariants (scene.hpp);
//   - it then runs (capped at 3 steps) without throwing, with status ok or failed.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "nhi/runner/scene.hpp"

namespace {

void require(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "fuzz_scene: invariant violated: %s\n", what);
    std::abort();
  }
}

bool finite_number(const nhi::json& x) { return x.is_number() && std::isfinite(x.get<double>()); }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string marker = "\n--set ";
  std::string text = input;
  std::vector<std::string> sets;
  for (size_t at = input.find(marker); at != std::string::npos;) {
    if (sets.empty()) text = input.substr(0, at);
    const size_t start = at + marker.size(), next = input.find(marker, start);
    sets.push_back(input.substr(start, next == std::string::npos ? std::string::npos : next - start));
    at = next;
  }
  nhi::json resolved;
  try {
    nhi::json scene = nhi::parse_scene_text(text, "fuzz input");
    for (const auto& s : sets) nhi::apply_override(&scene, s);
    resolved = nhi::validate_scene(scene);
  } catch (const nhi::SceneError&) {
    return 0;  // rejected with a message: fine
  }
  // Invariants of a resolved scene.
  require(resolved.is_object(), "resolved scene is an object");
  require(finite_number(resolved["h"]) && resolved["h"].get<double>() > 0, "h finite and > 0");
  require(resolved["steps"].is_number_integer() && resolved["steps"].get<long>() >= 1, "steps integer >= 1");
  require(resolved["output_every"].is_number_integer() && resolved["output_every"].get<long>() >= 1,
          "output_every integer >= 1");
  const double alpha = resolved["alpha"].get<double>();
  require(alpha >= 0 && alpha <= 1, "alpha in [0, 1]");
  const double tol = resolved["tolerance"].get<double>();
  require(tol > 0 && tol < 1, "tolerance in (0, 1)");
  for (const char* k : {"q0", "v0"}) {
    require(resolved[k].is_array() && !resolved[k].empty(), "q0, v0 non-empty arrays");
    for (const auto& x : resolved[k]) require(finite_number(x), "q0, v0 entries finite");
  }
  // A short run: must end ok or failed, never throw.
  resolved["steps"] = std::min<long>(resolved["steps"].get<long>(), 3);
  const nhi::json result = nhi::run_scene(resolved);
  require(result["status"] == "ok" || result["status"] == "failed", "status ok or failed");
  return 0;
}
