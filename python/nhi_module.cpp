// The Python module `nhi`: the scene runner of `nhi run` (scene.hpp) on a
// Python dict, its result with NumPy arrays.
//
//   nhi.run(scene)      the result of `nhi run` on the scene (README "Scene
//                       format", "Result format"): t, energy as 1-D arrays;
//                       q, v, constraint (and p, lambda, discrete_constraint
//                       where the method reports them) as 2-D arrays, one row
//                       per recorded point; first_integrals a dict of 1-D
//                       arrays; everything else (scene, status, failure,
//                       summary, stats, meta) as plain Python values.  The same
//                       numbers as `nhi run`, bit for bit: both call
//                       validate_scene() and run_scene() of the library.
//                       The GIL is released while the scene runs, so threads
//                       run scenes at once (stats.cpu_seconds and peak_rss_kb
//                       are then the process's, every thread's); Ctrl-C is
//                       seen only when the run returns.  A bad scene
//                       raises ValueError with the runner's message (what `nhi
//                       run` prints after "nhi: error: "); a run whose step
//                       fails returns status "failed", as the runner does.
//   nhi.systems()       the registered systems: name, n, m, params with their
//                       defaults, default q0 and v0, reversible, separable
//   nhi.methods()       every method the studies run: label, the scene keys
//                       that select it, order, symmetric, implicit, ...
//   nhi.compositions()  the compositions: name, order, stages
// (the lists of `nhi list --json`), and
//   nhi.scene_defaults() the scene keys that have defaults, with them (what
//                       validate_scene() fills in: discretization, alpha,
//                       stages, constraint, composition, start, tolerance,
//                       output_every, energy_limit).
//
// One translation unit over the compiled library: it instantiates no stepper.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <string>

#include "nhi/runner/scene.hpp"

namespace py = pybind11;
using nhi::json;

namespace {

// A Python value as JSON: dict (str keys), list or tuple, str, bool, int,
// float, None, and NumPy arrays and scalars (through tolist()).
json to_json(py::handle h, int depth) {
  if (depth > nhi::kMaxSceneDepth)
    throw nhi::SceneError("scene is nested deeper than " + std::to_string(nhi::kMaxSceneDepth) + " levels");
  if (h.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(h)) return h.cast<bool>();
  if (py::isinstance<py::int_>(h)) {
    try {
      return h.cast<long long>();
    } catch (const py::cast_error&) {
      throw nhi::SceneError("scene: the integer " + py::str(h).cast<std::string>() + " does not fit 64 bits");
    }
  }
  if (py::isinstance<py::float_>(h)) return h.cast<double>();
  if (py::isinstance<py::str>(h)) return h.cast<std::string>();
  if (py::isinstance<py::dict>(h)) {
    json o = json::object();
    for (auto item : h.cast<py::dict>()) {
      if (!py::isinstance<py::str>(item.first))
        throw nhi::SceneError("scene: a dict key must be a str, got " + py::repr(item.first).cast<std::string>());
      o[item.first.cast<std::string>()] = to_json(item.second, depth + 1);
    }
    return o;
  }
  if (py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h)) {
    json a = json::array();
    for (auto x : h) a.push_back(to_json(x, depth + 1));
    return a;
  }
  if (py::hasattr(h, "tolist") && py::hasattr(h, "dtype")) return to_json(h.attr("tolist")(), depth);
  throw nhi::SceneError("scene: a value of type '" + py::str(h.get_type().attr("__name__")).cast<std::string>() +
                        "' is not JSON (dict, list, str, int, float, bool or None)");
}

py::object to_python(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return py::none();
    case json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case json::value_t::number_integer:
      return py::int_(j.get<long long>());
    case json::value_t::number_unsigned:
      return py::int_(j.get<unsigned long long>());
    case json::value_t::number_float:
      return py::float_(j.get<double>());
    case json::value_t::string:
      return py::str(j.get<std::string>());
    case json::value_t::array: {
      py::list l;
      for (const auto& x : j) l.append(to_python(x));
      return std::move(l);
    }
    case json::value_t::object: {
      py::dict d;
      for (const auto& [k, v] : j.items()) d[py::str(k)] = to_python(v);
      return std::move(d);
    }
    default:
      throw std::runtime_error("nhi: unexpected JSON value in a result");
  }
}

// A number of a result array (a non-finite one stays NaN or inf).
double number(const json& x) { return x.is_number() ? x.get<double>() : std::nan(""); }

py::array_t<double> column(const json& a) {
  py::array_t<double> out(static_cast<py::ssize_t>(a.size()));
  auto w = out.mutable_unchecked<1>();
  for (size_t i = 0; i < a.size(); ++i) w(i) = number(a[i]);
  return out;
}

// Rows of `width` numbers as a (rows, width) array.
py::array_t<double> rows(const json& a, long width) {
  py::array_t<double> out({static_cast<py::ssize_t>(a.size()), static_cast<py::ssize_t>(width)});
  auto w = out.mutable_unchecked<2>();
  for (size_t i = 0; i < a.size(); ++i) {
    if (static_cast<long>(a[i].size()) != width) throw std::runtime_error("nhi: a result row has the wrong length");
    for (long c = 0; c < width; ++c) w(i, c) = number(a[i][c]);
  }
  return out;
}

long constraint_count(const std::string& system) {
  const json catalog = nhi::catalog();
  for (const auto& s : catalog["systems"])
    if (s["name"] == system) return s["m"].get<long>();
  throw std::runtime_error("nhi: unknown system " + system);
}

py::dict result_to_python(const json& r) {
  const long n = static_cast<long>(r["scene"]["q0"].size());
  // m from a recorded row, or (no point recorded) from the system's entry.
  const json& c = r["constraint"];
  const long m = c.empty() ? constraint_count(r["scene"]["system"].get<std::string>()) : static_cast<long>(c[0].size());
  py::dict d;
  for (const auto& [key, value] : r.items()) {
    if (key == "t" || key == "energy") {
      d[py::str(key)] = column(value);
    } else if (key == "q" || key == "v" || key == "p") {
      d[py::str(key)] = rows(value, n);
    } else if (key == "constraint" || key == "lambda" || key == "discrete_constraint") {
      d[py::str(key)] = rows(value, m);
    } else if (key == "first_integrals") {
      py::dict fi;
      for (const auto& [name, series] : value.items()) fi[py::str(name)] = column(series);
      d[py::str(key)] = fi;
    } else {
      d[py::str(key)] = to_python(value);
    }
  }
  return d;
}

py::dict run(py::handle scene) {
  json resolved;
  try {
    resolved = nhi::validate_scene(to_json(scene, 1));
  } catch (const nhi::SceneError& e) {
    throw py::value_error(e.what());
  } catch (const json::exception& e) {
    throw py::value_error(std::string("scene: ") + e.what());
  }
  json result;
  {
    py::gil_scoped_release release;
    try {
      result = nhi::run_scene(resolved);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("run: ") + e.what());
    }
  }
  return result_to_python(result);
}

// The defaults validate_scene() fills in, read off a minimal scene of the
// first registered system.
py::dict scene_defaults() {
  const json catalog = nhi::catalog();
  const json& first = catalog["systems"][0];
  const json minimal = {{"system", first["name"]}, {"q0", first["q0"]}, {"v0", first["v0"]},
                        {"method", catalog["methods"][0]["method"]}, {"h", 1.0}, {"steps", 1}};
  json resolved = nhi::validate_scene(minimal);
  py::dict d;
  for (const auto& [key, value] : resolved.items())
    if (!minimal.contains(key) && key != "params") d[py::str(key)] = to_python(value);
  return d;
}

}  // namespace

PYBIND11_MODULE(nhi, mod) {
  mod.doc() =
      "Nonholonomic integrators (Cortes & Martinez 2001 and methods after it): run a scene, list what exists.\n"
      "The scene and result formats are those of `nhi run` (README, 'Scene format', 'Result format').";
  mod.def("run", &run, py::arg("scene"),
          "Run a scene (a dict, as the JSON scene of `nhi run`) and return its result: t, energy as 1-D arrays; q, v,\n"
          "constraint (p, lambda, discrete_constraint where reported) as 2-D arrays, one row per recorded point.\n"
          "Raises ValueError for a bad scene, with the runner's message.  The GIL is released during the run.");
  mod.def(
      "systems", [] { return to_python(nhi::catalog()["systems"]); },
      "The registered systems: name, n, m, params (name: default), q0, v0, reversible, separable.");
  mod.def(
      "methods", [] { return to_python(nhi::catalog()["methods"]); },
      "Every method the studies run: label, keys (the scene keys that select it), method, composition, order,\n"
      "symmetric, implicit, adaptive, composable, group, style, own (the method's own scene keys, declared by\n"
      "the method) and every method's key (discretization, alpha, stages, constraint, ...: null where not its own).");
  mod.def(
      "compositions", [] { return to_python(nhi::catalog()["compositions"]); },
      "The compositions of a symmetric method: name, order, stages.");
  mod.def("scene_defaults", &scene_defaults,
          "The optional scene keys and their defaults (discretization, alpha, stages, constraint, composition, start,\n"
          "tolerance, output_every, energy_limit).");
}
