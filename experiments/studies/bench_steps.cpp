// Micro-benchmarks (Google Benchmark): nanoseconds per step of each "main"
// fixed-step study method on each registered scene (the stepper as the
// integrate loop drives it), the reference solution per run, and for the
// particle a hand-derived Newton step with the analytic Jacobian (the floor the
// library's DLA map is measured against, as a ratio in the same run), and for
// contact_oscillator_nr mp06 reduced by hand to one scalar equation
// (experiments/studies/hand_steps.hpp, the floor of the library's mp06 step there).
// Writes results/step_costs.json:  bench_steps -o FILE [--shard K/N] [google
// benchmark flags];  bench_steps --merge SHARD.json... -o FILE joins shards.
// Steps cycle through states of a real trajectory.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "cluster.hpp"
#include "hand_steps.hpp"
#include "nhi/methods/methods.hpp"
#include "nhi/runner/output.hpp"
#include "nhi/runner/scene.hpp"
#include "nhi/systems/registry.hpp"

namespace {

using nhi::Vec;

constexpr double kH = 0.2;
constexpr int kStates = 256;

// Steps of a library method from the system's default state, restarted every
// 10^3 steps to stay on a bounded stretch of trajectory.  The method is chosen
// by name once, outside the timed loop.  (The sleigh's angular velocity
// decays exponentially, by 1e-75 every 200 time units from its default
// state, and is subnormal from t ~ 800, step ~4000 at h = 0.2, after which
// subnormal arithmetic makes every step many times slower.)
template <class S>
void BM_Method(benchmark::State& state, nhi::MethodSpec spec) {
  const S sys;
  const Vec<double, S::n> q0 = S::default_q0(), v0 = S::default_v0();
  nhi::with_stepper(sys, spec, [&](auto& st) {
    st.start(q0, v0);
    long k = 0, iterations = 0;
    for (auto _ : state) {
      const nhi::StepSummary s = st.step(kH);
      iterations += s.iterations;
      benchmark::DoNotOptimize(s);
      if (++k % 1000 == 0) st.start(q0, v0);
    }
    state.counters["newton_iterations_per_step"] = double(iterations) / double(state.iterations());
    return 0;
  });
}

// The reference solution (tol 1e-12): cost per run to T = 200, and its internal steps.
template <class S>
void BM_Reference(benchmark::State& state) {
  const S sys;
  const Vec<double, S::n> q0 = S::default_q0(), v0 = S::default_v0();
  long internal = 0;
  for (auto _ : state) {
    const nhi::RunReport rep =
        nhi::integrate(nhi::ReferenceStepper<S>(sys), q0, v0, 200.0, 1, [](const auto&) { return true; });
    internal += rep.internal_steps;
  }
  state.counters["internal_steps_per_run"] = double(internal) / double(state.iterations());
  state.SetItemsProcessed(internal);
}

// States (q_k, p_k, guess_k, lambda_k) along a DLA trajectory, for the floor comparison.
template <class S, class D>
struct Trajectory {
  std::vector<Vec<double, S::n>> q, p, guess;
  std::vector<Vec<double, S::m>> lambda;
  explicit Trajectory(const nhi::DlaMap<S, D>& st) {
    const Vec<double, S::n> q0 = S::default_q0(), v0 = S::default_v0();
    Vec<double, S::n> qc = q0, pc = nhi::momentum(st.system(), q0, v0), g = q0 + kH * v0, qn = q0, pn = pc;
    Vec<double, S::m> l = Vec<double, S::m>::Zero();
    for (int k = 0; k < kStates; ++k) {
      q.push_back(qc);
      p.push_back(pc);
      guess.push_back(g);
      lambda.push_back(l);
      st.step(qc, pc, g, &qn, &l, &pn);
      g = qn + (qn - qc);
      qc = qn;
      pc = pn;
    }
  }
};

// The library's DLA map on the same states as the floor.
template <class S, class D>
void BM_DlaMap(benchmark::State& state, D disc) {
  const S sys;
  const nhi::DlaMap<S, D> st(sys, disc, kH);
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

// The floor: the particle's midpoint DLA step (eq. 6 with alpha = 1/2) by hand,
// residual and Jacobian (7) written out, Newton with a 4x4 LU and the same
// stopping rule spirit (until the update is at round-off).
struct AnalyticParticleStep {
  double h, kx = 1.0, ky = 1.0;
  void step(const Eigen::Vector3d& q0, const Eigen::Vector3d& p0, const Eigen::Vector3d& guess, Eigen::Vector3d* q1_out,
            double* lambda, Eigen::Vector3d* p1) const {
    Eigen::Vector3d q1 = guess;
    double lam = *lambda;
    const double w0x = -q0[1];  // omega(q0) = (-y0, 0, 1)
    for (int it = 0; it < 20; ++it) {
      const Eigen::Vector3d v = (q1 - q0) / h, qm = 0.5 * (q0 + q1);
      Eigen::Vector4d r;
      r[0] = p0[0] - h * kx * qm[0] - v[0] - w0x * lam;  // p + h/2 dL/dq - dL/dv - W^T lambda
      r[1] = p0[1] - h * ky * qm[1] - v[1];
      r[2] = p0[2] - v[2] - lam;
      r[3] = -qm[1] * v[0] + v[2];  // omega(q_m) v
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
  const nhi::DlaMap<nhi::Particle, nhi::AlphaDiscretization> st(sys, nhi::AlphaDiscretization{0.5}, kH);
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

// The floor for mp06 on contact_oscillator_nr: the step reduced by hand to one
// scalar equation solved by Newton (experiments/studies/hand_steps.hpp; the same map as the
// library's to round-off, tests/test_mp06.cpp), on the same trajectory
// as BM_Method's rows: from the default state, restarted every 10^3 steps.
void BM_Mp06NrFloor(benchmark::State& state) {
  const nhi::ContactOscillatorNR sys;
  floors::Mp06ContactOscillatorNR hand{sys.epsilon};
  const Eigen::Vector3d q0 = sys.default_q0(), p0 = nhi::momentum(sys, q0, sys.default_v0());
  Eigen::Vector3d q = q0, p = p0, q1, p1;
  double lambda = 0;
  long k = 0;
  for (auto _ : state) {
    if (!hand.step(kH, q, p, &q1, &p1, &lambda)) {
      state.SkipWithError("the hand-reduced step did not converge in 20 Newton iterations");
      break;
    }
    q = q1;
    p = p1;
    benchmark::DoNotOptimize(q);
    benchmark::DoNotOptimize(p);
    if (++k % 1000 == 0) q = q0, p = p0, lambda = 0;
  }
  state.counters["newton_iterations_per_step"] = double(hand.iterations) / double(state.iterations());
}

// A method row's benchmark name (scene/label, spaces as '_': Google
// Benchmark's filters split on them) and the method's label and scene keys,
// which each row also carries.
std::map<std::string, std::pair<std::string, std::string>>& method_rows() {
  static std::map<std::string, std::pair<std::string, std::string>> rows;
  return rows;
}

class Capture : public benchmark::ConsoleReporter {
 public:
  nhi::json rows = nhi::json::array();
  std::vector<std::string> errors;  // rows that stopped with SkipWithError
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const auto& r : runs) {
      if (r.run_type != Run::RT_Iteration) continue;
      if (r.error_occurred) {
        errors.push_back(r.benchmark_name() + ": " + r.error_message);
        continue;
      }
      nhi::json row = {{"name", r.benchmark_name()},
                       {"iterations", r.iterations},
                       {"real_ns", r.GetAdjustedRealTime()},
                       {"cpu_ns", r.GetAdjustedCPUTime()}};
      for (const auto& [k, c] : r.counters) row["counters"][k] = double(c);
      const auto method = method_rows().find(r.benchmark_name());
      if (method != method_rows().end()) row["label"] = method->second.first, row["keys"] = method->second.second;
      rows.push_back(row);
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace

// One row per registered scene and fixed-step study method, plus the
// reference solution per run, plus the floor comparisons (the particle's
// midpoint DLA, contact_oscillator_nr's mp06), each with its scene.  With
// nshards > 1 only the scenes whose place in nhi::Systems is shard modulo
// nshards: make reproduce runs two shards at once, one per core (see main).
void register_all(int shard, int nshards) {
  int index = 0;
  nhi::for_each_type(nhi::Systems{}, [&](auto tag) {
    using S = typename decltype(tag)::type;
    if (index++ % nshards != shard) return;
    const std::string scene = S::name;
    if (scene == "particle") {
      benchmark::RegisterBenchmark("particle/analytic_newton_floor", BM_AnalyticFloor);
      benchmark::RegisterBenchmark("particle/dla_map_alpha0.5", [](benchmark::State& st) {
        BM_DlaMap<nhi::Particle, nhi::AlphaDiscretization>(st, nhi::AlphaDiscretization{0.5});
      });
    }
    if (scene == "contact_oscillator_nr")
      benchmark::RegisterBenchmark("contact_oscillator_nr/mp06_hand_reduced_floor", BM_Mp06NrFloor);
    for (const nhi::StudyMethod& m : nhi::study_methods()) {
      if (!m.fixed_step() || !m.template on<S>()) continue;  // every fixed-step method studied on S, variants too
      std::string name = scene + "/" + m.label();
      std::replace(name.begin(), name.end(), ' ', '_');
      method_rows()[name] = {m.label(), m.spec.scene_keys()};
      const nhi::MethodSpec spec = m.spec;
      benchmark::RegisterBenchmark(name.c_str(), [spec](benchmark::State& st) { BM_Method<S>(st, spec); });
    }
    benchmark::RegisterBenchmark((scene + "/reference_run_T200").c_str(), BM_Reference<S>)
        ->Unit(benchmark::kMillisecond);
  });
}

// The result from its rows: each scene's steps as a ratio to that scene's RK4
// step (the same process, so the same run), and the floor ratios.
nhi::json step_costs(const nhi::json& rows) {
  auto ns = [&](const std::string& name) {
    for (const auto& r : rows)
      if (r["name"] == name) return r["cpu_ns"].get<double>();
    return std::nan("");
  };
  nhi::json result = {{"study", "step_costs"}, {"benchmarks", rows}};
  for (auto& r : result["benchmarks"]) {
    const std::string name = r["name"];
    const std::string scene = name.substr(0, name.find('/'));
    const double rk4 = ns(scene + "/rk4");
    if (name.find("reference_run") == std::string::npos && std::isfinite(rk4))
      r["ratio_to_rk4"] = r["cpu_ns"].get<double>() / rk4;
  }
  const double floor = ns("particle/analytic_newton_floor"), dla = ns("particle/dla_map_alpha0.5");
  result["particle_dla_over_floor"] =
      std::isfinite(floor) && std::isfinite(dla) ? nhi::json(dla / floor) : nhi::json(nullptr);
  result["target_ratio"] = 2.0;
  const double nr_floor = ns("contact_oscillator_nr/mp06_hand_reduced_floor"), nr = ns("contact_oscillator_nr/mp06");
  result["nr_mp06_over_floor"] =
      std::isfinite(nr_floor) && std::isfinite(nr) ? nhi::json(nr / nr_floor) : nhi::json(nullptr);
  result["meta"] = nhi::meta();
  return result;
}

int write(const std::string& out, const nhi::json& result) {
  try {
    nhi::AtomicFile f(out);
    f.commit(result.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::cerr << "bench_steps: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

// bench_steps --merge A.json B.json ... -o OUT: the shards' rows in one result
// (each shard holds whole scenes, so every ratio stays within one process).
int merge(const std::vector<std::string>& files, const std::string& out) {
  nhi::json rows = nhi::json::array();
  std::set<std::string> names;
  for (const std::string& file : files) {
    std::ifstream in(file);
    nhi::json part;
    try {
      part = nhi::json::parse(in);
    } catch (const std::exception& e) {
      std::cerr << "bench_steps --merge: " << file << ": " << e.what() << "\n";
      return 1;
    }
    if (!part.is_object() || !part.contains("study") || part["study"] != "step_costs" || !part.contains("benchmarks") ||
        !part["benchmarks"].is_array()) {
      std::cerr << "bench_steps --merge: " << file << " is not a bench_steps result\n";
      return 1;
    }
    for (const auto& r : part["benchmarks"]) {
      if (!r.is_object() || !r.contains("name") || !r["name"].is_string() || !r.contains("cpu_ns") ||
          !r["cpu_ns"].is_number()) {
        std::cerr << "bench_steps --merge: " << file << " has a row without a name or cpu_ns\n";
        return 1;
      }
      if (!names.insert(r["name"].get<std::string>()).second) {
        std::cerr << "bench_steps --merge: row " << r["name"] << " is in more than one shard\n";
        return 1;
      }
      rows.push_back(r);
    }
  }
  return write(out, step_costs(rows));
}

int main(int argc, char** argv) {
  // Timed: copies on one node would share its cores, and it is not sharded
  // by the cluster launcher (README, "Running on a cluster").
  if (study::launcher_ranks() > 1) {
    std::cerr << "bench_steps: started as one of " << study::launcher_ranks()
              << " ranks; it is timed and not sharded: run it as one process\n";
    return 2;
  }
  std::string out;
  std::vector<std::string> merge_files;
  int shard = 0, nshards = 1;
  bool merging = false;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "-o") == 0 && i + 1 < argc) {
      out = argv[++i];
    } else if (std::strcmp(argv[i], "--shard") == 0 && i + 1 < argc) {
      // --shard K/N: the scenes K, K + N, ... of nhi::Systems.
      char slash = 0;
      std::istringstream in(argv[++i]);
      if (!(in >> shard >> slash >> nshards) || slash != '/' || !in.eof() || nshards < 1 || shard < 0 ||
          shard >= nshards) {
        std::cerr << "bench_steps: --shard wants K/N with 0 <= K < N, got '" << argv[i] << "'\n";
        return 2;
      }
    } else if (std::strcmp(argv[i], "--merge") == 0) {
      merging = true;
    } else if (merging && argv[i][0] != '-') {
      merge_files.push_back(argv[i]);
    } else {
      args.push_back(argv[i]);
    }
  }
  if (merging) {
    if (out.empty() || merge_files.empty() || args.size() > 1) {
      std::cerr << "bench_steps: --merge FILE... -o OUT (and nothing else)\n";
      return 2;
    }
    return merge(merge_files, out);
  }
  int n = static_cast<int>(args.size());
  register_all(shard, nshards);
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 2;
  Capture rep;
  benchmark::RunSpecifiedBenchmarks(&rep);
  if (!rep.errors.empty()) {  // no result with a row missing or wrong
    for (const auto& e : rep.errors) std::cerr << "bench_steps: " << e << "\n";
    return 1;
  }
  if (out.empty()) return 0;
  // With --benchmark_repetitions=N (make reproduce: 3, randomly interleaved,
  // so that a slow spell of the machine falls on one repetition of a row, not
  // on all of it), each row is the repetition with the least CPU time (the
  // machine's noise only adds), and cpu_ns_repetitions lists all of them.
  std::vector<std::string> order;
  std::map<std::string, std::vector<nhi::json>> by_name;
  for (const auto& r : rep.rows) {
    const std::string name = r["name"];
    if (!by_name.count(name)) order.push_back(name);
    by_name[name].push_back(r);
  }
  nhi::json rows = nhi::json::array();
  for (const std::string& name : order) {
    std::vector<nhi::json>& rs = by_name[name];
    std::sort(rs.begin(), rs.end(), [](const nhi::json& a, const nhi::json& b) {
      return a["cpu_ns"].get<double>() < b["cpu_ns"].get<double>();
    });
    nhi::json row = rs.front();
    row["repetitions"] = rs.size();
    row["cpu_ns_repetitions"] = nhi::json::array();
    for (const auto& r : rs) row["cpu_ns_repetitions"].push_back(r["cpu_ns"]);
    rows.push_back(row);
  }
  return write(out, step_costs(rows));
}
