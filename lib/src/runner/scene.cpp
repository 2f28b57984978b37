// Scene validation and the runner behind `nhi run` (contract in scene.hpp and README.md).
#include "nhi/runner/scene.hpp"
#include "nhi/runner/scene_detail.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <sstream>

#include <sys/resource.h>

#include "nhi/methods/methods.hpp"
#include "nhi/roles/observer.hpp"
#include "nhi/runner/run.hpp"

namespace nhi {
namespace {

using namespace scene_detail;

// The scene's keys: the run's, then every method's own (MethodKey, methods.hpp).
const std::vector<std::string>& scene_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = {"system", "params",       "q0",          "v0",    "method",      "h",
                                  "steps",  "tolerance",    "output_every", "composition", "start", "energy_limit"};
    for (const MethodKey& mk : all_method_keys()) k.push_back(mk.name);
    return k;
  }();
  return keys;
}

// A method key's value in a scene (checked), or its default (MethodSpec's).
json method_key_value(const MethodKey& k, const json& scene) {
  const MethodSpec defaults;
  const bool given = scene.contains(k.name);
  if (k.kind == MethodKey::Kind::kChoice)
    return given ? json(one_of(scene[k.name], k.name, k.choices)) : json(k.text_of(defaults));
  if (k.kind == MethodKey::Kind::kInteger)
    return given ? integer(scene[k.name], k.name, long(k.lo), long(k.hi)) : long(k.number_of(defaults));
  if (!given) return k.number_of(defaults);
  const double x = finite_number(scene[k.name], k.name);
  if (!(x >= k.lo && x <= k.hi)) {
    char range[64];
    std::snprintf(range, sizeof range, "must be in [%g, %g], got ", k.lo, k.hi);
    fail(k.name, range + show(scene[k.name]));
  }
  return x;
}

// The method keys' values of a resolved scene, into spec.
void set_method_keys(MethodSpec* spec, const json& resolved) {
  for (const MethodKey& k : all_method_keys()) {
    if (k.kind == MethodKey::Kind::kChoice)
      k.set_text(spec, resolved[k.name].get<std::string>());
    else
      k.set_number(spec, resolved[k.name].get<double>());
  }
}

// The MethodSpec a resolved scene describes.
MethodSpec spec_of_scene(const json& sc) {
  MethodSpec spec;
  spec.kind = sc["method"];
  spec.tolerance = sc["tolerance"];
  spec.composition = sc["composition"];
  spec.start = sc["start"];
  set_method_keys(&spec, sc);
  return spec;
}

long peak_rss_kb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;  // kilobytes on Linux
}

double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// The scene's "energy_limit" (validated): "auto" max(|E0|, 1), "off", or a bound on |E - E0|.
EnergyLimit energy_limit_of(const json& j) {
  if (j.is_number()) return EnergyLimit::absolute_bound(j.get<double>());
  return j == "off" ? EnergyLimit::off() : EnergyLimit::runner_default();
}

template <class S>
json run_system(const S& sys, const json& sc) {
  constexpr int n = S::n;
  const Vec<double, n> q0 = vector_of<n>(sc["q0"], "q0");
  const Vec<double, n> v0 = vector_of<n>(sc["v0"], "v0");
  const double h = sc["h"];
  const long steps = sc["steps"], every = sc["output_every"];

  Recorder<S> rec(sys, every, steps);
  const double cpu0 = cpu_seconds();
  const auto wall0 = std::chrono::steady_clock::now();
  const MethodSpec spec = spec_of_scene(sc);
  const RunReport rep = run_method(sys, spec, q0, v0, h, steps, rec, energy_limit_of(sc["energy_limit"]));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double cpu = cpu_seconds() - cpu0;

  json out;
  out["scene"] = sc;
  out["status"] = rep.ok ? "ok" : "failed";
  if (!rep.ok)
    out["failure"] = {{"step", rep.failure_step},
                      {"time", rep.failure_step * h},
                      {"kind", to_string(rep.failure)},
                      {"reason", rep.reason}};
  rec.write(&out);
  out["stats"] = {{"wall_seconds", wall},
                  {"cpu_seconds", cpu},
                  {"steps_taken", rep.steps_taken},
                  {"newton_iterations", rep.newton_iterations},
                  {"residual_evaluations", rep.residual_evaluations},
                  {"fallback_steps", rep.fallbacks},
                  {"rhs_evaluations", rep.rhs_evaluations},
                  {"internal_steps", rep.internal_steps},
                  {"rejected_steps", rep.rejected_steps},
                  {"peak_rss_kb", peak_rss_kb()}};  // of the process so far, before serialization
  out["meta"] = meta();
  return out;
}

// Bytes available to this process: MemAvailable, or less if an address-space
// or data-segment limit is set.
double available_bytes() {
  double avail = std::numeric_limits<double>::infinity();
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kb;
  std::string unit;
  while (meminfo >> key >> kb >> unit)
    if (key == "MemAvailable:") avail = kb * 1024.0;
  for (int res : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit rl{};
    if (getrlimit(res, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) avail = std::min(avail, double(rl.rlim_cur));
  }
  return avail;
}

// A run keeps its recorded points until it writes them: per point the numbers
// in the Recorder's vectors (8 bytes), as JSON values (16 bytes plus the
// arrays around them) and as text (up to 25 bytes), with a per-point overhead
// for the row arrays.  Measured: particle DLA, 10^6 points, peak RSS 1.12 GB
// (1120 bytes per point, a 282 MB result file); this estimate gives 1320.
double estimated_bytes_per_point(int n, int m, bool has_p, int first_integrals) {
  const int numbers = 1 + n + n + 1 + m + first_integrals + (has_p ? n + m + m : 0);
  const int rows = 4 + (has_p ? 3 : 0);
  return numbers * (8.0 + 16.0 + 25.0 + 16.0) + rows * 64.0;
}

void refuse_if_too_large(const json& r, int n, int m, int first_integrals) {
  const long steps = r["steps"], every = r["output_every"];
  const double points = double(steps / every) + 2;
  const double bytes = points * estimated_bytes_per_point(n, m, method_flags(r["method"]).reports_p, first_integrals);
  const double avail = available_bytes();
  if (bytes > avail) {
    const double per_point = bytes / points;
    const long min_every = static_cast<long>(std::ceil(double(steps) * per_point / avail));
    std::ostringstream os;
    os.precision(3);
    os << "the run would record " << points << " points, about " << bytes / 1e9 << " GB in memory, more than the "
       << avail / 1e9 << " GB available; record fewer points with output_every >= " << min_every;
    fail("output_every", os.str());
  }
}

}  // namespace

std::vector<std::string> system_names() { return registered_system_names(); }
std::vector<std::string> registered_method_names() { return method_names(); }

json catalog() {
  json out;
  out["systems"] = json::array();
  for_each_type(Systems{}, [&](auto tag) {
    using S = typename decltype(tag)::type;
    const S sys;
    json params = json::object();
    for (const auto& p : S::parameters()) params[p.name] = sys.*(p.member);
    const Vec<double, S::n> q0 = S::default_q0(), v0 = S::default_v0();
    // The scene's class from its declared traits (system.hpp): Modin & Verdier's
    // reversible and integrable, refined where reversible but not integrable.
    const char* behaviour = behaviour_of<S>::value;
    std::string cls = "not reversible";
    if (is_reversible<S>::value)
      cls = std::string("reversible, ") + (is_integrable<S>::value ? "integrable" : behaviour ? behaviour : "not integrable");
    else if (has_reversible_flow<S>::value)
      cls = "reversible flow, non-reversible maps";
    // A rigid body (its orientation a unit quaternion) is a class of its own: its
    // candidates include the methods on the group.
    if (quaternion_at<S>::value >= 0) cls = "rigid body";
    out["systems"].push_back({{"name", S::name},
                              {"n", S::n},
                              {"m", S::m},
                              {"params", params},
                              {"q0", std::vector<double>(q0.data(), q0.data() + S::n)},
                              {"v0", std::vector<double>(v0.data(), v0.data() + S::n)},
                              {"reversible", is_reversible<S>::value},
                              {"integrable", is_integrable<S>::value},
                              {"reversible_flow", has_reversible_flow<S>::value},
                              {"behaviour", behaviour ? json(behaviour) : json(nullptr)},
                              {"class", cls},
                              {"separable", is_separable<S>::value}});
  });
  // Every method the studies run, with the traits it declares (on the first
  // registered system: a method's order and symmetry do not depend on it).
  using First = typename At<Systems, 0>::type;
  out["methods"] = json::array();
  for (const StudyMethod& m : study_methods()) {
    const MethodTraits t = method_traits(First{}, m.spec);
    json entry = {{"label", m.label()},
                  {"keys", m.spec.scene_keys()},
                  {"method", m.spec.kind},
                  {"composition", m.spec.composition},
                  {"order", t.order},
                  {"symmetric", t.symmetric},
                  {"implicit", t.implicit},
                  {"adaptive", t.adaptive},
                  {"composable", m.spec.composition == "none" && method_is_symmetric(m.spec)},
                  {"group", m.group},
                  {"style", m.style}};
    // Every method key: its value where the method has it, else null; "own"
    // lists the method's keys in their declared order.
    // The registered systems the method is studied on (StudyMethod::on): the
    // scenes a study runs it on, and where `nhi run` is sure to take it.
    entry["systems"] = json::array();
    for_each_type(Systems{}, [&](auto tag) {
      using S = typename decltype(tag)::type;
      if (m.template on<S>()) entry["systems"].push_back(S::name);
    });
    for (const MethodKey& k : all_method_keys()) entry[k.name] = nullptr;
    entry["own"] = json::array();
    for (const MethodKey& k : method_flags(m.spec.kind).keys) {
      entry["own"].push_back(k.name);
      if (k.kind == MethodKey::Kind::kChoice) entry[k.name] = k.text_of(m.spec);
      if (k.kind == MethodKey::Kind::kInteger) entry[k.name] = long(k.number_of(m.spec));
      if (k.kind == MethodKey::Kind::kNumber) entry[k.name] = k.number_of(m.spec);
    }
    out["methods"].push_back(entry);
  }
  out["compositions"] = json::array();
  for (const Composition& c : compositions())
    out["compositions"].push_back({{"name", c.name}, {"order", c.order}, {"stages", c.gamma.size()}});
  return out;
}

json load_scene_file(const std::string& path) {
  errno = 0;
  std::ifstream in(path);
  if (!in) throw SceneError("cannot read scene file '" + path + "': " + std::strerror(errno ? errno : ENOENT));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_scene_text(ss.str(), "scene file '" + path + "'");
}

namespace {

// json::parse, refusing values nested deeper than kMaxSceneDepth before they
// are built (printing or walking a value nested 10^5 deep overflows the stack).
json parse_bounded(const std::string& text, const std::string& what) {
  const json::parser_callback_t bound = [&what](int depth, json::parse_event_t, json&) {
    if (depth > kMaxSceneDepth)
      throw SceneError(what + " is nested deeper than " + std::to_string(kMaxSceneDepth) + " levels");
    return true;
  };
  return json::parse(text, bound);
}

}  // namespace

json parse_scene_text(const std::string& text, const std::string& origin) {
  try {
    return parse_bounded(text, origin);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for numbers like 1e999
    throw SceneError(origin + " is not valid JSON: " + e.what());
  }
}

void apply_override(json* scene, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) throw SceneError("--set expects key=value, got '" + assignment + "'");
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  json value;
  try {
    value = parse_bounded(text, "--set " + key);
  } catch (const json::parse_error&) {
    value = text;
  } catch (const json::exception& e) {  // out_of_range: a number like 1e999 (found by make fuzz)
    fail(key, std::string("value does not fit a double: ") + e.what());
  }
  if (!scene->is_object()) throw SceneError("scene must be a JSON object");
  const auto dot = key.find('.');
  if (dot == std::string::npos) {
    (*scene)[key] = value;
  } else {
    const std::string head = key.substr(0, dot), tail = key.substr(dot + 1);
    if (head != "params" || tail.empty() || tail.find('.') != std::string::npos)
      throw SceneError("--set: only params.NAME may be dotted, got '" + key + "'");
    if (!scene->contains("params")) (*scene)["params"] = json::object();
    if (!(*scene)["params"].is_object()) fail("params", "must be an object");
    (*scene)["params"][tail] = value;
  }
}

json validate_scene(const json& scene) {
  if (!scene.is_object()) throw SceneError("scene must be a JSON object, got " + show(scene));
  for (const auto& [key, value] : scene.items())
    if (std::find(scene_keys().begin(), scene_keys().end(), key) == scene_keys().end()) unknown_key(key, scene_keys());
  for (const char* key : {"system", "q0", "v0", "method", "h", "steps"})
    if (!scene.contains(key)) fail(key, "missing (required)");

  json r;
  r["system"] = one_of(scene["system"], "system", system_names());
  if (scene.contains("params") && !scene["params"].is_object())
    fail("params", "must be an object, got " + show(scene["params"]));
  r["method"] = one_of(scene["method"], "method", method_names());
  for (const MethodKey& k : all_method_keys()) r[k.name] = method_key_value(k, scene);
  r["start"] = scene.contains("start") ? one_of(scene["start"], "start", {"predictor", "continuation"}) : "predictor";
  r["composition"] =
      scene.contains("composition") ? one_of(scene["composition"], "composition", composition_names()) : "none";
  if (r["composition"] != "none") {
    MethodSpec spec;
    spec.kind = r["method"];
    set_method_keys(&spec, r);
    if (!method_is_symmetric(spec))
      fail("composition",
           "\"" + r["composition"].get<std::string>() +
               "\" composes only symmetric methods (\"composable\" in nhi list), not " + spec.label());
  }
  const double h = finite_number(scene["h"], "h");
  if (!(h > 0)) fail("h", "must be > 0, got " + show(scene["h"]));
  r["h"] = h;
  r["steps"] = integer(scene["steps"], "steps", 1, 10'000'000'000L);
  const double tol = scene.contains("tolerance") ? finite_number(scene["tolerance"], "tolerance") : kDefaultTolerance;
  if (!(tol > 0 && tol < 1)) fail("tolerance", "must be in (0, 1), got " + show(scene["tolerance"]));
  r["tolerance"] = tol;
  if (!scene.contains("energy_limit")) {
    r["energy_limit"] = "auto";
  } else if (scene["energy_limit"].is_string()) {
    r["energy_limit"] = one_of(scene["energy_limit"], "energy_limit", {"auto", "off"});
  } else {
    if (!scene["energy_limit"].is_number())
      fail("energy_limit", "must be \"auto\", \"off\" or a number > 0, got " + show(scene["energy_limit"]));
    const double lim = finite_number(scene["energy_limit"], "energy_limit");
    if (!(lim > 0)) fail("energy_limit", "must be > 0, got " + show(scene["energy_limit"]));
    r["energy_limit"] = lim;
  }
  r["output_every"] =
      scene.contains("output_every") ? integer(scene["output_every"], "output_every", 1, 10'000'000'000L) : 1L;
  if (!std::isfinite(h * double(r["steps"].get<long>()))) fail("h", "h * steps is not finite");

  json params;
  with_system(scene, &params, [&](const auto& sys) {
    using S = std::decay_t<decltype(sys)>;
    constexpr int n = S::n;
    const Vec<double, n> q0 = vector_of<n>(scene["q0"], "q0");
    const Vec<double, n> v0 = vector_of<n>(scene["v0"], "v0");
    // v0 must lie in the constraint distribution, to a relative 1e-9 of the
    // size of the terms of omega(q0) v0 (a hand-typed decimal passes, a wrong
    // velocity does not).
    const auto W = sys.template omega<double>(q0);
    for (int a = 0; a < S::m; ++a) {
      const double c = W.row(a).dot(v0);
      const double scale = (W.row(a).cwiseAbs() * v0.cwiseAbs()).sum();
      if (!(std::abs(c) <= 1e-9 * std::max(scale, 1e-300) || c == 0.0)) {
        std::ostringstream os;
        os << "violates constraint " << a << ": omega(q0) v0 = " << c << " (allowed: 1e-9 relative to " << scale << ")";
        fail("v0", os.str());
      }
    }
    r["q0"] = to_json(q0);
    r["v0"] = to_json(v0);
    refuse_if_too_large(r, S::n, S::m, static_cast<int>(std::tuple_size<FirstIntegrals<S>>::value));
    return 0;
  });
  r["params"] = params;
  return r;
}

json run_scene(const json& resolved) {
  json params;
  return with_system(resolved, &params, [&](const auto& sys) { return run_system(sys, resolved); });
}

}  // namespace nhi
