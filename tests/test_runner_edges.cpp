// The runner's edges, driven as a user drives the binaries:
// a study started away from the repository root, `nhi --version`, an unknown
// subcommand, "did you mean" for scene keys and values, NaN and Infinity named
// in messages (null in result files), progress on a terminal or a log, and
// file errors that say why.
#include <gtest/gtest.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "nhi/runner/output.hpp"
#include "nhi/runner/scene.hpp"
#include "nhi/runner/scene_detail.hpp"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
namespace sd = nhi::scene_detail;

struct Result {
  int code;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

long lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }

class RunnerEdges : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("nhi_edges_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "work");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // `command` run by the shell in dir_/work (away from the repository root),
  // its standard output and error captured in files outside that directory.
  Result sh(const std::string& command) const {
    const std::string out = path("stdout.txt"), err = path("stderr.txt");
    const std::string line = "cd '" + (dir_ / "work").string() + "' && " + command + " > " + out + " 2> " + err;
    const int status = std::system(line.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
  }
  Result nhi(const std::string& args) const { return sh(std::string(NHI_BINARY) + " " + args); }
  Result stability(const std::string& args) const { return sh(std::string(NHI_STABILITY) + " " + args); }
  bool work_empty() const { return fs::is_empty(dir_ / "work"); }
  fs::path dir_;
};

const char* kHint = "(run from the repository root, or pass --scenes DIR)";

// ---- 1. A study away from the repository root -------------------------------

// Exit 134 (an uncaught nhi::SceneError) before: now one line naming the
// scene file and the way out, exit 2, nothing written.
TEST_F(RunnerEdges, StudyAwayFromTheRepositoryRootFailsWithOneLineAndExit2) {
  const Result r = stability("--only particle --T 2 -o x.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("study_stability: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("experiments/scenes/particle.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(kHint), std::string::npos) << r.err;
  EXPECT_TRUE(work_empty()) << "a study that failed wrote something";
}

TEST_F(RunnerEdges, StudyWithAMissingOrBadScenesDirectoryFailsWithOneLineAndExit2) {
  const Result missing = stability("--only particle --T 2 --scenes " + path("no_such_dir") + " -o x.json");
  EXPECT_EQ(missing.code, 2) << missing.err;
  EXPECT_EQ(lines(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find(kHint), std::string::npos) << missing.err;

  // A scene file that is there but not valid (a misspelt key).
  fs::create_directories(dir_ / "scenes");
  json particle = json::parse(std::ifstream(std::string(NHI_SCENES) + "/particle.json"));
  particle["stepz"] = 3;
  std::ofstream(dir_ / "scenes" / "particle.json") << particle.dump();
  const Result bad = stability("--only particle --T 2 --scenes " + path("scenes") + " -o x.json");
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_EQ(lines(bad.err), 1) << bad.err;
  EXPECT_EQ(bad.err.rfind("study_stability: error: scene key 'stepz'", 0), 0u) << bad.err;
  EXPECT_TRUE(work_empty());
}

// ---- 7 (studies). An unwritable output fails before the study runs ---------

// Before: the study ran to the end, then exited 1.  Now: exit 2 at once, one
// line saying why (strerror), nothing created.
TEST_F(RunnerEdges, StudyWithAnUnwritableOutputFailsBeforeRunningSayingWhy) {
  const std::string scenes = std::string(" --scenes ") + NHI_SCENES;
  const Result nodir = stability("--only particle --T 2" + scenes + " -o no/such/dir/x.json");
  EXPECT_EQ(nodir.code, 2) << nodir.err;
  EXPECT_EQ(lines(nodir.err), 1) << nodir.err;
  EXPECT_NE(nodir.err.find(std::strerror(ENOENT)), std::string::npos) << nodir.err;
  EXPECT_EQ(nodir.err.find(" runs"), std::string::npos) << "the study ran: " << nodir.err;

  const Result isdir = stability("--only particle --T 2" + scenes + " -o " + path("work"));
  EXPECT_EQ(isdir.code, 2) << isdir.err;
  EXPECT_NE(isdir.err.find("is a directory"), std::string::npos) << isdir.err;
  EXPECT_TRUE(work_empty());
}

// A bad command line: exit 2 (CLI11's own codes, 105-109, before) and one line.
TEST_F(RunnerEdges, StudyBadCommandLineExits2WithOneLine) {
  for (const std::string& args : {std::string(""), std::string("-o x.json --threads 0"),
                                  std::string("-o x.json --only pendulum"), std::string("-o x.json --bogus")}) {
    const Result r = stability(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("study_stability: error: ", 0), 0u) << args << ": " << r.err;
  }
  EXPECT_EQ(stability("--help").code, 0);
  EXPECT_TRUE(work_empty());
}

// ---- 2. nhi --version ---------------------------------------------------------

TEST_F(RunnerEdges, VersionPrintsTheProjectVersionCompilerAndBuildFlags) {
  const Result r = nhi("--version");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out.rfind(std::string("nhi ") + NHI_PROJECT_VERSION + "\n", 0), 0u) << r.out;
  const json m = nhi::meta();  // the same library the binary links
  EXPECT_NE(r.out.find("compiler: " + m["compiler"].get<std::string>() + "\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("build flags: " + m["build_flags"].get<std::string>() + "\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(m["git_revision"].get<std::string>()), std::string::npos) << r.out;
}

// ---- 3. An unknown subcommand is named ------------------------------------------

TEST_F(RunnerEdges, UnknownSubcommandIsNamedWithASuggestionWhenClose) {
  const std::map<std::string, std::string> expect = {
      {"lst", "nhi: error: unknown subcommand \"lst\" (expected run or list); did you mean \"list\"?\n"},
      {"rnu", "nhi: error: unknown subcommand \"rnu\" (expected run or list); did you mean \"run\"?\n"},
      {"LIST", "nhi: error: unknown subcommand \"LIST\" (expected run or list); did you mean \"list\"?\n"},
      {"fly", "nhi: error: unknown subcommand \"fly\" (expected run or list)\n"},
  };
  for (const auto& [sub, message] : expect) {
    const Result r = nhi(sub + " " + NHI_SCENES + "/particle.json");
    EXPECT_EQ(r.code, 2) << sub;
    EXPECT_EQ(r.err, message);
  }
  // Still: no subcommand at all, and a known one with a bad option.
  for (const std::string& args : {std::string(""), std::string("list --bogus")}) {
    const Result r = nhi(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
    EXPECT_EQ(r.err.find("unknown subcommand"), std::string::npos) << args << ": " << r.err;
  }
  EXPECT_TRUE(work_empty());
}

// ---- 4. Did you mean ----------------------------------------------------------------

TEST(DidYouMean, DamerauLevenshteinDistance) {
  EXPECT_EQ(sd::edit_distance("", ""), 0u);
  EXPECT_EQ(sd::edit_distance("abc", ""), 3u);
  EXPECT_EQ(sd::edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(sd::edit_distance("mp6", "mp06"), 1u);
  EXPECT_EQ(sd::edit_distance("stpes", "steps"), 1u);  // a transposition is one edit
  EXPECT_EQ(sd::edit_distance("ca", "abc"), 3u);       // optimal string alignment, not unrestricted
}

TEST(DidYouMean, SuggestsTheNearestNameWithinAThirdOfTheLength) {
  const std::vector<std::string> methods = {"dla", "rk4", "benchmark", "mp06", "discrete_gradient", "spark"};
  EXPECT_EQ(sd::did_you_mean("mp6", methods), "; did you mean \"mp06\"?");
  EXPECT_EQ(sd::did_you_mean("RK4", methods), "; did you mean \"rk4\"?");
  EXPECT_EQ(sd::did_you_mean("discrete-gradiant", methods), "; did you mean \"discrete_gradient\"?");
  EXPECT_EQ(sd::did_you_mean("benchmrak", methods), "; did you mean \"benchmark\"?");
  EXPECT_EQ(sd::did_you_mean("euler", methods), "");
  EXPECT_EQ(sd::did_you_mean("ab", methods), "");     // max(1, 2/3) = 1 edit: "dla" is 2 away
  EXPECT_EQ(sd::did_you_mean("dla", methods), "");    // a known name is not a typo
  EXPECT_EQ(sd::did_you_mean(std::string(100000, 'x'), methods), "");
  EXPECT_EQ(sd::did_you_mean("x", {}), "");
}

// The message of the SceneError that f throws ("" if none).
template <class F>
std::string scene_error(F&& f) {
  try {
    f();
  } catch (const nhi::SceneError& e) {
    return e.what();
  }
  return "";
}

json particle() {
  return json::parse(R"({"system": "particle", "q0": [1, 0.5, 0], "v0": [0.5, 1, 0.25],
                         "method": "dla", "h": 0.2, "steps": 10})");
}

TEST(DidYouMean, SceneValuesKeysAndParameters) {
  json s = particle();
  s["method"] = "mp6";
  const std::string method = scene_error([&] { nhi::validate_scene(s); });
  EXPECT_EQ(method.rfind("scene key 'method': unknown value \"mp6\" (expected one of \"dla\", ", 0), 0u) << method;
  const std::string tail = "\"); did you mean \"mp06\"?";
  ASSERT_GE(method.size(), tail.size());
  EXPECT_EQ(method.substr(method.size() - tail.size()), tail) << method;
  s = particle();
  s["system"] = "partcle";
  EXPECT_NE(scene_error([&] { nhi::validate_scene(s); }).find("did you mean \"particle\"?"), std::string::npos);
  s = particle();
  s["composition"] = "triplejump";
  EXPECT_NE(scene_error([&] { nhi::validate_scene(s); }).find("did you mean \"triple_jump\"?"), std::string::npos);
  s = particle();
  s["method"] = "euler";
  EXPECT_EQ(scene_error([&] { nhi::validate_scene(s); }).find("did you mean"), std::string::npos);

  // params.NAME (make_system)
  s = particle();
  s["params"] = {{"KY", 2.0}};
  EXPECT_EQ(scene_error([&] { nhi::validate_scene(s); }),
            "scene key 'params.KY': unknown parameter for system \"particle\" (known: kx, ky); did you mean \"ky\"?");
  s["params"] = {{"mass", 2.0}};
  EXPECT_EQ(scene_error([&] { nhi::validate_scene(s); }).find("did you mean"), std::string::npos);

  // unknown keys (validate_scene calls unknown_key with its list of keys)
  const std::vector<std::string> keys = {"system", "params", "q0", "v0", "method", "steps", "output_every"};
  EXPECT_EQ(scene_error([&] { sd::unknown_key("stepz", keys); }),
            "scene key 'stepz': unknown key; did you mean \"steps\"?");
  EXPECT_EQ(scene_error([&] { sd::unknown_key("output_evry", keys); }),
            "scene key 'output_evry': unknown key; did you mean \"output_every\"?");
  EXPECT_EQ(scene_error([&] { sd::unknown_key("colour", keys); }), "scene key 'colour': unknown key");
}

TEST_F(RunnerEdges, RunnerSuggestsTheValueMeant) {
  const Result r = nhi(std::string("run ") + NHI_SCENES + "/particle.json --set method=mp6 -o x.json");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("did you mean \"mp06\"?"), std::string::npos) << r.err;
  EXPECT_TRUE(work_empty());
}

// ---- 5. NaN is called NaN ----------------------------------------------------------

TEST(NonFinite, MessagesSayNaNAndInfinityNotNull) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  // A scene built in memory (the Python module's nhi.run(dict)) can hold them.
  EXPECT_EQ(scene_error([&] { sd::finite_number(json(nan), "h"); }), "scene key 'h': must be finite, got NaN");
  EXPECT_EQ(scene_error([&] { sd::finite_number(json(inf), "h"); }), "scene key 'h': must be finite, got Infinity");
  EXPECT_EQ(scene_error([&] { sd::finite_number(json(-inf), "h"); }), "scene key 'h': must be finite, got -Infinity");
  EXPECT_EQ(sd::show(json::array({1.0, nan, -inf})), "[1.0,NaN,-Infinity]");
  EXPECT_EQ(sd::show(json{{"a", inf}}), "{\"a\":Infinity}");
  EXPECT_EQ(sd::show(json(nullptr)), "null");  // a real null is still null
  json s = particle();
  s["q0"] = {1.0, nan, 0.0};
  EXPECT_EQ(scene_error([&] { nhi::validate_scene(s); }), "scene key 'q0[1]': must be finite, got NaN");
  // show() as before on finite values: compact JSON, at most 60 characters.
  EXPECT_EQ(sd::show(json::parse(R"({"x": [1, 2.5, "a"]})")), R"({"x":[1,2.5,"a"]})");
  const std::string long_one = sd::show(json(std::vector<double>(100, 0.125)));
  EXPECT_EQ(long_one.size(), 60u);
  EXPECT_EQ(long_one.substr(57), "...");
  json nested = json::array();
  for (int i = 0; i < 200; ++i) nested = json::array({nested});
  EXPECT_EQ(sd::show(nested).substr(0, 5), "[[[[[");
}

// Result files: JSON has no NaN or Infinity; a non-finite number is written as
// null, and the file stays JSON (nlohmann and jq read it).
TEST_F(RunnerEdges, ResultFilesWriteNonFiniteNumbersAsNull) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const json r = {{"summary", {{"max_abs_energy_error", inf}, {"points", 3}}}, {"energy", {1.0, nan, -inf}}};
  const std::string text = nhi::json_lines(r);
  const json back = json::parse(text);
  EXPECT_TRUE(back["summary"]["max_abs_energy_error"].is_null());
  EXPECT_EQ(back["energy"], json::parse("[1.0, null, null]"));
  std::ofstream(path("r.json")) << text;
  if (std::system("command -v jq > /dev/null 2>&1") == 0) {
    const Result jq = sh("jq -c .energy " + path("r.json"));
    EXPECT_EQ(jq.code, 0) << jq.err;
    EXPECT_EQ(jq.out, "[1,null,null]\n");
  }
}

// ---- 6. Progress: '\r' on a terminal only -------------------------------------------

TEST_F(RunnerEdges, ProgressInALogIsOnePlainLinePerTenthOfTheRuns) {
  const Result r = stability("--only particle --T 2 --roots-from 1 --threads 2 --scenes " + std::string(NHI_SCENES) +
                             " -o " + path("s.json"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "a carriage return in a log";
  // Every line "LABEL: d/total runs"; per label at most 10 lines, increasing,
  // the last at total.
  const std::regex line_re(R"((.+): (\d+)/(\d+) runs)");
  std::map<std::string, std::vector<std::pair<long, long>>> by_label;
  std::istringstream in(r.err);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(line, m, line_re)) << "not a progress line: " << line;
    by_label[m[1]].emplace_back(std::stol(m[2]), std::stol(m[3]));
  }
  ASSERT_FALSE(by_label.empty());
  for (const auto& [label, seen] : by_label) {
    EXPECT_LE(seen.size(), 10u) << label;
    EXPECT_EQ(seen.back().first, seen.back().second) << label;
    for (size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i].first, seen[i - 1].first) << label;
    // (A tenth can be skipped only when a worker thread is held up for a
    // tenth of the runs between finishing a run and printing.)
    if (seen.back().second >= 10) EXPECT_GE(seen.size(), 5u) << label;
  }
}

TEST_F(RunnerEdges, ProgressOnATerminalIsRedrawnWithCarriageReturns) {
  int master = -1;
  const std::string out = path("t.json"), scenes = NHI_SCENES;
  const pid_t pid = ::forkpty(&master, nullptr, nullptr, nullptr);
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl(NHI_STABILITY, NHI_STABILITY, "--only", "particle", "--T", "2", "--roots-from", "1", "--scenes",
            scenes.c_str(), "-o", out.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::string text;
  char buf[4096];
  for (;;) {
    const ssize_t k = ::read(master, buf, sizeof buf);
    if (k > 0) {
      text.append(buf, static_cast<size_t>(k));
      continue;
    }
    if (k < 0 && errno == EINTR) continue;
    break;  // EOF or EIO: the child closed the terminal
  }
  ::close(master);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << text;
  EXPECT_NE(text.find("\rstability particle: "), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(out));
}

// ---- 7. File errors say why ---------------------------------------------------------

TEST_F(RunnerEdges, AtomicFileErrorsNameTheCauseNotAStaleErrno) {
  // The temporary cannot be created.
  try {
    nhi::AtomicFile f(path("no/such/dir/r.json"));
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(std::strerror(ENOENT)), std::string::npos) << e.what();
  }
  // The rename fails (the target became a non-empty directory after the
  // temporary was claimed): the message says so, whatever errno held before
  // (successful calls do not reset it), and the temporary is gone.
  const std::string target = path("target");
  {
    nhi::AtomicFile f(target);
    fs::create_directories(dir_ / "target" / "inside");
    errno = ENOSPC;  // stale, from some earlier call
    try {
      f.commit("{}\n");
      ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("cannot write output '" + target + "'"), std::string::npos) << what;
      EXPECT_NE(what.find(std::strerror(EISDIR)), std::string::npos) << what;
      EXPECT_EQ(what.find(std::strerror(ENOSPC)), std::string::npos) << what;
    }
  }
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

}  // namespace
