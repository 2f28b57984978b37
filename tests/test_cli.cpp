// The `nhi run` command line, driven as a user (or an outside check) drives it:
// exit codes, one-line errors, result files whole or absent.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

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

TEST_F(Cli, BadInputsFailWithOneLineAndNoFile) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {write("trunc.json", R"({"system": "particle", "q0": [1, 0.5)"), ""},
      {write("notobj.json", "[1, 2, 3]"), ""},
      {scene(), "--set system=pendulum"},
      {scene(), "--set method=euler"},
      {scene(), "--set 'q0=[1,2]'"},
      {scene(), "--set alpha=1.5"},
      {scene(), "--set h=0"},
      {scene(), "--set steps=0"},
      {scene(), "--set steps=2.5"},
      {scene(), "--set h=1e400"},
      {scene(), "--set 'v0=[0.5,1,1]'"},
      {scene(), "--set colour=3"},
      {path("missing.json"), ""},
  };
  const std::string out = path("out.json");
  std::ofstream(out) << "precious";
  for (const auto& [file, extra] : cases) {
    const Result r = run("run " + file + " " + extra + " -o " + out);
    EXPECT_EQ(r.code, 2) << file << " " << extra << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("nhi: error:"), std::string::npos) << r.err;
    std::ifstream in(out);
    std::string text;
    std::getline(in, text);
    EXPECT_EQ(text, "precious") << "output clobbered by " << file << " " << extra;
  }
  // Nothing else was left in the directory (no temporary files).
  for (const auto& e : fs::directory_iterator(dir_)) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(name == "out.json" || name == "stderr.txt" || name.size() > 5) << name;
    EXPECT_EQ(name.find(".tmp."), std::string::npos) << name;
  }
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
  const std::string scenes = std::string(" --scenes ") + NHI_SCENES;
  ASSERT_EQ(std::system((std::string(NHI_STABILITY) + " --threads 1 -o " + one + scenes + " 2>/dev/null").c_str()), 0);
  ASSERT_EQ(std::system((std::string(NHI_STABILITY) + " --threads 2 -o " + two + scenes + " 2>/dev/null").c_str()), 0);
  json a = json::parse(std::ifstream(one)), b = json::parse(std::ifstream(two));
  a.erase("meta");
  b.erase("meta");
  EXPECT_EQ(a, b);  // bit-identical numbers: JSON doubles round-trip exactly
}

TEST_F(Cli, InterruptedRunWritesNothing) {
  const std::string out = path("i.json");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string sc = scene();
    ::execl(NHI_BINARY, NHI_BINARY, "run", sc.c_str(), "--set", "steps=2000000000", "--set",
            "output_every=100000000", "-o", out.c_str(), static_cast<char*>(nullptr));
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
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << e.path();
}

}  // namespace
