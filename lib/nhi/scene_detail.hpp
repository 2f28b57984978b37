// Scene plumbing shared by the runner and the study executables: JSON value
// checks that name the key, per-system parameter parsing, and visit_system(),
// which calls a generic lambda with the concrete system a scene names.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "nhi/core.hpp"
#include "nhi/scene.hpp"
#include "nhi/systems/particle.hpp"
#include "nhi/systems/robot.hpp"

namespace nhi::scene_detail {

[[noreturn]] inline void fail(const std::string& key, const std::string& problem) {
  throw SceneError("scene key '" + key + "': " + problem);
}

// A value for a message.  Invalid UTF-8 (possible in a --set string value,
// which is not parsed as JSON) is replaced, not thrown on: found by make fuzz.
inline std::string show(const json& j) {
  std::string s = j.dump(-1, ' ', false, json::error_handler_t::replace);
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// Largest magnitude a scene number may have: the energy multiplies a few of
// them, and 1e100^3 is still finite, so an accepted scene cannot overflow at t = 0.
constexpr double kMaxMagnitude = 1e100;

inline double finite_number(const json& j, const std::string& key) {
  if (!j.is_number()) fail(key, "must be a number, got " + show(j));
  const double x = j.get<double>();
  if (!std::isfinite(x)) fail(key, "must be finite, got " + show(j));
  if (std::abs(x) > kMaxMagnitude) fail(key, "must be at most 1e100 in magnitude, got " + show(j));
  return x;
}

inline long integer(const json& j, const std::string& key, long lo, long hi) {
  if (j.is_number_float()) {
    const double x = j.get<double>();
    if (!std::isfinite(x) || x != std::floor(x))
      fail(key, "must be an integer, got " + show(j));
    if (x < double(lo) || x > double(hi))
      fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + show(j));
    return static_cast<long>(x);
  }
  if (j.is_number_unsigned()) {
    const auto u = j.get<unsigned long long>();
    if (u > static_cast<unsigned long long>(hi) || static_cast<long>(u) < lo)
      fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + show(j));
    return static_cast<long>(u);
  }
  if (j.is_number_integer()) {
    const long x = j.get<long>();
    if (x < lo || x > hi)
      fail(key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + show(j));
    return x;
  }
  fail(key, "must be an integer, got " + show(j));
}

inline std::string one_of(const json& j, const std::string& key, const std::vector<std::string>& names) {
  std::string list;
  for (const auto& s : names) list += (list.empty() ? "" : ", ") + ("\"" + s + "\"");
  if (!j.is_string()) fail(key, "must be one of " + list + ", got " + show(j));
  const std::string s = j.get<std::string>();
  if (std::find(names.begin(), names.end(), s) == names.end())
    fail(key, "unknown value \"" + s + "\" (expected one of " + list + ")");
  return s;
}

template <int N>
Vec<double, N> vector_of(const json& j, const std::string& key) {
  if (!j.is_array()) fail(key, "must be an array of " + std::to_string(N) + " numbers, got " + show(j));
  if (j.size() != N)
    fail(key, "must have " + std::to_string(N) + " entries for this system, got " +
                  std::to_string(j.size()));
  Vec<double, N> v;
  for (int i = 0; i < N; ++i) v[i] = finite_number(j[i], key + "[" + std::to_string(i) + "]");
  return v;
}

template <int N>
json to_json(const Vec<double, N>& v) {
  json a = json::array();
  for (int i = 0; i < N; ++i) a.push_back(v[i]);
  return a;
}

// Per-system glue: parameters from JSON, defaults.  Each scene file stays free of JSON.
template <class S>
struct SceneTraits;

template <>
struct SceneTraits<Particle> {
  static Particle make(const json& params, json* resolved) {
    Particle p;
    for (const auto& [key, value] : params.items()) {
      if (key == "kx") p.kx = finite_number(value, "params.kx");
      else if (key == "ky") p.ky = finite_number(value, "params.ky");
      else fail("params." + key, "unknown parameter for system \"particle\" (known: kx, ky)");
    }
    *resolved = {{"kx", p.kx}, {"ky", p.ky}};
    return p;
  }
};

template <>
struct SceneTraits<Robot> {
  static Robot make(const json& params, json* resolved) {
    Robot r;
    for (const auto& [key, value] : params.items()) {
      const std::string k = "params." + key;
      if (key == "m") r.mass = finite_number(value, k);
      else if (key == "I") r.I = finite_number(value, k);
      else if (key == "Iw") r.Iw = finite_number(value, k);
      else if (key == "R") r.R = finite_number(value, k);
      else if (key == "V0") r.V0 = finite_number(value, k);
      else fail(k, "unknown parameter for system \"robot\" (known: m, I, Iw, R, V0)");
      if (key != "V0" && !(value.get<double>() > 0)) fail(k, "must be > 0, got " + show(value));
    }
    *resolved = {{"m", r.mass}, {"I", r.I}, {"Iw", r.Iw}, {"R", r.R}, {"V0", r.V0}};
    return r;
  }
};

// Call f(system) with the concrete system type named in the scene.
template <class F>
auto with_system(const json& scene, json* resolved_params, F&& f) {
  const std::string name = scene.at("system").get<std::string>();
  const json params = scene.contains("params") ? scene.at("params") : json::object();
  if (name == "particle") return f(SceneTraits<Particle>::make(params, resolved_params));
  if (name == "robot") return f(SceneTraits<Robot>::make(params, resolved_params));
  fail("system", "unknown system \"" + name + "\"");
}

}  // namespace nhi::scene_detail

namespace nhi {

// f(system, q0, v0) for a validated scene (validate_scene()).
template <class F>
auto visit_scene(const json& resolved, F&& f) {
  json params;
  return scene_detail::with_system(resolved, &params, [&](const auto& sys) {
    using S = std::decay_t<decltype(sys)>;
    const Vec<double, S::n> q0 = scene_detail::vector_of<S::n>(resolved.at("q0"), "q0");
    const Vec<double, S::n> v0 = scene_detail::vector_of<S::n>(resolved.at("v0"), "v0");
    return f(sys, q0, v0);
  });
}

}  // namespace nhi
