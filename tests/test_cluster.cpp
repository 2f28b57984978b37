// The studies over MPI ranks (experiments/studies/cluster.hpp, study.hpp map_cells),
// driven as a cluster user drives them: `mpirun -np N study_... -o F` gives
// the single-process JSON (timings and meta aside), a failing cell fails the
// whole run naming the cell, and no failure leaves a result file behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

#ifdef NHI_HAVE_MPI
constexpr bool kMpi = true;
#else
constexpr bool kMpi = false;
#define NHI_MPIEXEC ""
#endif

struct Result {
  int code;
  std::string err;
};

class Cluster : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("nhi_cluster_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // Open MPI refuses to start as root (CI containers) without these.
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  // `env` before the command, `ranks` > 0 under mpirun (oversubscribed: this
  // machine has two cores), else one plain process.
  Result run(const std::string& binary, const std::string& args, int ranks, const std::string& env = "") const {
    const std::string err = path("stderr.txt");
    std::string cmd = env.empty() ? "" : "env " + env + " ";
    if (ranks > 0) cmd += std::string(NHI_MPIEXEC) + " --oversubscribe -np " + std::to_string(ranks) + " ";
    cmd += binary + " " + args + " --scenes " + NHI_SCENES + " 2> " + err + " > /dev/null";
    const int status = std::system(cmd.c_str());
    std::ifstream in(err);
    std::stringstream ss;
    ss << in.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
  }
  // The result without the fields that may differ between runs: meta (time,
  // revision) and stats (ranks, busy times).
  static json stripped(const std::string& file) {
    json j = json::parse(std::ifstream(file));
    j.erase("meta");
    j.erase("stats");
    return j;
  }
  // No file in the test's directory but stderr.txt: no result, no temporary.
  bool nothing_written() const {
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename() != "stderr.txt") return false;
    return true;
  }
  fs::path dir_;
};

const std::string kStability = std::string(NHI_STABILITY) + " --only particle,contact_oscillator --T 10 --roots-from 1";
const std::string kFateMap = std::string(NHI_FATE_MAP) + " --states 3 --per-decade 4 --values 0.3,3 --T 20";

TEST_F(Cluster, RanksGiveTheSingleProcessResult) {
  if (!kMpi) GTEST_SKIP() << "built without MPI";
  for (const std::string& study : {kStability, kFateMap}) {
    const Result one = run(study, "-o " + path("one.json"), 0);
    ASSERT_EQ(one.code, 0) << one.err;
    const json a = stripped(path("one.json"));
    for (const int ranks : {2, 3}) {
      const std::string out = path("n" + std::to_string(ranks) + ".json");
      const Result r = run(study, "--threads 1 -o " + out, ranks);
      ASSERT_EQ(r.code, 0) << ranks << " ranks: " << r.err;
      EXPECT_EQ(stripped(out), a) << study << " with " << ranks << " ranks";
      // Every rank ran a share, and the shares add up to every cell once.
      const json st = json::parse(std::ifstream(out))["stats"];
      ASSERT_EQ(st["ranks"], ranks);
      ASSERT_EQ(st["busy_seconds"].size(), size_t(ranks));
      long cells = 0;
      for (const json& c : st["cells"]) {
        EXPECT_GT(c.get<long>(), 0);  // untimed cells: every rank has a share
        cells += c.get<long>();
      }
      EXPECT_EQ(cells, json::parse(std::ifstream(path("one.json")))["stats"]["cells"][0].get<long>());
    }
  }
}

TEST_F(Cluster, CellsAreBalancedByEstimatedCost) {
  if (!kMpi) GTEST_SKIP() << "built without MPI";
  // The stability study's cells cost T/h steps: by index, the rank with the
  // small h would carry almost all of it; by cost, the shares are even.
  const std::string out = path("b.json");
  ASSERT_EQ(run(kStability, "--threads 1 -o " + out, 3).code, 0);
  const json cost = json::parse(std::ifstream(out))["stats"]["estimated_cost"];
  double lo = 1e300, hi = 0;
  for (const json& c : cost) {
    lo = std::min(lo, c.get<double>());
    hi = std::max(hi, c.get<double>());
  }
  EXPECT_LT(hi / lo, 1.05) << cost;
}

TEST_F(Cluster, FailingCellFailsTheRunAndNamesIt) {
  for (const int ranks : {0, 2, 3}) {
    if (ranks > 0 && !kMpi) continue;
    const Result r = run(kStability, "--threads 1 -o " + path("f.json"), ranks, "NHI_STUDY_FAIL_CELL=5");
    EXPECT_NE(r.code, 0) << ranks;
    // Cell 5 of the first phase: the particle's first method at the sixth h (0.01 * 10^0.5).
    EXPECT_NE(r.err.find("stability particle: dla a=0.5 at h = 0.031623"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("injected failure"), std::string::npos) << r.err;
    EXPECT_TRUE(nothing_written()) << ranks << " ranks";
  }
}

TEST_F(Cluster, KilledRankLeavesNoFile) {
  if (!kMpi) GTEST_SKIP() << "built without MPI";
  for (const int ranks : {2, 3}) {
    const Result r = run(kStability, "--threads 1 -o " + path("k.json"), ranks, "NHI_STUDY_KILL_CELL=7");
    EXPECT_NE(r.code, 0) << ranks;
    EXPECT_TRUE(nothing_written()) << ranks << " ranks: " << r.err;
  }
}

}  // namespace
