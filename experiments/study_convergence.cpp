// Study 1: convergence order over alpha.
// Global error max_i |q_i(T) - q_ref,i(T)| at T = 10 against CVODE (tol 1e-13),
// over h = 0.2 / 2^j, j = 0..8, on both scenes, for the DLA with the alpha
// discretization (alpha = 0, 1/4, 1/2, 3/4, 1), the symmetric one (alpha = 0, 1/4)
// and RK4; plus the isolation runs that show what limits the order for
// alpha != 1/2 (L_d and omega_d of different alpha, and the start p_0).
// Fitted order: least-squares slope over the four finest h whose error is above
// 1e-10 (the asymptotic regime; coarse h are pre-asymptotic for RK4 on the robot).
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr double kT = 10.0;
constexpr double kFloor = 1e-10;
constexpr size_t kFitPoints = 4;  // the finest h with error above the floor

std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

struct Variant {
  std::string label, family;  // family: alpha, symmetric, rk4, isolation
  double alpha = 0.5;
  std::function<json(double h)> error_at;  // returns {"error", "cpu_seconds", "status"}
};

// Error of one run that ends at q(T).
template <class S, class Run>
json measure(const Vec<double, S::n>& qref, Run&& run) {
  Vec<double, S::n> q = Vec<double, S::n>::Zero();
  const double c0 = study::thread_cpu_seconds();
  const nhi::RunReport rep = run([&](const nhi::Sample<S::n, S::m>& s) {
    q = s.q;
    return true;
  });
  const double cpu = study::thread_cpu_seconds() - c0;
  if (!rep.ok) return {{"status", "failed"}, {"reason", rep.reason}, {"cpu_seconds", cpu}};
  return {{"status", "ok"}, {"error", (q - qref).cwiseAbs().maxCoeff()}, {"cpu_seconds", cpu}};
}

template <class S>
std::vector<Variant> variants(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                              const Vec<double, S::n>& qref) {
  std::vector<Variant> out;
  auto steps = [](double h) { return std::lround(kT / h); };
  for (double a : {0.0, 0.25, 0.5, 0.75, 1.0})
    out.push_back({"DLA alpha=" + num(a), "alpha", a,
                   [=, &sys](double h) {
                     nhi::MethodSpec m{"dla", "alpha", a};
                     return measure<S>(qref, [&](auto&& obs) { return nhi::run_method(sys, m, q0, v0, h, steps(h), obs); });
                   }});
  for (double a : {0.0, 0.25})
    out.push_back({"symmetric alpha=" + num(a), "symmetric", a,
                   [=, &sys](double h) {
                     nhi::MethodSpec m{"dla", "symmetric", a};
                     return measure<S>(qref, [&](auto&& obs) { return nhi::run_method(sys, m, q0, v0, h, steps(h), obs); });
                   }});
  out.push_back({"RK4", "rk4", 0.0, [=, &sys](double h) {
                   nhi::MethodSpec m{"rk4"};
                   return measure<S>(qref, [&](auto&& obs) { return nhi::run_method(sys, m, q0, v0, h, steps(h), obs); });
                 }});
  // Isolation: L_d^{aL} with omega_d^{aw}, started from p_0 = dL/dqdot or from the
  // consistent p_0 = dL/dqdot + h (aL - 1/2) dL/dq.
  for (double a : {0.0, 0.25}) {
    struct Iso { double aL, aw; bool consistent; const char* name; };
    for (const Iso& iso : {Iso{a, 0.5, false, "L_d^a + omega_d^1/2, p0 = dL/dv"},
                           Iso{a, 0.5, true, "L_d^a + omega_d^1/2, consistent p0"},
                           Iso{0.5, a, false, "L_d^1/2 + omega_d^a, p0 = dL/dv"},
                           Iso{a, a, true, "L_d^a + omega_d^a, consistent p0"}}) {
      char label[96];
      std::snprintf(label, sizeof label, "%s (a=%g)", iso.name, a);
      out.push_back({label, "isolation", a, [=, &sys](double h) {
                       Vec<double, S::n> Lq, Lv;
                       nhi::autodiff_partials(sys, q0, v0, &Lq, &Lv);
                       const Vec<double, S::n> p0 = iso.consistent ? Vec<double, S::n>(Lv + h * (iso.aL - 0.5) * Lq) : Lv;
                       const nhi::DlaStepper<S, nhi::SplitDiscretization> st(sys, nhi::SplitDiscretization{iso.aL, iso.aw}, h);
                       return measure<S>(qref, [&](auto&& obs) { return nhi::integrate_dla_from(st, q0, v0, p0, steps(h), obs); });
                     }});
    }
  }
  return out;
}

json fit(const std::vector<double>& hs, const json& runs) {
  std::vector<double> x, y;
  json local = json::array();
  for (size_t j = 0; j < hs.size(); ++j) {
    const bool ok = runs[j]["status"] == "ok";
    const double e = ok ? runs[j]["error"].get<double>() : 0.0;
    if (ok && e > kFloor) {
      x.push_back(hs[j]);
      y.push_back(e);
    }
    if (j > 0 && ok && runs[j - 1]["status"] == "ok" && e > kFloor)
      local.push_back(std::log(runs[j - 1]["error"].get<double>() / e) / std::log(hs[j - 1] / hs[j]));
    else if (j > 0)
      local.push_back(nullptr);
  }
  if (x.size() > kFitPoints) {  // keep the finest
    x.erase(x.begin(), x.end() - kFitPoints);
    y.erase(y.begin(), y.end() - kFitPoints);
  }
  json f = {{"local_orders", local}, {"fit_h", x}};
  f["fitted_order"] = x.size() >= 3 ? json(nhi::loglog_slope(x, y)) : json(nullptr);
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const study::Options opt = study::parse(argc, argv, "Convergence order over alpha, both scenes");
  study::install_signal_handlers();
  std::vector<double> hs;
  for (int j = 0; j <= 8; ++j) hs.push_back(0.2 / (1 << j));
  json result = {{"study", "convergence"},
                 {"config", {{"T", kT}, {"h", hs}, {"reference", "CVODE Adams rtol = atol = 1e-13"},
                             {"error", "max_i |q_i(T) - q_ref,i(T)|"},
                             {"fit", "least squares of log error on log h over the 4 finest h with error > 1e-10"}}}};
  for (const std::string name : {"particle", "robot"}) {
    const json sc = study::scene(opt, name);
    json scene_out = nhi::visit_scene(sc, [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      const Vec<double, S::n> qref = study::reference_q(sys, q0, v0, kT, 1e-13);
      const auto vs = variants(sys, q0, v0, qref);
      std::vector<json> runs(vs.size() * hs.size());
      study::Progress progress("convergence " + name, static_cast<long>(runs.size()));
      study::parallel_for(runs.size(), opt.threads, [&](size_t i) {
        runs[i] = vs[i / hs.size()].error_at(hs[i % hs.size()]);
      }, &progress);
      json methods = json::array();
      for (size_t v = 0; v < vs.size(); ++v) {
        json rs = json::array(), errs = json::array();
        for (size_t j = 0; j < hs.size(); ++j) {
          rs.push_back(runs[v * hs.size() + j]);
          errs.push_back(runs[v * hs.size() + j].value("error", std::nan("")));
        }
        json m = {{"label", vs[v].label}, {"family", vs[v].family}, {"alpha", vs[v].alpha},
                  {"h", hs}, {"error", errs}, {"runs", rs}};
        m.update(fit(hs, rs));
        methods.push_back(m);
      }
      return json{{"scene", sc}, {"reference_q", study::to_json<S::n>(qref)}, {"methods", methods}};
    });
    result["scenes"][name] = scene_out;
  }
  return study::finish(opt, result);
}
