// Scene plumbing shared by the runner and the study executables: JSON value
// checks that name the key, per-system parameter parsing from each system's
// parameter table, and with_system()/visit_scene(), which call a generic lambda
// with the concrete registered system (systems/registry.hpp) a scene names.
#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "nhi/roles/core.hpp"
#include "nhi/runner/scene.hpp"
#include "nhi/systems/registry.hpp"

namespace nhi::scene_detail {

[[noreturn]] inline void fail(const std::string& key, const std::string& problem) {
  throw SceneError("scene key '" + key + "': " + problem);
}

// A value for a message, at most 60 characters.  A non-finite number is
// written NaN, Infinity or -Infinity (json::dump() would write null, which
// reads as a missing value: a scene handed over from Python can hold one).
// Invalid UTF-8 (possible in a --set string value, which is not parsed as
// JSON) is replaced, not thrown on: found by make fuzz.
inline void append_shown(std::string& out, const json& j, size_t limit) {
  if (out.size() > limit) return;  // enough for the message: also bounds the recursion
  if (j.is_number_float()) {
    const double x = j.get<double>();
    if (std::isnan(x)) {
      out += "NaN";
      return;
    }
    if (std::isinf(x)) {
      out += x > 0 ? "Infinity" : "-Infinity";
      return;
    }
  }
  if (j.is_array() && !j.empty()) {
    out += '[';
    bool first = true;
    for (const auto& e : j) {
      if (out.size() > limit) return;
      if (!first) out += ',';
      first = false;
      append_shown(out, e, limit);
    }
    out += ']';
    return;
  }
  if (j.is_object() && !j.empty()) {
    out += '{';
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (out.size() > limit) return;
      if (!first) out += ',';
      first = false;
      out += json(it.key()).dump(-1, ' ', false, json::error_handler_t::replace) + ':';
      append_shown(out, it.value(), limit);
    }
    out += '}';
    return;
  }
  out += j.dump(-1, ' ', false, json::error_handler_t::replace);
}

inline std::string show(const json& j) {
  std::string s;
  append_shown(s, j, 60);
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// Damerau-Levenshtein distance (optimal string alignment: insertions,
// deletions, substitutions and transpositions of two adjacent characters).
inline size_t edit_distance(const std::string& a, const std::string& b) {
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<size_t>> d(n + 1, std::vector<size_t>(m + 1, 0));
  for (size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (size_t k = 0; k <= m; ++k) d[0][k] = k;
  for (size_t i = 1; i <= n; ++i)
    for (size_t k = 1; k <= m; ++k) {
      const size_t cost = a[i - 1] == b[k - 1] ? 0 : 1;
      d[i][k] = std::min({d[i - 1][k] + 1, d[i][k - 1] + 1, d[i - 1][k - 1] + cost});
      if (i > 1 && k > 1 && a[i - 1] == b[k - 2] && a[i - 2] == b[k - 1])
        d[i][k] = std::min(d[i][k], d[i - 2][k - 2] + 1);
    }
  return d[n][m];
}

// "" or `; did you mean "x"?`, x the name nearest to s (ignoring case) within
// a Damerau-Levenshtein distance of max(1, |s| / 3); the first such name on a tie.
inline std::string did_you_mean(const std::string& s, const std::vector<std::string>& names) {
  auto lower = [](std::string x) {
    for (char& c : x) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return x;
  };
  const size_t limit = std::max<size_t>(1, s.size() / 3);
  const std::string ls = lower(s);
  const std::string* best = nullptr;
  size_t best_d = limit + 1;
  for (const std::string& name : names) {
    if (name == s) return "";
    // Lengths further apart than the limit cannot be within it (and a long
    // input costs no quadratic table).
    if ((name.size() > s.size() ? name.size() - s.size() : s.size() - name.size()) > limit) continue;
    const size_t d = edit_distance(ls, lower(name));
    if (d < best_d) best_d = d, best = &name;
  }
  return best ? "; did you mean \"" + *best + "\"?" : "";
}

// Refuse an unknown scene key, suggesting the nearest known one
// ("scene key 'stepz': unknown key; did you mean \"steps\"?").
[[noreturn]] inline void unknown_key(const std::string& key, const std::vector<std::string>& known_keys) {
  fail(key, "unknown key" + did_you_mean(key, known_keys));
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
    if (!std::isfinite(x) || x != std::floor(x)) fail(key, "must be an integer, got " + show(j));
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
    fail(key, "unknown value " + show(j) + " (expected one of " + list + ")" + did_you_mean(s, names));
  return s;
}

template <int N>
Vec<double, N> vector_of(const json& j, const std::string& key) {
  if (!j.is_array()) fail(key, "must be an array of " + std::to_string(N) + " numbers, got " + show(j));
  if (j.size() != N)
    fail(key, "must have " + std::to_string(N) + " entries for this system, got " + std::to_string(j.size()));
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

// A system from the scene's `params`: its parameter table (system.hpp, Param)
// gives the names, the defaults (the members' initial values) and the checks.
// *resolved gets every parameter with its value.
template <class S>
S make_system(const json& params, json* resolved) {
  S sys;
  const auto table = S::parameters();
  for (const auto& [key, value] : params.items()) {
    const std::string k = "params." + key;
    const Param<S>* p = nullptr;
    for (const auto& entry : table)
      if (key == entry.name) p = &entry;
    if (!p) {
      std::string known;
      std::vector<std::string> names;
      for (const auto& entry : table) {
        known += (known.empty() ? "" : ", ") + std::string(entry.name);
        names.emplace_back(entry.name);
      }
      fail(k, "unknown parameter for system \"" + std::string(S::name) + "\" (known: " + known + ")" +
                  did_you_mean(key, names));
    }
    sys.*(p->member) = finite_number(value, k);
    if (p->check == ParamCheck::kPositive && !(sys.*(p->member) > 0)) fail(k, "must be > 0, got " + show(value));
    if (p->check == ParamCheck::kNonNegative && !(sys.*(p->member) >= 0)) fail(k, "must be >= 0, got " + show(value));
  }
  *resolved = json::object();
  for (const auto& entry : table) (*resolved)[entry.name] = sys.*(entry.member);
  return sys;
}

// Call f(system) with the concrete registered system named in the scene.
template <class F>
auto with_system(const json& scene, json* resolved_params, F&& f) {
  const std::string name = scene.at("system").get<std::string>();
  const json params = scene.contains("params") ? scene.at("params") : json::object();
  using R = decltype(f(std::declval<const typename Front<Systems>::type&>()));
  std::optional<R> out;
  for_each_type(Systems{}, [&](auto tag) {
    using S = typename decltype(tag)::type;
    if (!out && name == S::name) out.emplace(f(make_system<S>(params, resolved_params)));
  });
  if (!out) fail("system", "unknown system " + show(json(name)) + did_you_mean(name, system_names()));
  return std::move(*out);
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
