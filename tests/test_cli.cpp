// The `nhi` command line (run, list), driven as a user (or an outside check) drives it:
// exit codes, one-line errors, result files whole or absent.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "nhi/runner/scene.hpp"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

struct Result {
  int code;
  std::string err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("nhi_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  Result run(const std::string& args) const {
    const std::string err = path("stderr.txt");
    const int status = std::system((std::string(NHI_BINARY) + " " + args + " 2> " + err).c_str());
    std::ifstream in(err);
    std::stringstream ss;
    ss << in.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
  }
  static std::string scene() { return std::string(NHI_SCENES) + "/particle.json"; }
  fs::path dir_;
};

TEST_F(Cli, RunWritesTheResultContract) {
  const std::string out = path("r.json");
  const Result r = run("run " + scene() + " --set steps=20 -o " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const json j = json::parse(std::ifstream(out));
  EXPECT_EQ(j["status"], "ok");
  for (const char* k : {"scene", "t", "q", "v", "energy", "constraint", "p", "lambda", "stats", "meta", "summary"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["t"].size(), 21u);
  EXPECT_EQ(j["q"][20].size(), 3u);
  EXPECT_EQ(j["constraint"][0].size(), 1u);
  EXPECT_EQ(j["scene"]["steps"], 20);
  EXPECT_TRUE(j["meta"].contains("git_revision"));
  EXPECT_TRUE(j["stats"].contains("newton_iterations"));
  EXPECT_TRUE(j["stats"].contains("cpu_seconds"));
}

TEST_F(Cli, EveryMethodRuns) {
  for (const char* m : {"dla", "rk4", "benchmark"}) {
    const std::string out = path(std::string(m) + ".json");
    const Result r = run("run " + scene() + " --set method=" + m + " --set steps=5 -o " + out);
    ASSERT_EQ(r.code, 0) << m << ": " << r.err;
    const json j = json::parse(std::ifstream(out));
    EXPECT_EQ(j["t"].size(), 6u) << m;
    EXPECT_EQ(j.contains("p"), std::string(m) == "dla");
  }
}

// Hostile scene files through `nhi run`: each is rejected with exit 2 and one
// line on stderr, creates no output file, and leaves an existing one as it was.
struct BadScene {
  const char* what;
  std::string text;  // the scene file's contents
  std::string set;   // extra command-line arguments
};

json particle_scene() {
  return json::parse(R"({"system": "particle", "q0": [1, 0.5, 0], "v0": [0.5, 1, 0.25],
                         "method": "dla", "h": 0.2, "steps": 10})");
}
json robot_scene() {
  return json::parse(R"({"system": "robot", "q0": [0, 0, 0, 0], "v0": [1, 0, 1, 1],
                         "method": "dla", "h": 0.2, "steps": 10})");
}
std::string edited(json s, const std::function<void(json&)>& edit) {
  edit(s);
  return s.dump();
}
// The particle scene's text with one value replaced by raw text (for non-JSON literals).
std::string raw(const std::string& key, const std::string& value) {
  json s = particle_scene();
  s[key] = "@@";
  std::string t = s.dump();
  return t.replace(t.find("\"@@\""), 4, value);
}

std::vector<BadScene> bad_scenes() {
  using F = std::function<void(json&)>;
  auto P = [](const F& f) { return edited(particle_scene(), f); };
  auto R = [](const F& f) { return edited(robot_scene(), f); };
  return {
      {"truncated JSON", R"({"system": "particle", "q0": [1, 0.5)", ""},
      // Nested 10^5 deep: printing or walking it overflowed the stack (exit 139).
      {"an array nested 100000 deep", std::string(100000, '[') + std::string(100000, ']'), ""},
      {"a scene key nested 100000 deep", raw("q0", std::string(100000, '[') + "1" + std::string(100000, ']')), ""},
      // (A command-line argument is limited to 128 KiB: 1000 levels.)
      {"--set value nested 1000 deep", particle_scene().dump(),
       "--set 'q0=" + std::string(1000, '[') + std::string(1000, ']') + "'"},
      {"empty file", "", ""},
      {"not an object", "[1, 2, 3]", ""},
      {"a bare string", "\"particle\"", ""},
      {"trailing garbage", particle_scene().dump() + " }", ""},
      {"h a string", P([](json& s) { s["h"] = "0.2"; }), ""},
      {"q0 a string", P([](json& s) { s["q0"] = "1 0.5 0"; }), ""},
      {"steps a boolean", P([](json& s) { s["steps"] = true; }), ""},
      {"h null", P([](json& s) { s["h"] = nullptr; }), ""},
      {"q0 nested arrays", P([](json& s) { s["q0"] = json::parse("[[1], [0.5], [0]]"); }), ""},
      {"missing system", P([](json& s) { s.erase("system"); }), ""},
      {"missing q0", P([](json& s) { s.erase("q0"); }), ""},
      {"missing steps", P([](json& s) { s.erase("steps"); }), ""},
      {"unknown key", P([](json& s) { s["stepz"] = 10; }), ""},
      {"unknown parameter", P([](json& s) {
         s["params"] = {{"mass", 2}};
       }),
       ""},
      {"params an array", P([](json& s) {
         s["params"] = {1, 2};
       }),
       ""},
      {"empty q0", P([](json& s) { s["q0"] = json::array(); }), ""},
      {"empty v0", P([](json& s) { s["v0"] = json::array(); }), ""},
      {"NaN literal", raw("h", "NaN"), ""},
      {"Infinity literal", raw("h", "Infinity"), ""},
      {"number overflowing a double", raw("h", "1e999"), ""},
      {"huge q0 entry", raw("q0", "[1e300, 0.5, 0]"), ""},
      {"huge parameter", P([](json& s) {
         s["params"] = {{"kx", 1e200}};
       }),
       ""},
      {"huge steps", raw("steps", "1e30"), ""},
      {"alpha just above 1", P([](json& s) { s["alpha"] = 1.0000001; }), ""},
      {"alpha just below 0", P([](json& s) { s["alpha"] = -1e-9; }), ""},
      {"h zero", P([](json& s) { s["h"] = 0; }), ""},
      {"h negative", P([](json& s) { s["h"] = -0.2; }), ""},
      {"steps zero", P([](json& s) { s["steps"] = 0; }), ""},
      {"steps negative", P([](json& s) { s["steps"] = -5; }), ""},
      {"steps non-integer", P([](json& s) { s["steps"] = 2.5; }), ""},
      {"output_every zero", P([](json& s) { s["output_every"] = 0; }), ""},
      {"tolerance zero", P([](json& s) { s["tolerance"] = 0; }), ""},
      {"particle q0 of length 4", P([](json& s) {
         s["q0"] = {1, 0.5, 0, 0};
       }),
       ""},
      {"particle v0 of length 2", P([](json& s) {
         s["v0"] = {0.5, 1};
       }),
       ""},
      {"robot q0 of length 3", R([](json& s) {
         s["q0"] = {0, 0, 0};
       }),
       ""},
      {"robot v0 of length 5", R([](json& s) {
         s["v0"] = {1, 0, 1, 1, 0};
       }),
       ""},
      {"particle v0 off the constraint", P([](json& s) {
         s["v0"] = {0.5, 1, 0.3};
       }),
       ""},
      {"robot v0 off the constraint", R([](json& s) {
         s["v0"] = {1, 0.1, 1, 1};
       }),
       ""},
      {"robot with a particle parameter", R([](json& s) {
         s["params"] = {{"kx", 1}};
       }),
       ""},
      {"robot with a negative mass", R([](json& s) {
         s["params"] = {{"m", -1}};
       }),
       ""},
      {"unknown system", P([](json& s) { s["system"] = "pendulum"; }), ""},
      {"unknown method", P([](json& s) { s["method"] = "euler"; }), ""},
      {"unknown discretization", P([](json& s) { s["discretization"] = "trapezoid"; }), ""},
      // Bad overrides on a good scene.
      {"--set without =", particle_scene().dump(), "--set steps"},
      {"--set unknown key", particle_scene().dump(), "--set colour=3"},
      {"--set h=1e400", particle_scene().dump(), "--set h=1e400"},
      {"--set q0 too short", particle_scene().dump(), "--set 'q0=[1,2]'"},
      // Found by make fuzz: a string value with invalid UTF-8 made the message
      // itself throw (nlohmann type_error 316) instead of naming the key.
      {"--set value with invalid UTF-8", particle_scene().dump(), "--set 'h=\x86\x86'"},
  };
}

TEST_F(Cli, HostileScenesFailWithOneLineAndTouchNoFile) {
  const std::vector<BadScene> cases = bad_scenes();
  EXPECT_GE(cases.size(), 25u);
  const std::string fresh = path("fresh.json"), existing = path("existing.json");
  std::ofstream(existing) << "precious";
  int i = 0;
  for (const BadScene& c : cases) {
    const std::string file = write("bad" + std::to_string(i++) + ".json", c.text);
    for (const std::string& out : {fresh, existing}) {
      const Result r = run("run " + file + " " + c.set + " -o " + out);
      EXPECT_EQ(r.code, 2) << c.what << ": " << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.what << ": " << r.err;
      EXPECT_EQ(r.err.rfind("nhi: error: ", 0), 0u) << c.what << ": " << r.err;
    }
    EXPECT_FALSE(fs::exists(fresh)) << c.what << " created an output file";
    std::ifstream in(existing);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), "precious") << "output clobbered by: " << c.what;
  }
  // No temporary files left behind.
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

// A scene nested beyond the limit is refused while it is parsed, by a message
// naming the limit (deeper values would overflow the stack).
TEST_F(Cli, DeeplyNestedSceneIsRefusedNamingTheLimit) {
  const std::string file = write("deep.json", std::string(100000, '[') + std::string(100000, ']'));
  const std::string out = path("deep_out.json");
  const Result r = run("run " + file + " -o " + out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("nested deeper than 64 levels"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// A run whose recorded points cannot fit in memory is refused before it starts
// exit 2, one line naming output_every, nothing written.
TEST_F(Cli, RunTooLargeForMemoryIsRefusedBeforeItStarts) {
  const std::string out = path("big.json");
  const Result r = run("run " + scene() + " --set method=rk4 --set h=0.01 --set steps=100000000 -o " + out);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("scene key 'output_every'"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

// `nhi list` names every registered system with its parameters' defaults,
// every study method and every composition, as text, Markdown and JSON; every
// system and method it lists runs from a scene.
TEST_F(Cli, ListNamesEverySystemMethodAndComposition) {
  const std::string out = path("list.json");
  ASSERT_EQ(run("list --json > " + out).code, 0);
  const json c = json::parse(std::ifstream(out));
  std::vector<std::string> systems;
  for (const auto& s : c["systems"]) systems.push_back(s["name"]);
  EXPECT_EQ(systems, nhi::system_names());
  ASSERT_FALSE(c["methods"].empty());
  for (const auto& s : c["systems"]) EXPECT_FALSE(s["params"].empty()) << s["name"];
  std::set<std::string> kinds;
  for (const auto& m : c["methods"]) {
    kinds.insert(m["method"].get<std::string>());
    EXPECT_GE(m["order"].get<int>(), 1) << m["label"];
  }
  const std::vector<std::string> names = nhi::registered_method_names();
  EXPECT_EQ(kinds, std::set<std::string>(names.begin(), names.end()));
  EXPECT_EQ(c["compositions"].size(), 4u);
  // Each listed method runs on the default state of each system it lists as studied on
  // (eps-cayley on the Suslov body only, dla-group on the rigid bodies).
  for (const auto& s : c["systems"])
    for (const auto& m : c["methods"]) {
      const auto& on = m["systems"];
      if (std::find(on.begin(), on.end(), s["name"]) == on.end()) continue;
      json scene = {{"system", s["name"]},
                    {"q0", s["q0"]},
                    {"v0", s["v0"]},
                    {"method", m["method"]},
                    {"composition", m["composition"]},
                    {"h", 0.05},
                    {"steps", 3}};
      if (!m["discretization"].is_null()) scene["discretization"] = m["discretization"], scene["alpha"] = m["alpha"];
      EXPECT_EQ(run("run " + write("listed.json", scene.dump()) + " -o " + path("listed_out.json")).code, 0)
          << s["name"] << " " << m["label"];
    }
  const std::string md = path("list.md");
  ASSERT_EQ(run("list --markdown > " + md).code, 0);
  std::stringstream text;
  text << std::ifstream(md).rdbuf();
  for (const char* heading : {"## scenes\n", "## methods\n", "## compositions\n"})
    EXPECT_NE(text.str().find(heading), std::string::npos) << heading;
  EXPECT_EQ(run("list --markdown --json").code, 2);
}

// plots/method_styles.gp is what `nhi list --gnuplot` writes from the methods'
// declared line styles (make figures rewrites it): a method added or restyled
// without it fails here, with the file's new text.
TEST_F(Cli, MethodStylesFileIsTheMethodsDeclaredStyles) {
  const std::string out = path("method_styles.gp");
  ASSERT_EQ(run("list --gnuplot > " + out).code, 0);
  std::stringstream now, committed;
  now << std::ifstream(out).rdbuf();
  committed << std::ifstream(NHI_SOURCE_DIR "/plots/method_styles.gp").rdbuf();
  EXPECT_EQ(committed.str(), now.str()) << "plots/method_styles.gp is stale: run `build/bin/nhi list --gnuplot > "
                                           "plots/method_styles.gp` (or make figures)";
  EXPECT_NE(now.str().find("label eq \"dla a=0.5\" ? 11 :"), std::string::npos) << now.str();
}

TEST_F(Cli, BadCommandLinesFailWithOneLine) {
  const std::string out = path("out.json");
  std::ofstream(out) << "precious";
  for (const std::string& args : {"run " + path("missing.json") + " -o " + out, "run -o " + out,
                                  "run " + scene() + " -o " + out + " --bogus", "fly " + scene()}) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  std::ifstream in(out);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "precious");
}

TEST_F(Cli, OutputPathThatIsADirectoryOrUnwritableFails) {
  EXPECT_EQ(run("run " + scene() + " -o " + dir_.string()).code, 2);
  EXPECT_EQ(run("run " + scene() + " -o " + path("no/such/dir/r.json")).code, 2);
}

TEST_F(Cli, UnconvergedStepEndsTheRunAsFailedAndKeepsTheTrajectory) {
  // A tolerance below round-off cannot be met: the very first solve fails,
  // through Newton and the TinySolver fallback, and the run says so.
  const std::string out = path("f.json");
  const Result r = run("run " + scene() + " --set tolerance=1e-30 -o " + out);
  EXPECT_EQ(r.code, 3) << r.err;
  const json j = json::parse(std::ifstream(out));
  EXPECT_EQ(j["status"], "failed");
  EXPECT_EQ(j["failure"]["step"], 1);
  EXPECT_NE(j["failure"]["reason"].get<std::string>().find("did not converge"), std::string::npos);
  // A DLA point k is complete (lambda_k, v_k) only once q_{k+1} is known: none is.
  EXPECT_EQ(j["t"].size(), 0u);
}

// A whole result file with status "failed": the failing step, its reason, and
// every point before it, consecutive (output_every = 1).
void expect_complete_failed_run(const json& j, double h, long complete_points, const std::string& reason) {
  EXPECT_EQ(j["status"], "failed");
  EXPECT_NE(j["failure"]["reason"].get<std::string>().find(reason), std::string::npos) << j["failure"];
  ASSERT_EQ(j["t"].size(), static_cast<size_t>(complete_points));
  for (long k = 0; k < complete_points; ++k) EXPECT_DOUBLE_EQ(j["t"][k].get<double>(), k * h);
  EXPECT_EQ(j["q"].size(), j["t"].size());
  EXPECT_EQ(j["energy"].size(), j["t"].size());
  EXPECT_EQ(j["summary"]["points"], complete_points);
}

TEST_F(Cli, IllPosedStepEndsTheRunAsFailedWithEveryStepBefore) {
  // The robot at h = 1: at step 5 the DLA equations (6) have no solution near
  // the guess (Newton and Levenberg-Marquardt both stall at a residual ~0.1).
  // (Its energy error passes max(|E0|, 1) at step 1: the energy limit is
  // turned off to reach the solve's failure.)
  const std::string out = path("ill.json");
  const Result r = run("run " + std::string(NHI_SCENES) + "/robot.json --set h=1 --set steps=200 --set energy_limit=off -o " +
                       out);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const json j = json::parse(std::ifstream(out));
  const long step = j["failure"]["step"];
  EXPECT_GT(step, 1);
  // A DLA point k needs q_{k+1}: the failing solve for q_j leaves points 0..j-2.
  expect_complete_failed_run(j, 1.0, step - 1, "did not converge");
}

TEST_F(Cli, NonFiniteStateEndsTheRunAsFailedWithEveryStepBefore) {
  // RK4 far outside its stability interval overflows (with the energy limit
  // off: on, the run fails at step 1, its energy error already 1.6e4).
  const std::string out = path("inf.json");
  const Result r = run("run " + scene() + " --set method=rk4 --set h=5 --set steps=2000 --set energy_limit=off -o " + out);
  EXPECT_EQ(r.code, 3) << r.err;
  const json j = json::parse(std::ifstream(out));
  const long step = j["failure"]["step"];
  EXPECT_GT(step, 1);
  EXPECT_LT(step, 2000);
  expect_complete_failed_run(j, 5.0, step, "non-finite");
  for (const auto& q : j["q"])
    for (const auto& x : q) EXPECT_TRUE(x.is_number()) << "a recorded state is not finite";
}

// Peak resident memory (kB) of one `nhi run`, from the kernel's accounting of the child.
long peak_rss_kb(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(NHI_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::freopen("/dev/null", "w", stderr);
    ::execv(NHI_BINARY, argv.data());
    ::_exit(127);
  }
  int status = 0;
  rusage ru{};
  ::wait4(pid, &status, 0, &ru);
  return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? ru.ru_maxrss : -1;
}

#if defined(__SANITIZE_ADDRESS__)
#define NHI_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NHI_ASAN 1
#endif
#endif

TEST_F(Cli, MemoryDoesNotGrowWithTheNumberOfSteps) {
#ifdef NHI_ASAN
  GTEST_SKIP() << "AddressSanitizer's quarantine and shadow memory make peak RSS meaningless";
#endif
  // Ten times the steps with the same number of recorded points (the stride
  // scales): the peak must not move by more than page-level noise.  Keeping
  // anything per step (even 100 bytes) would add 90 MB to the longer run.
  for (const char* sc : {"particle", "robot"}) {
    const std::string file = std::string(NHI_SCENES) + "/" + sc + ".json", out = path("m.json");
    const long a = peak_rss_kb({"run", file, "--set", "steps=100000", "--set", "output_every=10000", "-o", out});
    const long b = peak_rss_kb({"run", file, "--set", "steps=1000000", "--set", "output_every=100000", "-o", out});
    std::printf("    %s: peak RSS %ld kB at 1e5 steps, %ld kB at 1e6 steps (11 recorded points each)\n", sc, a, b);
    ASSERT_GT(a, 0);
    ASSERT_GT(b, 0);
    EXPECT_LT(std::abs(b - a), 1024) << sc;
    // and the summary's maxima are over every step, not just the recorded ones
    const json j = json::parse(std::ifstream(out));
    EXPECT_EQ(j["summary"]["points"], 11);
    double recorded = 0;
    for (const auto& e : j["energy"])
      recorded = std::max(recorded, std::abs(e.get<double>() - j["energy"][0].get<double>()));
    EXPECT_GE(j["summary"]["max_abs_energy_error"].get<double>(), recorded);
  }
}

TEST_F(Cli, SameSceneGivesBitIdenticalResults) {
  for (const char* m : {"dla", "rk4", "benchmark"}) {
    const std::string a = path("a.json"), b = path("b.json");
    ASSERT_EQ(run("run " + scene() + " --set method=" + m + " --set steps=300 -o " + a).code, 0);
    ASSERT_EQ(run("run " + scene() + " --set method=" + m + " --set steps=300 -o " + b).code, 0);
    const json ja = json::parse(std::ifstream(a)), jb = json::parse(std::ifstream(b));
    for (const char* k : {"q", "v", "energy", "constraint", "summary"}) EXPECT_EQ(ja[k], jb[k]) << m << " " << k;
    if (std::string(m) == "dla") {
      EXPECT_EQ(ja["p"], jb["p"]);
      EXPECT_EQ(ja["lambda"], jb["lambda"]);
    }
  }
}

TEST_F(Cli, StudyResultsDoNotDependOnTheNumberOfThreads) {
  const std::string one = path("one.json"), two = path("two.json");
  // Every scene, over a hundredth of the study's horizon: the cells and their
  // order are the study's own, and the run stays short under the sanitizers,
  // costly methods included (the roots followed from h = 1 on: their cells
  // too, fewer of them).
  const std::string scenes = std::string(" --T 2 --roots-from 1 --scenes ") + NHI_SCENES;
  ASSERT_EQ(std::system((std::string(NHI_STABILITY) + " --threads 1 -o " + one + scenes + " 2>/dev/null").c_str()), 0);
  ASSERT_EQ(std::system((std::string(NHI_STABILITY) + " --threads 2 -o " + two + scenes + " 2>/dev/null").c_str()), 0);
  json a = json::parse(std::ifstream(one)), b = json::parse(std::ifstream(two));
  EXPECT_EQ(a["stats"]["threads_per_rank"], 1);
  EXPECT_EQ(b["stats"]["threads_per_rank"], 2);
  for (json* j : {&a, &b}) {
    j->erase("meta");
    j->erase("stats");  // threads and busy times
  }
  EXPECT_EQ(a, b);  // bit-identical numbers: JSON doubles round-trip exactly
}

TEST_F(Cli, InterruptedRunWritesNothing) {
  for (const int sig : {SIGTERM, SIGINT}) {
    const std::string out = path("i.json");
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const std::string sc = scene();
      ::execl(NHI_BINARY, NHI_BINARY, "run", sc.c_str(), "--set", "steps=2000000000", "--set", "output_every=100000000",
              "-o", out.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Wait until the run has claimed its temporary output (the handlers are
    // installed before that), then interrupt it: the run itself would take minutes.
    auto claimed = [&] {
      for (const auto& e : fs::directory_iterator(dir_))
        if (e.path().filename().string().find("i.json.tmp.") == 0) return true;
      return false;
    };
    for (int i = 0; i < 2000 && !claimed(); ++i) ::usleep(5000);
    if (!claimed()) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      FAIL() << "the run never started";
    }
    ::usleep(100000);
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << "signal " << sig;
    EXPECT_EQ(WEXITSTATUS(status), 130) << "signal " << sig;
    EXPECT_FALSE(fs::exists(out)) << "signal " << sig;
    for (const auto& e : fs::directory_iterator(dir_))
      EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
  }
}

// bench_steps' shards (make reproduce runs --shard 0/2 and 1/2 side by side):
// together they hold every row of the unsharded run, each row once, each
// scene whole (a row's ratio to its scene's RK4 is measured in one
// process); --merge joins shard results, recomputes each ratio against its
// scene's RK4, and refuses a row in two shards or a file that is not a
// bench_steps result, writing nothing.  Rows are listed, not timed
// (--benchmark_list_tests), and the merge runs on small hand-made results.
TEST_F(Cli, BenchShardsPartitionTheRowsAndMergeJoinsThem) {
  auto list = [&](const std::string& args) {
    const std::string out = path("list.txt");
    const int status = std::system(
        (std::string(NHI_BENCH) + " --benchmark_list_tests=true " + args + " > " + out + " 2> " + path("list_err.txt"))
            .c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << args;
    std::ifstream in(out);
    std::vector<std::string> rows;
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) rows.push_back(line);
    return rows;
  };
  auto scene_of = [](const std::string& row) { return row.substr(0, row.find('/')); };
  const std::vector<std::string> all = list(""), s0 = list("--shard 0/2"), s1 = list("--shard 1/2");
  ASSERT_GT(all.size(), 20u);
  ASSERT_FALSE(s0.empty());
  ASSERT_FALSE(s1.empty());
  std::vector<std::string> joined = s0;
  joined.insert(joined.end(), s1.begin(), s1.end());
  std::sort(joined.begin(), joined.end());
  std::vector<std::string> sorted = all;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(joined, sorted);  // every row once
  for (const auto& a : s0)
    for (const auto& b : s1) EXPECT_NE(scene_of(a), scene_of(b)) << a << " and " << b;  // scenes whole
  for (const auto& shards :
       {std::vector<std::string>{"--shard 2/2"}, {"--shard 1/0"}, {"--shard x"}, {"--shard 1/2/3"}})
    EXPECT_EQ(std::system((std::string(NHI_BENCH) + " " + shards[0] + " > /dev/null 2>&1").c_str()) >> 8, 2)
        << shards[0];

  auto row = [](const std::string& name, double ns) { return json{{"name", name}, {"cpu_ns", ns}}; };
  const std::string a =
      write("a.json",
            json{{"study", "step_costs"}, {"benchmarks", {row("particle/rk4", 40), row("particle/mp06", 50)}}}.dump());
  const std::string b = write(
      "b.json", json{{"study", "step_costs"}, {"benchmarks", {row("robot/rk4", 100), row("robot/mp06", 90)}}}.dump());
  const std::string out = path("merged.json");
  auto merge = [&](const std::string& files) {
    return std::system((std::string(NHI_BENCH) + " --merge " + files + " -o " + out + " 2> " + path("merge_err.txt"))
                           .c_str()) >>
           8;
  };
  ASSERT_EQ(merge(a + " " + b), 0);
  const json m = json::parse(std::ifstream(out));
  ASSERT_EQ(m["benchmarks"].size(), 4u);
  for (const auto& r : m["benchmarks"]) {
    const double expect = r["name"] == "particle/mp06" ? 50.0 / 40 : r["name"] == "robot/mp06" ? 0.9 : 1.0;
    EXPECT_DOUBLE_EQ(r["ratio_to_rk4"].get<double>(), expect) << r["name"];
  }
  fs::remove(out);
  const std::string bad = write("bad.json", R"({"study": "convergence", "benchmarks": []})");
  const std::string nameless = write("nameless.json", R"({"study": "step_costs", "benchmarks": [{"cpu_ns": 1}]})");
  const std::string broken = write("broken.json", R"({"study": "step_costs", "bench)");
  for (const std::string& files : {a + " " + a, a + " " + bad, nameless, broken, a + " " + path("missing.json")}) {
    EXPECT_EQ(merge(files), 1) << files;
    EXPECT_FALSE(fs::exists(out)) << files;
  }
}

}  // namespace
