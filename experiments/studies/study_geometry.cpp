// Study 5: the geometry of the discrete flow, as series for figures.
//  - "momentum": Theorem 5.3 (eq. 24) along DLA runs, the discrete nonholonomic
//    momentum J_k and J_0 + sum of the right-hand sides of eq. (24), with the
//    per-step residual: the particle with V = y^2 (kx = 0) and the robot with SE(2).
//  - "extrinsic": the robot with its circles as unit vectors (holonomic
//    constraints, eq. 17; systems/robot_extrinsic.hpp) against the intrinsic
//    DLA: energy and constraint along a run, and errors at T = 2 over h.
//  - "holonomic": Remark 3.3 on the circle, the omega-DLA and the eq.-17 (g) DLA:
//    energy and the radius along a run.
//  - "reversibility": every fixed-step method's symmetry and rho-reversibility
//    defects (reversibility.hpp) at each scene file's h, the largest over
//    kStates states on the constraint along an RK4 run from the scene's state.
// Initial states come from the scene files; the tests (tests/test_geometry.cpp,
// tests/test_embedding.cpp) assert what these series show.
#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/readings/reversibility.hpp"
#include "nhi/systems/circle.hpp"
#include "nhi/systems/robot_extrinsic.hpp"
#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

// Eq. (24) along a DLA run of S (which has nonholonomic_momentum / momentum_equation_rhs).
template <class S>
json momentum_run(const S& sys, double alpha, double h, long steps, const Vec<double, S::n>& q0,
                  const Vec<double, S::n>& v0) {
  nhi::DlaStepper<S, nhi::AlphaDiscretization> st(sys, nhi::AlphaDiscretization{alpha});
  std::vector<Vec<double, S::n>> qs, ps;
  const nhi::RunReport rep = nhi::integrate(st, q0, v0, h, steps, [&](const nhi::Sample<S::n, S::m>& s) {
    qs.push_back(s.q);
    ps.push_back(s.p);
    return true;
  });
  std::vector<double> t, J, Jsum, residual;
  double acc = S::nonholonomic_momentum(qs[0], ps[0]);
  for (size_t k = 0; k < qs.size(); ++k) {
    t.push_back(k * h);
    J.push_back(S::nonholonomic_momentum(qs[k], ps[k]));
    Jsum.push_back(acc);
    if (k + 1 < qs.size()) {
      const double rhs = S::momentum_equation_rhs(qs[k], qs[k + 1], ps[k + 1]);
      acc += rhs;
      residual.push_back(std::abs(S::nonholonomic_momentum(qs[k + 1], ps[k + 1]) - J.back() - rhs));
    }
  }
  json j = {{"alpha", alpha},
            {"h", h},
            {"t", t},
            {"J", J},
            {"J0_plus_sum_rhs", Jsum},
            {"residual", residual},
            {"max_residual", *std::max_element(residual.begin(), residual.end())}};
  j["status"] = rep.ok ? "ok" : "failed";
  if (!rep.ok) j["reason"] = rep.reason;
  return j;
}

constexpr int kStates = 8;         // states per scene for the map defects
constexpr long kStateStride = 25;  // steps of h between them

// The map defects of every fixed-step method on one scene (reversibility.hpp).
json reversibility_of(const json& scene) {
  return nhi::visit_scene(scene, [&](const auto& sys, const auto& q0, const auto& v0) {
    using S = std::decay_t<decltype(sys)>;
    const double h = scene["h"].get<double>();
    std::vector<Vec<double, S::n>> qs, vs;
    nhi::run_method(sys, nhi::spec_of("rk4"), q0, v0, h, kStates * kStateStride, [&](const nhi::Sample<S::n, S::m>& s) {
      if (s.k % kStateStride == 0 && qs.size() < size_t(kStates)) {
        qs.push_back(s.q);
        vs.push_back(nhi::project_to_constraint(sys, s.q, s.v));
      }
      return true;
    });
    json methods = json::array();
    for (const nhi::StudyMethod& m : study::on<S>(study::methods(study::fixed_step))) {
      const nhi::MethodTraits t = nhi::method_traits(sys, m.spec);
      nhi::MapDefects worst;
      for (size_t i = 0; i < qs.size(); ++i) {
        const nhi::MapDefects d = nhi::map_defects(sys, m.spec, qs[i], vs[i], h);
        worst.ok = worst.ok && d.ok;
        worst.symmetry_q = std::max(worst.symmetry_q, d.symmetry_q);
        worst.symmetry_phase = std::max(worst.symmetry_phase, d.symmetry_phase);
        worst.reversibility_q = std::max(worst.reversibility_q, d.reversibility_q);
        worst.reversibility_phase = std::max(worst.reversibility_phase, d.reversibility_phase);
      }
      methods.push_back({{"label", m.label()},
                         {"symmetric", t.symmetric},
                         {"symmetric_in_phase", t.symmetric_in_phase},
                         {"status", worst.ok ? "ok" : "failed"},
                         {"symmetry_defect_q", worst.symmetry_q},
                         {"symmetry_defect_phase", worst.symmetry_phase},
                         {"reversibility_defect_q", worst.reversibility_q},
                         {"reversibility_defect_phase", worst.reversibility_phase}});
    }
    return json{{"h", h}, {"reversible", nhi::is_reversible<S>::value}, {"states", qs.size()}, {"methods", methods}};
  });
}

struct ChartRun {
  std::vector<Vec<double, 4>> q, v;
  double max_g = 0;
  bool ok = true;
};

ChartRun robot_run(bool extrinsic, double h, long steps, const Vec<double, 4>& q0, const Vec<double, 4>& v0) {
  ChartRun r;
  const nhi::AlphaDiscretization mid{0.5};
  if (!extrinsic) {
    nhi::DlaStepper<nhi::Robot, nhi::AlphaDiscretization> st(nhi::Robot{}, mid);
    r.ok = nhi::integrate(st, q0, v0, h, steps, [&](const nhi::Sample<4, 2>& s) {
             r.q.push_back(s.q);
             r.v.push_back(s.v);
             return true;
           }).ok;
  } else {
    using X = nhi::RobotExtrinsic;
    const X sys;
    nhi::DlaStepper<X, nhi::AlphaDiscretization> st(sys, mid);
    Vec<double, 4> near = q0;
    r.ok = nhi::integrate(st, X::embed(q0), X::embed_velocity(q0, v0), h, steps, [&](const nhi::Sample<6, 2>& s) {
             near = X::chart(s.q, near);
             r.q.push_back(near);
             r.v.push_back(X::chart_velocity(s.q, s.v));
             r.max_g = std::max(r.max_g, sys.g<double>(s.q).cwiseAbs().maxCoeff());
             return true;
           }).ok;
  }
  return r;
}

json robot_series(const ChartRun& r, double h, const Vec<double, 4>& q0, const Vec<double, 4>& v0) {
  const nhi::Robot sys;
  const double E0 = nhi::energy(sys, q0, v0);
  std::vector<double> t, dE, c;
  double maxE = 0, maxc = 0;
  for (size_t k = 0; k < r.q.size(); ++k) {
    t.push_back(k * h);
    dE.push_back(nhi::energy(sys, r.q[k], r.v[k]) - E0);
    c.push_back(nhi::constraint_values(sys, r.q[k], r.v[k]).cwiseAbs().maxCoeff());
    maxE = std::max(maxE, std::abs(dE.back()));
    maxc = std::max(maxc, c.back());
  }
  return {{"t", t},
          {"energy_error", dE},
          {"constraint", c},
          {"max_abs_energy_error", maxE},
          {"max_abs_constraint", maxc},
          {"max_abs_g", r.max_g},
          {"status", r.ok ? "ok" : "failed"}};
}

}  // namespace

int main(int argc, char** argv) {
  const study::Options o = study::parse(argc, argv, "Geometry of the discrete flow: eq. 24, eq. 17, Remark 3.3");
  json out;
  try {
    const json ps = study::scene(o, "particle"), rs = study::scene(o, "robot");
    const Vec<double, 3> pq0 = nhi::scene_detail::vector_of<3>(ps["q0"], "q0"),
                         pv0 = nhi::scene_detail::vector_of<3>(ps["v0"], "v0");
    const Vec<double, 4> rq0 = nhi::scene_detail::vector_of<4>(rs["q0"], "q0"),
                         rv0 = nhi::scene_detail::vector_of<4>(rs["v0"], "v0");
    nhi::Particle particle;
    particle.kx = 0.0;  // V = ky y^2: translations in (x, z) are a symmetry
    const double h = 0.2;
    const long steps = 2000;

    const std::vector<std::string> scenes = study::scene_names(o);
    std::vector<json> slots(8 + scenes.size());
    std::vector<std::function<void()>> tasks;
    tasks.push_back([&] { slots[0] = momentum_run(particle, 0.5, h, steps, pq0, pv0); });
    tasks.push_back([&] { slots[1] = momentum_run(particle, 0.25, h, steps, pq0, pv0); });
    tasks.push_back([&] { slots[2] = momentum_run(nhi::Robot{}, 0.5, h, steps, rq0, rv0); });
    tasks.push_back([&] { slots[3] = momentum_run(nhi::Robot{}, 0.25, h, steps, rq0, rv0); });
    tasks.push_back([&] { slots[4] = robot_series(robot_run(false, h, steps, rq0, rv0), h, rq0, rv0); });
    tasks.push_back([&] { slots[5] = robot_series(robot_run(true, h, steps, rq0, rv0), h, rq0, rv0); });
    // Convergence at T = 2 against the exact reduced flow (robot.hpp).
    tasks.push_back([&] {
      const double T = 2.0;
      Vec<double, 4> qT, vT;
      nhi::Robot{}.reduced_flow(rq0, rv0, T, 200000, &qT, &vT);
      std::vector<double> hs, ein, eex;
      for (double hh = 0.2; hh > 0.005; hh /= 2) {
        const long n = std::lround(T / hh);
        hs.push_back(hh);
        ein.push_back((robot_run(false, hh, n, rq0, rv0).q.back() - qT).cwiseAbs().maxCoeff());
        eex.push_back((robot_run(true, hh, n, rq0, rv0).q.back() - qT).cwiseAbs().maxCoeff());
      }
      const std::vector<double> fh(hs.end() - 4, hs.end()), fi(ein.end() - 4, ein.end()), fe(eex.end() - 4, eex.end());
      slots[6] = {{"T", T},
                  {"h", hs},
                  {"intrinsic", ein},
                  {"extrinsic", eex},
                  {"order_intrinsic", nhi::loglog_slope(fh, fi)},
                  {"order_extrinsic", nhi::loglog_slope(fh, fe)},
                  {"order_fit", "least squares over the 4 smallest h"}};
    });
    // Remark 3.3: the circle, omega-DLA and g-DLA (eq. 17), h = 0.1.
    tasks.push_back([&] {
      const double hc = 0.1;
      const long n = 5000;
      const Vec<double, 2> q0(std::cos(-0.3), std::sin(-0.3)), v0 = 1.7 * Vec<double, 2>(-q0[1], q0[0]);
      const nhi::CircleParticle cp;
      const double E0 = nhi::energy(cp, q0, v0);
      auto series = [&](auto stepper) {
        std::vector<double> t, dE, radius;
        using St = decltype(stepper);
        constexpr int m = St::m;
        const bool ok = nhi::integrate(stepper, q0, v0, hc, n, [&](const nhi::Sample<2, m>& s) {
                          t.push_back(s.t);
                          dE.push_back(nhi::energy(cp, s.q, s.v) - E0);
                          radius.push_back(s.q.norm() - 1.0);
                          return true;
                        }).ok;
        return json{{"t", t}, {"energy_error", dE}, {"radius_error", radius}, {"status", ok ? "ok" : "failed"}};
      };
      slots[7] = {{"h", hc},
                  {"omega", series(nhi::DlaStepper<nhi::CircleParticle, nhi::AlphaDiscretization>(
                                cp, nhi::AlphaDiscretization{0.5}))},
                  {"g", series(nhi::DlaStepper<nhi::CircleHolonomic, nhi::AlphaDiscretization>(
                            nhi::CircleHolonomic{}, nhi::AlphaDiscretization{0.5}))}};
    });
    for (const std::string& name : scenes) {
      const json sc = study::scene(o, name);
      tasks.push_back([&slots, sc, i = tasks.size()] { slots[i] = reversibility_of(sc); });
    }
    // Task i fills slots[i]; estimated costs in RK4 steps (the reduced flow's
    // 200000 steps dominate the convergence task).
    std::vector<double> cost = {12000, 12000, 20000, 20000, 12000, 12000, 220000, 30000};
    std::vector<std::string> names = {"momentum particle a=1/2", "momentum particle a=1/4", "momentum robot a=1/2",
                                      "momentum robot a=1/4",    "robot intrinsic",         "robot extrinsic",
                                      "robot convergence",       "circle (Remark 3.3)"};
    for (const std::string& name : scenes) {
      cost.push_back(30000);
      names.push_back("reversibility " + name);
    }
    study::Cells cells;
    cells.label = "geometry";
    cells.count = tasks.size();
    cells.run = [&](size_t i) {
      tasks[i]();
      return slots[i];
    };
    cells.cost = [&](size_t i) { return cost[i]; };
    cells.name = [&](size_t i) { return names[i]; };
    slots = study::map_cells(o, cells);
    out = {{"study", "geometry"},
           {"momentum",
            {{"particle", {{"kx", 0.0}, {"ky", particle.ky}, {"runs", {slots[0], slots[1]}}}},
             {"robot", {{"runs", {slots[2], slots[3]}}}}}},
           {"extrinsic", {{"h", h}, {"intrinsic", slots[4]}, {"extrinsic", slots[5]}, {"convergence", slots[6]}}},
           {"holonomic", {{"circle", slots[7]}}}};
    json& rev = out["reversibility"];
    rev["rho"] = "(q, v) -> (q, -v)";
    rev["defect"] =
        "max over the states of |rho Phi_h rho Phi_h z - z| (reversibility) and |Phi_-h Phi_h z - z| (symmetry), "
        "in q and in (q, v), relative to 1 + max|z| + max|Phi_h z|; rho is applied through the method's start "
        "(reversibility.hpp)";
    for (size_t i = 0; i < scenes.size(); ++i) rev["scenes"][scenes[i]] = slots[8 + i];
  } catch (const std::exception& e) {
    std::cerr << "study_geometry: error: " << e.what() << "\n";
    return 1;
  }
  return study::finish(o, out);
}
