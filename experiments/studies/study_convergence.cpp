// Study 1: convergence order over alpha.
// Global error max_i |q_i(T) - q_ref,i(T)| at T = 10 against the exact solution
// where the system has one (the sleigh), else the reference solution (CVODE,
// tol 1e-13), over h = 0.2 / 2^j, j = 0..8, on every registered
// scene, for every fixed-step study method (nhi::study_methods(): the DLA with
// alpha = 0, 1/4, 1/2, 3/4, 1, the symmetric DLA with alpha = 0, 1/4, RK4, ...);
// plus the isolation runs that show what limits the order for
// alpha != 1/2 (L_d and omega_d of different alpha, and the start p_0).
// Fitted order: least-squares slope over the four finest h whose error is above
// 1e-10 (the asymptotic regime; coarse h are pre-asymptotic for RK4 on the robot),
// less finest points that sit on a higher floor (fit.hpp, drop_floor_tail: the
// composed methods' accumulated solves on the robot and the sleigh).  Where the
// reference solution's own error is larger than 1e-11 (estimated as its distance
// to CVODE at tol 1e-14), the floor is 3 times that error: the rigid bodies'
// references are off by 6e-11 (the sphere) and 1.8e-10 (the Suslov body, whose
// turnover amplifies every error) at T = 10.
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr double kT = 10.0;
constexpr double kFloor = 1e-10;
constexpr size_t kFitPoints = 4;  // the finest h with error above the floor

struct Variant {
  std::string label, family;  // family: alpha, symmetric, rk4, isolation
  double alpha = 0.5;
  std::function<json(double h)> error_at;  // returns {"error", "cpu_seconds", "status"}
  double weight = 1.0;                     // study::step_weight: estimated cost of a step
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

// Where the system's motion has a closed-form limit (the sleigh), the errors
// in the limit speed and heading of a run of spec to the settle time.
template <class S>
void add_limit_errors(const S& sys, const nhi::MethodSpec& spec, const Vec<double, S::n>& q0,
                      const Vec<double, S::n>& v0, double h, json* j) {
  if constexpr (study::has_limit_motion<S>::value) {
    double speed, heading, settle;
    if ((*j)["status"] != "ok" || !sys.limit_motion(q0, v0, &speed, &heading, &settle)) return;
    Vec<double, S::n> q = q0, v = v0;
    double t = 0;
    const nhi::RunReport rep = nhi::run_method(sys, spec, q0, v0, h, std::lround(std::ceil(settle / h)),
                                               [&](const nhi::Sample<S::n, S::m>& s) {
                                                 q = s.q, v = s.v, t = s.t;
                                                 return true;
                                               });
    if (rep.ok) study::add_limit_errors(sys, q0, v0, t, q, v, j);
  }
}

template <class S>
std::vector<Variant> variants(const S& sys, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                              const Vec<double, S::n>& qref) {
  std::vector<Variant> out;
  auto steps = [](double h) { return std::lround(kT / h); };
  for (const nhi::StudyMethod& m : study::on<S>(study::methods(study::fixed_step))) {
    const nhi::MethodSpec spec = m.spec;
    const std::string family = spec.kind == "dla" ? spec.discretization : spec.kind;
    out.push_back({m.label(), family, spec.alpha,
                   [=, &sys](double h) {
                     json j = measure<S>(
                         qref, [&](auto&& obs) { return nhi::run_method(sys, spec, q0, v0, h, steps(h), obs); });
                     add_limit_errors(sys, spec, q0, v0, h, &j);
                     return j;
                   },
                   study::step_weight(spec)});
  }
  // Isolation: L_d^{aL} with omega_d^{aw}, started from p_0 = dL/dqdot or from the
  // consistent p_0 = dL/dqdot + h (aL - 1/2) dL/dq.
  for (double a : {0.0, 0.25}) {
    struct Iso {
      double aL, aw;
      bool consistent;
      const char* name;
    };
    for (const Iso& iso :
         {Iso{a, 0.5, false, "L_d^a + omega_d^1/2, p0 = dL/dv"},
          Iso{a, 0.5, true, "L_d^a + omega_d^1/2, consistent p0"},
          Iso{0.5, a, false, "L_d^1/2 + omega_d^a, p0 = dL/dv"}, Iso{a, a, true, "L_d^a + omega_d^a, consistent p0"}}) {
      char label[96];
      std::snprintf(label, sizeof label, "%s (a=%g)", iso.name, a);
      out.push_back(
          {label, "isolation", a,
           [=, &sys](double h) {
             Vec<double, S::n> Lq, Lv;
             nhi::autodiff_partials(sys, q0, v0, &Lq, &Lv);
             const Vec<double, S::n> p0 = iso.consistent ? Vec<double, S::n>(Lv + h * (iso.aL - 0.5) * Lq) : Lv;
             nhi::DlaStepper<S, nhi::SplitDiscretization> st(sys, nhi::SplitDiscretization{iso.aL, iso.aw});
             st.start_momentum(p0);
             return measure<S>(qref, [&](auto&& obs) { return nhi::integrate(st, q0, v0, h, steps(h), obs); });
           },
           study::step_weight(nhi::MethodSpec{})});
    }
  }
  return out;
}

json fit(const std::vector<double>& hs, const json& runs, double floor = kFloor) {
  std::vector<double> errs;
  for (const json& r : runs) errs.push_back(r["status"] == "ok" ? r["error"].get<double>() : std::nan(""));
  const nhi::OrderFit f = nhi::fit_order(hs, errs, floor, kFitPoints, /*drop_floor_tail=*/true);
  json local = json::array();
  for (const auto& o : f.local) local.push_back(o ? json(*o) : json(nullptr));
  return {{"local_orders", local}, {"fit_h", f.h}, {"fitted_order", f.order ? json(*f.order) : json(nullptr)}};
}

}  // namespace

int main(int argc, char** argv) {
  const study::Options opt = study::parse(argc, argv, "Convergence order over alpha, every scene");
  std::vector<double> hs;
  for (int j = 0; j <= 8; ++j) hs.push_back(0.2 / (1 << j));
  json result = {
      {"study", "convergence"},
      {"config",
       {{"T", kT},
        {"h", hs},
        {"reference", "per scene: the exact solution where the system has one, else CVODE Adams rtol = atol = 1e-13"},
        {"error", "max_i |q_i(T) - q_ref,i(T)|"},
        {"fit",
         "least squares of log error on log h over the 4 finest h with error above the floor (1e-10, or 3 x the "
         "reference's own error where that is larger: its distance to CVODE at tol 1e-14), after dropping finest "
         "points on a higher floor (while the last local order differs by > 0.5 from the one before it)"}}}};
  for (const std::string& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    json scene_out = nhi::visit_scene(sc, [&](const auto& sys, const auto& q0, const auto& v0) {
      using S = std::decay_t<decltype(sys)>;
      // The exact solution where the system has one (the sleigh with g = 0, the
      // knife edge), else the reference solution.
      Vec<double, S::n> qref = Vec<double, S::n>::Zero(), vexact;
      bool exact = false;
      if constexpr (nhi::has_exact_solution<S>::value) exact = sys.exact_solution(q0, v0, kT, &qref, &vexact);
      double reference_error = 0;
      if (!exact) {
        qref = study::reference_q(sys, q0, v0, kT, 1e-13);
        reference_error = (qref - study::reference_q(sys, q0, v0, kT, 1e-14)).cwiseAbs().maxCoeff();
      }
      const double floor = std::max(kFloor, 3 * reference_error);
      const auto vs = variants(sys, q0, v0, qref);
      study::Cells cells;
      cells.label = "convergence " + name;
      cells.count = vs.size() * hs.size();
      cells.run = [&](size_t i) { return vs[i / hs.size()].error_at(hs[i % hs.size()]); };
      cells.cost = [&](size_t i) { return kT / hs[i % hs.size()] * vs[i / hs.size()].weight; };
      cells.name = [&](size_t i) { return vs[i / hs.size()].label + " at h = " + std::to_string(hs[i % hs.size()]); };
      const std::vector<json> runs = study::map_cells(opt, cells);
      json methods = json::array();
      for (size_t v = 0; v < vs.size(); ++v) {
        json rs = json::array(), errs = json::array();
        for (size_t j = 0; j < hs.size(); ++j) {
          rs.push_back(runs[v * hs.size() + j]);
          errs.push_back(runs[v * hs.size() + j].value("error", std::nan("")));
        }
        json m = {{"label", vs[v].label}, {"family", vs[v].family},
                  {"alpha", vs[v].alpha}, {"h", hs},
                  {"error", errs},        {"runs", rs}};
        m.update(fit(hs, rs, floor));
        // The limit speed's and heading's errors (the sleigh) and their fitted orders.
        for (const char* key : {"limit_speed_error", "limit_heading_error"}) {
          if (!rs[0].contains(key)) continue;
          json e = json::array(), as_runs = json::array();
          for (const json& r : rs) {
            e.push_back(r.contains(key) ? r[key] : json(nullptr));
            as_runs.push_back(r.contains(key) ? json{{"status", "ok"}, {"error", r[key]}} : json{{"status", "failed"}});
          }
          m[key] = e;
          m[std::string(key) + "_order"] = fit(hs, as_runs)["fitted_order"];
        }
        methods.push_back(m);
      }
      return json{{"scene", sc},
                  {"reference_q", study::to_json<S::n>(qref)},
                  {"reference", exact ? "exact solution (closed form)" : "CVODE Adams rtol = atol = 1e-13"},
                  {"reference_error", reference_error},
                  {"floor", floor},
                  {"methods", methods}};
    });
    result["scenes"][name] = scene_out;
  }
  return study::finish(opt, result);
}
