// Study: the growth of the global (phase) error over long times on the
// integrable scenes.  On an integrable system a method whose energy and first
// integrals stay bounded makes an error in the frequencies of O(h^p), so its
// phase error grows linearly in t; a method whose invariants drift makes the
// frequencies drift too, and the phase error grows quadratically (Hairer,
// Lubich & Wanner, "Geometric Numerical Integration", 2nd ed., X.3; for
// reversible nonholonomic integrators Modin & Verdier 2020).
// For every registered scene that declares itself integrable, every fixed-step
// "main" method runs kSteps steps of a quarter of the scene file's h from its state; the
// error max_i |q_i(t) - q_ref,i(t)| is taken at ~10 log-spaced checkpoints per
// decade against the exact solution where the system has one, else CVODE at
// rtol = atol = 1e-13 on the same grid.  The growth exponent is the log-log
// slope of the error over the last two decades [T/100, T], using only
// checkpoints where the error is above kFloor (the reference's own error) and
// below kSaturation (a phase error of O(1) no longer grows).
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr long kSteps = 40000;
// A quarter of the scene file's h: at the scene's own h a second-order
// method's phase error reaches O(1) (where it stops growing) within 10^3
// time units on the paper's scenes, before the growth can be read.
constexpr double kStepFraction = 0.25;
constexpr double kFloor = 1e-9;
constexpr double kSaturation = 0.1;

std::vector<long> checkpoints(long steps) {
  std::vector<long> out;
  for (double x = 0; x <= std::log10(double(steps)) + 1e-9; x += 0.1) {
    const long k = std::lround(std::pow(10.0, x));
    if (out.empty() || k > out.back()) out.push_back(k);
  }
  if (out.back() != steps) out.push_back(steps);
  return out;
}

// q at the checkpoints of a run of spec (an empty vector where it failed).
template <class S>
std::vector<Vec<double, S::n>> q_at(const S& sys, const nhi::MethodSpec& spec, const Vec<double, S::n>& q0,
                                    const Vec<double, S::n>& v0, double h, const std::vector<long>& ks,
                                    nhi::RunReport* rep) {
  std::vector<Vec<double, S::n>> out;
  size_t next = 0;
  *rep = nhi::run_method(sys, spec, q0, v0, h, ks.back(), [&](const nhi::Sample<S::n, S::m>& s) {
    if (next < ks.size() && s.k == ks[next]) {
      out.push_back(s.q);
      ++next;
    }
    return true;
  });
  return out;
}

json num(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

// Systems that declare `integrable = true` (system.hpp).
template <class S, class = void>
struct declares_integrable : std::false_type {};
template <class S>
struct declares_integrable<S, std::enable_if_t<S::integrable>> : std::true_type {};

}  // namespace

int main(int argc, char** argv) {
  const study::Options opt = study::parse(argc, argv, "Growth of the global error on the integrable scenes");
  const std::vector<nhi::StudyMethod> all_methods =
      study::methods([](const nhi::StudyMethod& m) { return m.fixed_step() && m.group == "main"; });
  const std::vector<long> ks = checkpoints(kSteps);
  json result = {{"study", "global_error"},
                 {"config",
                  {{"steps", kSteps},
                   {"h", "per scene: a quarter of the scene file's h"},
                   {"reference", "the exact solution where the system has one, else CVODE rtol = atol = 1e-13"},
                   {"error", "max_i |q_i(t) - q_ref,i(t)| at ~10 log-spaced checkpoints per decade"},
                   {"growth_exponent",
                    "least-squares log-log slope of the error over [T/100, T], checkpoints with kFloor < error < "
                    "kSaturation"},
                   {"floor", kFloor},
                   {"saturation", kSaturation}}}};
  for (const std::string& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    const bool integrable = nhi::visit_scene(sc, [](const auto& sys, const auto&, const auto&) {
      return declares_integrable<std::decay_t<decltype(sys)>>::value;
    });
    if (!integrable) continue;
    const double h = kStepFraction * sc["h"].get<double>();
    const json scene_out = nhi::visit_scene(sc, [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      const std::vector<nhi::StudyMethod> methods = study::on<S>(all_methods);
      // The reference on the checkpoints.
      std::vector<Vec<double, S::n>> ref;
      std::string reference = "cvode 1e-13";
      bool exact = false;
      if constexpr (nhi::has_exact_solution<S>::value) {
        Vec<double, S::n> q, v;
        exact = sys.exact_solution(q0, v0, 0.0, &q, &v);
        if (exact) {
          reference = "exact";
          for (long k : ks) {
            sys.exact_solution(q0, v0, double(k) * h, &q, &v);
            ref.push_back(q);
          }
        }
      }
      if (!exact) {
        nhi::MethodSpec rs = nhi::spec_of(nhi::ReferenceMethod::name);
        rs.tolerance = 1e-13;
        nhi::RunReport rep;
        ref = q_at(sys, rs, q0, v0, h, ks, &rep);
        if (!rep.ok) throw std::runtime_error(name + ": the reference solution failed: " + rep.reason);
      }
      study::Cells cells;
      cells.label = "global error " + name;
      cells.count = methods.size();
      cells.cost = [&](size_t i) { return double(kSteps) * study::step_weight(methods[i].spec); };
      cells.name = [&](size_t i) { return name + " " + methods[i].label(); };
      cells.run = [&](size_t i) {
        nhi::RunReport rep;
        const auto qs = q_at(sys, methods[i].spec, q0, v0, h, ks, &rep);
        std::vector<double> t, err, ft, fe;
        for (size_t j = 0; j < qs.size(); ++j) {
          t.push_back(double(ks[j]) * h);
          err.push_back((qs[j] - ref[j]).cwiseAbs().maxCoeff());
          if (double(ks[j]) >= kSteps / 100.0 && err.back() > kFloor && err.back() < kSaturation) {
            ft.push_back(t.back());
            fe.push_back(err.back());
          }
        }
        json j = {{"label", methods[i].label()}, {"t", t}, {"error", err}, {"fit_points", ft.size()}};
        j["growth_exponent"] = ft.size() >= 3 ? num(nhi::loglog_slope(ft, fe)) : json(nullptr);
        j.update(study::report_json(rep, h));
        return j;
      };
      return json{{"h", h},
                  {"T", h * double(kSteps)},
                  {"reference", reference},
                  {"reversible", nhi::is_reversible<S>::value},
                  {"methods", study::map_cells(opt, cells)}};
    });
    result["scenes"][name] = scene_out;
  }
  return study::finish(opt, result);
}
