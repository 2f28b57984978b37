// The study toolkit shared by the study executables: the command line (-o,
// --threads, --scenes), the registered scenes (systems/registry.hpp) with their
// scene files, the methods every study runs (nhi::study_methods()), a parallel
// map over independent runs, a progress line on stderr, per-thread CPU time,
// a run report as JSON, and writing the result with `meta`.  Each run is
// independent and deterministic, so results do not depend on the number of
// threads.  Adding a scene to the registry or a method to study_methods() adds
// it to every study.
#pragma once

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <functional>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "nhi/fit.hpp"
#include "nhi/methods.hpp"
#include "nhi/run.hpp"
#include "nhi/output.hpp"
#include "nhi/scene.hpp"
#include "nhi/scene_detail.hpp"
#include "nhi/signals.hpp"

namespace study {

using nhi::json;

struct Options {
  std::string out;
  std::string scenes_dir = "experiments/scenes";
  int threads = 2;
};

// Parse the common options and install the interrupt handlers; exits on
// --help or a bad command line.
inline Options parse(int argc, char** argv, const std::string& what) {
  CLI::App app{what};
  Options o;
  app.add_option("-o,--output", o.out, "Result file (JSON)")->required();
  app.add_option("--scenes", o.scenes_dir, "Directory with one NAME.json per registered system");
  app.add_option("--threads", o.threads, "Worker threads")->check(CLI::Range(1, 64));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  nhi::install_interrupt_handlers();
  return o;
}

// The registered scenes, in registry order.
inline std::vector<std::string> scene_names() { return nhi::system_names(); }

// The validated scene file of a scene name: SCENES/NAME.json.
inline json scene(const Options& o, const std::string& name) {
  return nhi::validate_scene(nhi::load_scene_file(o.scenes_dir + "/" + name + ".json"));
}

// The methods of study_methods() that pass `keep`, in their fixed order.
inline std::vector<nhi::StudyMethod> methods(const std::function<bool(const nhi::StudyMethod&)>& keep) {
  std::vector<nhi::StudyMethod> out;
  for (const auto& m : nhi::study_methods())
    if (keep(m)) out.push_back(m);
  return out;
}
// Library methods with a fixed step (everything but the reference and the external ones).
inline bool fixed_step(const nhi::StudyMethod& m) { return !m.external && m.spec.kind != "benchmark"; }

inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// A progress line on stderr: "label: done/total", rewritten at most twice a second.
class Progress {
 public:
  Progress(std::string label, long total) : label_(std::move(label)), total_(total) {}
  void tick() {
    const long d = ++done_;
    std::lock_guard<std::mutex> lock(m_);
    const auto now = std::chrono::steady_clock::now();
    if (d == total_ || now - last_ > std::chrono::milliseconds(500)) {
      last_ = now;
      std::fprintf(stderr, "\r%s: %ld/%ld runs%s", label_.c_str(), d, total_, d == total_ ? "\n" : "");
      std::fflush(stderr);
    }
  }

 private:
  std::string label_;
  long total_;
  std::atomic<long> done_{0};
  std::mutex m_;
  std::chrono::steady_clock::time_point last_{};
};

// Run task(i) for every i on `threads` workers; results land in their own slots.
inline void parallel_for(size_t count, int threads, const std::function<void(size_t)>& task,
                         Progress* progress = nullptr) {
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i; (i = next++) < count;) {
      if (nhi::interrupt_flag().load()) return;
      task(i);
      if (progress) progress->tick();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

// status and, when failed, failure {step, time, kind, reason} of a run.
inline json report_json(const nhi::RunReport& rep, double h) {
  json j = {{"status", rep.ok ? "ok" : "failed"}};
  if (!rep.ok)
    j["failure"] = {{"step", rep.failure_step}, {"time", rep.failure_step * h},
                    {"kind", nhi::to_string(rep.failure)}, {"reason", rep.reason}};
  return j;
}

// Write {result..., meta} atomically; an interrupted study writes nothing.
inline int finish(const Options& o, json result) {
  if (nhi::interrupt_flag().load()) {
    std::cerr << "study: interrupted; nothing written\n";
    return 130;
  }
  result["meta"] = nhi::meta();
  try {
    nhi::AtomicFile f(o.out);
    f.commit(result.dump() + "\n");
  } catch (const std::exception& e) {
    std::cerr << "study: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

// A JSON array of a vector's entries.
template <int N>
json to_json(const nhi::Vec<double, N>& v) {
  return std::vector<double>(v.data(), v.data() + N);
}

// q(T) of the reference solution at rtol = atol = tol.
template <class S>
nhi::Vec<double, S::n> reference_q(const S& sys, const nhi::Vec<double, S::n>& q0,
                                   const nhi::Vec<double, S::n>& v0, double T, double tol) {
  nhi::Vec<double, S::n> q;
  nhi::reference_solution(sys, q0, v0, T, tol, &q);
  return q;
}

}  // namespace study
