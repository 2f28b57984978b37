// Micro-benchmarks (Google Benchmark): nanoseconds per step of each method on
// each scene, and for the particle a hand-derived Newton step with the analytic
// Jacobian (the floor the library's DLA step is measured against, as a ratio in
// the same run).  Writes results/step_costs.json:  bench_steps -o FILE [google
// benchmark flags].  Steps cycle through states of a real trajectory.
#include <benchmark/benchmark.h>

#include <cstring>
#include <iostream>

#include "nhi/methods.hpp"
#include "nhi/output.hpp"
#include "nhi/scene.hpp"
#include "nhi/systems/particle.hpp"
#include "nhi/systems/robot.hpp"

namespace {

using nhi::Vec;

constexpr double kH = 0.2;
constexpr int kStates = 256;

// The initial state of the scene file experiments/scenes/<system>.json (run from
// the repository root, as `make reproduce` does).
template <class S>
void scene_state(Vec<double, S::n>* q, Vec<double, S::n>* v) {
  static const nhi::json scene =
      nhi::validate_scene(nhi::load_scene_file(std::string("experiments/scenes/") + S::name + ".json"));
  for (int i = 0; i < S::n; ++i) {
    (*q)[i] = scene["q0"][i].get<double>();
    (*v)[i] = scene["v0"][i].get<double>();
  }
}

// States (q_k, p_k, guess_k, lambda_k) along a DLA trajectory.
template <class S, class D>
struct Trajectory {
  std::vector<Vec<double, S::n>> q, p, guess;
  std::vector<Vec<double, S::m>> lambda;
  explicit Trajectory(const nhi::DlaStepper<S, D>& st) {
    Vec<double, S::n> q0, v0;
    scene_state<S>(&q0, &v0);
    Vec<double, S::n> qc = q0, pc = nhi::momentum(st.system(), q0, v0), g = q0 + kH * v0, qn = q0, pn = pc;
    Vec<double, S::m> l = Vec<double, S::m>::Zero();
    for (int k = 0; k < kStates; ++k) {
      q.push_back(qc); p.push_back(pc); guess.push_back(g); lambda.push_back(l);
      st.step(qc, pc, g, &qn, &l, &pn);
      g = qn + (qn - qc);
      qc = qn;
      pc = pn;
    }
  }
};

template <class S, class D>
void BM_Dla(benchmark::State& state, D disc) {
  const S sys;
  const nhi::DlaStepper<S, D> st(sys, disc, kH);
  const Trajectory<S, D> tr(st);
  Vec<double, S::n> qn, pn;
  Vec<double, S::m> l;
  int k = 0;
  for (auto _ : state) {
    l = tr.lambda[k];
    auto s = st.step(tr.q[k], tr.p[k], tr.guess[k], &qn, &l, &pn);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(qn);
    k = (k + 1) % kStates;
  }
}

template <class S>
void BM_Rk4(benchmark::State& state) {
  const S sys;
  const nhi::Rk4Stepper<S> st(sys, kH);
  Vec<double, S::n> q, v;
  scene_state<S>(&q, &v);
  long k = 0;
  for (auto _ : state) {
    st.step(&q, &v);
    benchmark::DoNotOptimize(q);
    if (++k % 10000 == 0) scene_state<S>(&q, &v);  // stay on a bounded stretch of trajectory
  }
}

// CVODE (tol 1e-12): cost per internal step, from runs to T = 200.
template <class S>
void BM_Cvode(benchmark::State& state) {
  const S sys;
  Vec<double, S::n> q0, v0;
  scene_state<S>(&q0, &v0);
  long internal = 0;
  for (auto _ : state) {
    const nhi::RunReport rep = nhi::integrate_benchmark(sys, 200.0, q0, v0, 1, nhi::BenchmarkOptions{},
                                                        [](const auto&) { return true; });
    internal += rep.internal_steps;
  }
  state.counters["internal_steps_per_run"] = double(internal) / double(state.iterations());
  state.SetItemsProcessed(internal);
}

// The floor: the particle's midpoint DLA step (eq. 6 with alpha = 1/2) by hand,
// residual and Jacobian (7) written out, Newton with a 4x4 LU and the same
// stopping rule spirit (until the update is at round-off).
struct AnalyticParticleStep {
  double h, kx = 1.0, ky = 1.0;
  void step(const Eigen::Vector3d& q0, const Eigen::Vector3d& p0, const Eigen::Vector3d& guess,
            Eigen::Vector3d* q1_out, double* lambda, Eigen::Vector3d* p1) const {
    Eigen::Vector3d q1 = guess;
    double lam = *lambda;
    const double w0x = -q0[1];  // omega(q0) = (-y0, 0, 1)
    for (int it = 0; it < 20; ++it) {
      const Eigen::Vector3d v = (q1 - q0) / h, qm = 0.5 * (q0 + q1);
      Eigen::Vector4d r;
      r[0] = p0[0] - h * kx * qm[0] - v[0] - w0x * lam;   // p + h/2 dL/dq - dL/dv - W^T lambda
      r[1] = p0[1] - h * ky * qm[1] - v[1];
      r[2] = p0[2] - v[2] - lam;
      r[3] = -qm[1] * v[0] + v[2];                          // omega(q_m) v
      // Same stopping rule as the library: residual at round-off relative to its terms.
      const double scale = std::abs(p0[0]) + std::abs(h * kx * qm[0]) + std::abs(v[0]) + std::abs(w0x * lam) +
                           std::abs(p0[1]) + std::abs(h * ky * qm[1]) + std::abs(v[1]) + std::abs(p0[2]) +
                           std::abs(v[2]) + std::abs(lam) + (q0.cwiseAbs() + q1.cwiseAbs()).sum() / h;
      if (r.cwiseAbs().maxCoeff() <= 16 * 2.2e-16 * scale) break;
      Eigen::Matrix4d J = Eigen::Matrix4d::Zero();
      J(0, 0) = -0.5 * h * kx - 1.0 / h;
      J(1, 1) = -0.5 * h * ky - 1.0 / h;
      J(2, 2) = -1.0 / h;
      J(0, 3) = -w0x;
      J(2, 3) = -1.0;
      J(3, 0) = -qm[1] / h;
      J(3, 1) = -0.5 * v[0];
      J(3, 2) = 1.0 / h;
      const Eigen::Vector4d dx = J.partialPivLu().solve(r);
      q1 -= dx.head<3>();
      lam -= dx[3];
    }
    *q1_out = q1;
    *lambda = lam;
    const Eigen::Vector3d v = (q1 - q0) / h, qm = 0.5 * (q0 + q1);
    *p1 = Eigen::Vector3d(-h * kx * qm[0], -h * ky * qm[1], 0.0) + v;  // D2 L_d = h/2 dL/dq + dL/dv
  }
};

void BM_AnalyticFloor(benchmark::State& state) {
  const nhi::Particle sys;
  const nhi::DlaStepper<nhi::Particle, nhi::AlphaDiscretization> st(sys, nhi::AlphaDiscretization{0.5}, kH);
  const Trajectory<nhi::Particle, nhi::AlphaDiscretization> tr(st);
  const AnalyticParticleStep an{kH};
  Eigen::Vector3d qn, pn;
  double l;
  int k = 0;
  for (auto _ : state) {
    l = tr.lambda[k][0];
    an.step(tr.q[k], tr.p[k], tr.guess[k], &qn, &l, &pn);
    benchmark::DoNotOptimize(qn);
    benchmark::DoNotOptimize(pn);
    k = (k + 1) % kStates;
  }
}

class Capture : public benchmark::ConsoleReporter {
 public:
  nhi::json rows = nhi::json::array();
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration) continue;
      nhi::json row = {{"name", r.benchmark_name()}, {"iterations", r.iterations},
                       {"real_ns", r.GetAdjustedRealTime()}, {"cpu_ns", r.GetAdjustedCPUTime()}};
      for (const auto& [k, c] : r.counters) row["counters"][k] = double(c);
      rows.push_back(row);
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace

void register_all() {
  using P = nhi::Particle;
  using R = nhi::Robot;
  using A = nhi::AlphaDiscretization;
  using Y = nhi::SymmetricDiscretization;
  benchmark::RegisterBenchmark("particle/analytic_newton_floor", BM_AnalyticFloor);
  benchmark::RegisterBenchmark("particle/dla_alpha0.5", [](benchmark::State& st) { BM_Dla<P, A>(st, A{0.5}); });
  benchmark::RegisterBenchmark("particle/dla_symmetric0", [](benchmark::State& st) { BM_Dla<P, Y>(st, Y{0.0}); });
  benchmark::RegisterBenchmark("particle/rk4", BM_Rk4<P>);
  benchmark::RegisterBenchmark("particle/cvode_run_T200", BM_Cvode<P>)->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("robot/dla_alpha0.5", [](benchmark::State& st) { BM_Dla<R, A>(st, A{0.5}); });
  benchmark::RegisterBenchmark("robot/dla_symmetric0", [](benchmark::State& st) { BM_Dla<R, Y>(st, Y{0.0}); });
  benchmark::RegisterBenchmark("robot/rk4", BM_Rk4<R>);
  benchmark::RegisterBenchmark("robot/cvode_run_T200", BM_Cvode<R>)->Unit(benchmark::kMillisecond);
}

int main(int argc, char** argv) {
  std::string out;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "-o") == 0 && i + 1 < argc) {
      out = argv[++i];
    } else {
      args.push_back(argv[i]);
    }
  }
  int n = static_cast<int>(args.size());
  register_all();
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
  Capture rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  if (out.empty()) return 0;
  auto ns = [&](const std::string& name) {
    for (const auto& r : rep.rows)
      if (r["name"] == name) return r["cpu_ns"].get<double>();
    return std::nan("");
  };
  nhi::json result = {{"study", "step_costs"}, {"benchmarks", rep.rows}};
  const double floor = ns("particle/analytic_newton_floor"), dla = ns("particle/dla_alpha0.5");
  result["particle_dla_over_floor"] = std::isfinite(floor) && std::isfinite(dla) ? nhi::json(dla / floor) : nhi::json(nullptr);
  result["target_ratio"] = 2.0;
  result["meta"] = nhi::meta();
  try {
    nhi::AtomicFile f(out);
    f.commit(result.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::cerr << "bench_steps: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
