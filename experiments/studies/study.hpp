// The study toolkit shared by the study executables: the command line (-o,
// --threads, --scenes, --only), the registered scenes (systems/registry.hpp)
// with their scene files, the methods every study runs (nhi::study_methods()),
// map_cells() over a study's independent cells (threads within a process, MPI
// ranks across processes: cluster.hpp), a progress line on stderr, per-thread
// CPU time, a run report as JSON, and writing the result with `meta` and
// `stats`.  Each cell is independent and deterministic, so results do not
// depend on the number of threads or ranks.  Adding a scene to the registry or
// a method to study_methods() adds it to every study.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <functional>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cluster.hpp"
#include "nhi/methods/composition.hpp"
#include "nhi/methods/methods.hpp"
#include "nhi/readings/fit.hpp"
#include "nhi/roles/signals.hpp"
#include "nhi/runner/output.hpp"
#include "nhi/runner/run.hpp"
#include "nhi/runner/scene.hpp"
#include "nhi/runner/scene_detail.hpp"

namespace study {

using nhi::json;

struct Options {
  std::string out;
  std::string scenes_dir = "experiments/scenes";
  int threads = 2;
  std::vector<std::string> only;  // registered scenes to run (empty: all)
};

// The wall-clock start of the study (for stats.wall_seconds).
inline std::chrono::steady_clock::time_point& start_time() {
  static std::chrono::steady_clock::time_point t = std::chrono::steady_clock::now();
  return t;
}

// The study's name in messages: its executable's (set by parse()).
inline std::string& program_name() {
  static std::string name = "study";
  return name;
}

// "" if a result can be written at `path` (a file in an existing, writable
// directory), else why not.  Checked when the command line is parsed, so that
// an unwritable output fails before the study runs; nothing is created (a
// study killed mid-run must leave no temporary file behind).
inline std::string output_problem(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) return "output '" + path + "' is a directory";
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    return "cannot write output '" + path + "': " + dir + ": " + std::strerror(errno);
  return "";
}

// The common options on `app` (a study adds its own before calling parse).
inline void add_options(CLI::App& app, Options& o) {
  app.add_option("-o,--output", o.out, "Result file (JSON)")
      ->required()
      ->check(CLI::Validator([](std::string& path) { return output_problem(path); }, "FILE", "writable output"));
  app.add_option("--scenes", o.scenes_dir, "Directory with one NAME.json per registered system");
  app.add_option("--threads", o.threads, "Worker threads (per rank under MPI)")->check(CLI::Range(1, 64));
  app.add_option("--only", o.only, "Run only these registered scenes (comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember(nhi::system_names()));
}

// A scene that cannot be loaded or is not valid ends the study: one line,
// exit 2, nothing written (every rank alike: they all read the same files).
// The usual cause is a study started away from the repository root, where
// the default --scenes directory is not found.
[[noreturn]] inline void scene_error_exit(const std::string& message) {
  Cluster& cl = Cluster::get();
  if (cl.root())
    std::fprintf(stderr, "%s: error: %s (run from the repository root, or pass --scenes DIR)\n",
                 program_name().c_str(), message.c_str());
  cl.exit_all(2);
}

// The thread that parsed the command line (the one that may end the study).
inline std::thread::id& main_thread() {
  static std::thread::id id = std::this_thread::get_id();
  return id;
}

// Installed by parse(): a nhi::SceneError that no study code catches (a
// scene derived from a scene file and validated in main, say) ends the study
// as scene_error_exit() does, not with an abort (exit 134).
inline void on_terminate() {
  if (const std::exception_ptr p = std::current_exception()) {
    try {
      std::rethrow_exception(p);
    } catch (const nhi::SceneError& e) {
      if (Cluster::get().root())
        std::fprintf(stderr, "%s: error: %s (run from the repository root, or pass --scenes DIR)\n",
                     program_name().c_str(), e.what());
      Cluster::abort(2);
    } catch (...) {
    }
  }
  std::abort();
}

// Join the ranks (cluster.hpp), parse the command line and install the
// interrupt handlers; exits on --help (0) or a bad command line (2, one line
// on stderr; every rank alike).
inline void parse(CLI::App& app, int argc, char** argv) {
  start_time();
  main_thread();
  if (argc > 0 && argv[0]) {
    const std::string a0 = argv[0];
    program_name() = a0.substr(a0.find_last_of('/') + 1);
  }
  std::set_terminate(on_terminate);
  Cluster& cl = Cluster::get();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Every rank parses the same line; only the first prints the help or error.
    if (e.get_exit_code() == 0) cl.exit_all(cl.root() ? app.exit(e) : 0);
    if (cl.root()) std::fprintf(stderr, "%s: error: %s\n", program_name().c_str(), e.what());
    cl.exit_all(2);
  }
  nhi::install_interrupt_handlers();
}

inline Options parse(int argc, char** argv, const std::string& what) {
  CLI::App app{what};
  Options o;
  add_options(app, o);
  parse(app, argc, argv);
  return o;
}

// The scenes to run: the registered ones (or those of --only), in registry order.
inline std::vector<std::string> scene_names(const Options& o) {
  std::vector<std::string> out;
  for (const std::string& name : nhi::system_names())
    if (o.only.empty() || std::find(o.only.begin(), o.only.end(), name) != o.only.end()) out.push_back(name);
  return out;
}

// The validated scene file of a scene name: SCENES/NAME.json.  A scene file
// that cannot be read or is not valid ends the study (scene_error_exit());
// off the main thread (inside a cell) it throws, and the cell fails.
inline json scene(const Options& o, const std::string& name) {
  try {
    return nhi::validate_scene(nhi::load_scene_file(o.scenes_dir + "/" + name + ".json"));
  } catch (const nhi::SceneError& e) {
    if (std::this_thread::get_id() != main_thread()) throw;
    scene_error_exit(e.what());
  }
}

// The methods of study_methods() that pass `keep`, in their fixed order.
inline std::vector<nhi::StudyMethod> methods(const std::function<bool(const nhi::StudyMethod&)>& keep) {
  std::vector<nhi::StudyMethod> out;
  for (const auto& m : nhi::study_methods())
    if (keep(m)) out.push_back(m);
  return out;
}
// The methods of `list` studied on the system S, in their order (StudyMethod::on:
// the group DLA only on the systems with a quaternion).
template <class S>
inline std::vector<nhi::StudyMethod> on(const std::vector<nhi::StudyMethod>& list) {
  std::vector<nhi::StudyMethod> out;
  for (const auto& m : list)
    if (m.template on<S>()) out.push_back(m);
  return out;
}
// Is m studied on the system of `scene` (a validated scene)?  A study whose
// cells span scenes runs a cell that is not as nothing: it returns
// not_studied() (cost 0), and the study leaves that row out.
inline bool studied_on_scene(const nhi::StudyMethod& m, const json& scene) {
  return nhi::visit_scene(scene, [&](const auto& sys, const auto&, const auto&) {
    return m.template on<std::decay_t<decltype(sys)>>();
  });
}
inline json not_studied() { return json{{"not_studied", true}}; }
inline bool is_not_studied(const json& row) { return row.is_object() && row.contains("not_studied"); }

// Library methods with a fixed step (everything but the reference and the external ones).
inline bool fixed_step(const nhi::StudyMethod& m) { return m.fixed_step(); }

inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Whether a progress line drawn with '\r' is open on stderr (a message then
// starts on a new line).
inline std::atomic<bool>& progress_line_open() {
  static std::atomic<bool> open{false};
  return open;
}
// "\n" if a message must first end an open progress line, else "".
inline const char* end_progress_line() { return progress_line_open().exchange(false) ? "\n" : ""; }

// Progress on stderr: "label: done/total runs".  On a terminal, one line
// redrawn with '\r' at most twice a second; otherwise (a log file, a pipe)
// one plain line at each tenth of the runs, the last at total.
class Progress {
 public:
  Progress(std::string label, long total, bool terminal = ::isatty(STDERR_FILENO) == 1)
      : label_(std::move(label)), total_(total), terminal_(terminal) {}
  void tick() {
    const long d = ++done_;
    std::lock_guard<std::mutex> lock(m_);
    if (terminal_) {
      const auto now = std::chrono::steady_clock::now();
      if (d == total_ || now - last_ > std::chrono::milliseconds(500)) {
        last_ = now;
        std::fprintf(stderr, "\r%s: %ld/%ld runs%s", label_.c_str(), d, total_, d == total_ ? "\n" : "");
        progress_line_open() = d != total_;
        std::fflush(stderr);
      }
      return;
    }
    // The tenth reached (d may arrive out of order from the threads: a
    // tenth is printed once, by the first tick to reach it).
    const long tenth = total_ > 0 ? d * 10 / total_ : 10;
    if (tenth > printed_tenth_) {
      printed_tenth_ = tenth;
      std::fprintf(stderr, "%s: %ld/%ld runs\n", label_.c_str(), d, total_);
      std::fflush(stderr);
    }
  }

 private:
  std::string label_;
  long total_;
  bool terminal_;
  std::atomic<long> done_{0};
  std::mutex m_;
  std::chrono::steady_clock::time_point last_{};
  long printed_tenth_ = 0;
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
    j["failure"] = {{"step", rep.failure_step},
                    {"time", rep.failure_step * h},
                    {"kind", nhi::to_string(rep.failure)},
                    {"reason", rep.reason}};
  return j;
}

// ---- Cells: the unit of work distributed over threads and ranks ------------

// The estimated cost of a step of a method, in RK4 steps of the same scene
// (the method's step_cost, methods.hpp).  Only the balance of the ranks depends on it.
inline double step_weight(const nhi::MethodSpec& spec) { return nhi::method_step_cost(spec); }

// A study's phase of independent cells.  run(i) computes cell i and returns its
// JSON; it may throw (the study then fails, naming the cell).  cost(i) is the
// cell's estimated cost (steps times step_weight()), name(i) names it in
// messages.  A timed phase (its cells measure CPU time) runs on one rank per
// node only, so that no two timed ranks share a core.
struct Cells {
  std::string label;
  size_t count = 0;
  std::function<json(size_t)> run;
  std::function<double(size_t)> cost = [](size_t) { return 1.0; };
  std::function<std::string(size_t)> name = [](size_t i) { return "cell " + std::to_string(i); };
  bool timed = false;
};

// This rank's share of the work so far (finish() reports every rank's in `stats`).
struct RankStats {
  long cells = 0;
  double estimated_cost = 0, busy_seconds = 0;
};
inline RankStats& rank_stats() {
  static RankStats s;
  return s;
}

// Owner rank of each cell: longest processing time first, over `ranks` (each
// cell, by decreasing cost and then index, to the least loaded rank, ties to the
// lowest).  Every rank computes the same table.
inline std::vector<int> assign_cells(const std::vector<double>& cost, const std::vector<int>& ranks) {
  std::vector<size_t> order(cost.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return cost[a] > cost[b]; });
  std::vector<double> load(ranks.size(), 0.0);
  std::vector<int> owner(cost.size(), ranks.front());
  for (const size_t i : order) {
    const size_t r = static_cast<size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    owner[i] = ranks[r];
    load[r] += cost[i];
  }
  return owner;
}

// Fault injection for the tests (tests/test_cluster.cpp): NHI_STUDY_FAIL_CELL=K
// makes cell K of every phase throw, NHI_STUDY_KILL_CELL=K kills the process
// that runs it (SIGKILL).  -1 when unset.
inline long fault_cell(const char* var) {
  const char* v = std::getenv(var);
  return v ? std::atol(v) : -1;
}

namespace detail {

// The ranks that run the cells (timed cells: one per node, said once).
inline std::vector<int> cell_ranks(const Cells& c) {
  Cluster& cl = Cluster::get();
  std::vector<int> ranks;
  if (!c.timed) {
    for (int r = 0; r < cl.size(); ++r) ranks.push_back(r);
    return ranks;
  }
  ranks = cl.node_leaders();
  static bool told = false;
  if (cl.root() && !told && ranks.size() < static_cast<size_t>(cl.size())) {
    std::fprintf(stderr, "%s: timed cells run on one rank per node (%zu of %d ranks); the others wait\n",
                 c.label.c_str(), ranks.size(), cl.size());
    told = true;
  }
  return ranks;
}

// This rank's cells, costliest first (so that the threads finish together).
inline std::vector<size_t> own_cells(const Cells& c) {
  Cluster& cl = Cluster::get();
  std::vector<double> cost(c.count);
  for (size_t i = 0; i < c.count; ++i) cost[i] = c.cost(i);
  const std::vector<int> owner = assign_cells(cost, cell_ranks(c));
  std::vector<size_t> mine;
  RankStats& st = rank_stats();
  for (size_t i = 0; i < c.count; ++i)
    if (owner[i] == cl.rank()) {
      mine.push_back(i);
      st.estimated_cost += cost[i];
    }
  std::stable_sort(mine.begin(), mine.end(), [&](size_t a, size_t b) { return cost[a] > cost[b]; });
  return mine;
}

using CellErrors = std::vector<std::pair<size_t, std::string>>;

// Run `mine` on o.threads threads into out; the first cell that throws stops
// the others.  Fault injection for the tests: NHI_STUDY_FAIL_CELL (throws),
// NHI_STUDY_KILL_CELL (SIGKILL); NHI_STUDY_CELL_TIMES=1: each cell's wall
// seconds on stderr (where a study spends its time).
inline CellErrors run_own_cells(const Options& o, const Cells& c, const std::vector<size_t>& mine,
                                std::vector<json>* out) {
  Cluster& cl = Cluster::get();
  CellErrors errors;
  std::mutex m;
  std::atomic<bool> failed{false};
  const std::string label = cl.parallel() ? c.label + " (rank 0 of " + std::to_string(cl.size()) + ")" : c.label;
  Progress progress(label, static_cast<long>(mine.size()));
  const auto t0 = std::chrono::steady_clock::now();
  const long fail_cell = fault_cell("NHI_STUDY_FAIL_CELL"), kill_cell = fault_cell("NHI_STUDY_KILL_CELL");
  const bool cell_times = std::getenv("NHI_STUDY_CELL_TIMES") != nullptr;
  auto fail = [&](size_t i, std::string what) {
    std::lock_guard<std::mutex> lock(m);
    errors.emplace_back(i, std::move(what));
    failed = true;
  };
  parallel_for(
      mine.size(), o.threads,
      [&](size_t k) {
        if (failed.load()) return;
        const size_t i = mine[k];
        try {
          if (static_cast<long>(i) == kill_cell) std::raise(SIGKILL);
          if (static_cast<long>(i) == fail_cell) throw std::runtime_error("injected failure (NHI_STUDY_FAIL_CELL)");
          const auto c0 = std::chrono::steady_clock::now();
          (*out)[i] = c.run(i);
          if (cell_times)
            std::fprintf(stderr, "%s: cell %zu (%s): %.3f s\n", c.label.c_str(), i, c.name(i).c_str(),
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count());
        } catch (const std::exception& e) {
          fail(i, e.what());
        } catch (...) {
          fail(i, "unknown exception");
        }
      },
      cl.root() && !mine.empty() ? &progress : nullptr);
  RankStats& st = rank_stats();
  st.busy_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  st.cells += static_cast<long>(mine.size());
  return errors;
}

// Under MPI: every rank's cells (and errors, and interrupts) to every rank;
// each cell must arrive exactly once.
inline void gather_cells(const Cells& c, const std::vector<size_t>& mine, std::vector<json>* out, CellErrors* errors,
                         bool* interrupted) {
  Cluster& cl = Cluster::get();
  json part = {{"cells", json::array()}, {"errors", json::array()}, {"interrupted", *interrupted}};
  if (errors->empty() && !*interrupted)
    for (const size_t i : mine) part["cells"].push_back({i, std::move((*out)[i])});
  for (const auto& e : *errors) part["errors"].push_back({e.first, e.second});
  const std::vector<uint8_t> bytes = json::to_cbor(part);
  // Ranks without cells (a timed phase) wait asleep, not polling a core
  // that a timed rank of their node may be using.
  cl.quiet_barrier();
  const std::vector<std::string> all = cl.all_gather(std::string(bytes.begin(), bytes.end()));
  errors->clear();
  std::vector<int> received(c.count, 0);
  for (const std::string& b : all) {
    const json p = json::from_cbor(b);
    *interrupted = *interrupted || p["interrupted"].get<bool>();
    for (const json& e : p["errors"]) errors->emplace_back(e[0].get<size_t>(), e[1].get<std::string>());
    for (const json& cell : p["cells"]) {
      const size_t i = cell[0].get<size_t>();
      (*out)[i] = cell[1];
      ++received[i];
    }
  }
  // Every cell exactly once, or the ranks disagreed on the owner table
  // (their cost tables differ: another libm on another node?).
  if (!*interrupted && errors->empty())
    for (size_t i = 0; i < c.count; ++i)
      if (received[i] != 1) {
        errors->emplace_back(
            i, "received from " + std::to_string(received[i]) + " ranks (the ranks disagree on which rank runs it)");
        break;
      }
}

// An interrupt (exit 130) or a failed cell (exit 1, naming it) ends the study
// on every rank before anything is written.
inline void end_if_failed(const Cells& c, CellErrors errors, bool interrupted) {
  Cluster& cl = Cluster::get();
  if (interrupted) {
    if (cl.root()) std::fprintf(stderr, "%sstudy: interrupted; nothing written\n", end_progress_line());
    cl.exit_all(130);
  }
  if (errors.empty()) return;
  std::sort(errors.begin(), errors.end());
  if (cl.root()) {
    for (const auto& e : errors)
      std::fprintf(stderr, "%sstudy: %s: %s failed: %s\n", end_progress_line(), c.label.c_str(),
                   c.name(e.first).c_str(), e.second.c_str());
    std::fprintf(stderr, "study: failed; nothing written\n");
  }
  cl.exit_all(1);
}

}  // namespace detail

// Every cell's JSON, on every rank, in cell order.  This rank computes its
// cells on o.threads threads, costliest first; under MPI the ranks then exchange results.  A
// cell that throws, or an interrupt on any rank, ends the study on every rank
// (exit 1, naming the cell, or 130), before anything is written.
inline std::vector<json> map_cells(const Options& o, const Cells& c) {
  const std::vector<size_t> mine = detail::own_cells(c);
  std::vector<json> out(c.count);
  detail::CellErrors errors = detail::run_own_cells(o, c, mine, &out);
  bool interrupted = nhi::interrupt_flag().load();
  if (Cluster::get().parallel()) detail::gather_cells(c, mine, &out, &errors, &interrupted);
  detail::end_if_failed(c, std::move(errors), interrupted);
  return out;
}

// Write {result..., stats, meta} atomically from the first rank; an interrupted
// study writes nothing.  Collective: every rank calls it and returns its code.
// stats: the ranks, threads per rank, and per rank the cells it ran, their
// estimated cost and its busy (computing) wall seconds.
inline int finish(const Options& o, json result) {
  Cluster& cl = Cluster::get();
  const RankStats& st = rank_stats();
  const json mine = {st.cells, st.estimated_cost, st.busy_seconds, nhi::interrupt_flag().load()};
  const std::vector<uint8_t> bytes = json::to_cbor(mine);
  json stats = {{"ranks", cl.size()},
                {"threads_per_rank", o.threads},
                {"cells", json::array()},
                {"estimated_cost", json::array()},
                {"busy_seconds", json::array()}};
  bool interrupted = false;
  for (const std::string& b : cl.all_gather(std::string(bytes.begin(), bytes.end()))) {
    const json r = json::from_cbor(b);
    stats["cells"].push_back(r[0]);
    stats["estimated_cost"].push_back(r[1]);
    stats["busy_seconds"].push_back(r[2]);
    interrupted = interrupted || r[3].get<bool>();
  }
  stats["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time()).count();
  int code = 0;
  if (interrupted) {
    if (cl.root()) std::cerr << "study: interrupted; nothing written\n";
    code = 130;
  } else if (cl.root()) {
    result["stats"] = stats;
    result["meta"] = nhi::meta();
    try {
      nhi::AtomicFile f(o.out);
      f.commit(nhi::json_lines(result));
    } catch (const std::exception& e) {
      // AtomicFile's message names the path and says why (strerror).
      std::cerr << program_name() << ": error: " << e.what() << "; nothing written\n";
      code = 2;  // unwritable output (the exit-code contract)
    }
  }
  // Every rank leaves with the first rank's code.
  const std::vector<std::string> codes = cl.all_gather(std::to_string(code));
  code = std::atoi(codes.front().c_str());
  cl.finalize();
  return code;
}

// A JSON array of a vector's entries.
template <int N>
json to_json(const nhi::Vec<double, N>& v) {
  return std::vector<double>(v.data(), v.data() + N);
}

// q(T) of the reference solution at rtol = atol = tol.
// Systems whose motion tends to a limit in closed form (the sleigh: limit_motion,
// forward_speed): a run's error there is the error in the limit speed and heading.
template <class S, class = void>
struct has_limit_motion : std::false_type {};
template <class S>
struct has_limit_motion<S, std::void_t<decltype(&S::limit_motion), decltype(&S::forward_speed)>> : std::true_type {};

// Adds "limit_speed_error" and "limit_heading_error" (the heading is q[2]) of
// the late state (q, v) of a run from (q0, v0) to row, where the system has a closed-form limit and
// the run has reached its settle time t_end (else nothing).
template <class S>
void add_limit_errors(const S& sys, const nhi::Vec<double, S::n>& q0, const nhi::Vec<double, S::n>& v0, double t_end,
                      const nhi::Vec<double, S::n>& q, const nhi::Vec<double, S::n>& v, json* row) {
  if constexpr (has_limit_motion<S>::value) {
    double speed = 0, heading = 0, settle = 0;
    if (!sys.limit_motion(q0, v0, &speed, &heading, &settle) || t_end < settle) return;
    (*row)["limit_speed_error"] = std::abs(S::forward_speed(q, v) - speed);
    (*row)["limit_heading_error"] = std::abs(q[2] - heading);
  }
}

template <class S>
nhi::Vec<double, S::n> reference_q(const S& sys, const nhi::Vec<double, S::n>& q0, const nhi::Vec<double, S::n>& v0,
                                   double T, double tol) {
  nhi::Vec<double, S::n> q;
  nhi::reference_solution(sys, q0, v0, T, tol, &q);
  return q;
}

}  // namespace study
