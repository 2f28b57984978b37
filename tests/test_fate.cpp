// Unit tests of fate.hpp on synthetic energy-error records, made the way the
// long-horizon study records a run (h = 0.2, 10^6 steps, T = 2e5): each signal
// is a known fate (bounded, large but flat, drifting, accelerating, a random
// walk, dissipating, blown up) and the reading must name it.
#include "nhi/readings/fate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace nhi {
namespace {

constexpr double kH = 0.2;
constexpr long kSteps = 1000000;
constexpr long kBlock = 1000;

// A run's record as the study's HorizonObserver keeps it: checkpoints at steps
// round(10^{j/40}) and the last step, with the running max of |E - E0| over
// every step; means of E - E0 over blocks of 1000 steps (step 0 included), at
// the blocks' mid times.
struct Record {
  std::vector<double> t, running_max, block_t, block_mean;
};

// dE(k, t) = E - E0 at step k (t = k h), called once per step in order k = 0, 1, ..., steps.
template <class F>
Record record(F&& dE, long steps = kSteps, double h = kH) {
  std::vector<long> checkpoints;
  for (double x = 0; x <= std::log10(double(steps)) + 1e-9; x += 1.0 / 40) {
    const long k = std::lround(std::pow(10.0, x));
    if (checkpoints.empty() || k > checkpoints.back()) checkpoints.push_back(k);
  }
  if (checkpoints.back() != steps) checkpoints.push_back(steps);
  Record r;
  double max = 0, sum = 0;
  long in_block = 0;
  size_t next = 0;
  for (long k = 0; k <= steps; ++k) {
    const double e = dE(k, double(k) * h);
    max = std::max(max, std::abs(e));
    sum += e;
    if (++in_block == kBlock) {
      r.block_t.push_back((double(k) - (kBlock - 1) / 2.0) * h);
      r.block_mean.push_back(sum / kBlock);
      sum = 0;
      in_block = 0;
    }
    if (next < checkpoints.size() && k == checkpoints[next]) {
      r.t.push_back(double(k) * h);
      r.running_max.push_back(max);
      ++next;
    }
  }
  return r;
}

TailReading read(const Record& r, double E0, const FateLevels& levels = {}) {
  return read_tail(r.t, r.running_max, r.block_t, r.block_mean, E0, levels);
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// The block mean nearest to time t.
double block_mean_at(const Record& r, double t) {
  size_t best = 0;
  for (size_t i = 0; i < r.block_t.size(); ++i)
    if (std::abs(r.block_t[i] - t) < std::abs(r.block_t[best] - t)) best = i;
  return r.block_mean[best];
}

// A plateau (an offset and an oscillation) and then a linear drift from
// t ~ 1.1e4: block means -0.0045 early, ~0.01-0.02 at 1.6e4, ~0.44 at 1.57e5,
// E0 = 1.46, as a real run.  Over [T/1000, T] the plateau dilutes the running
// max's slope to ~0.5 (a random walk's); over the last decade it is > 1.
TEST(Fate, PlateauThenLinearDriftReadsAsDriftingUp) {
  const double E0 = 1.46;
  const Record rec =
      record([](long, double t) { return -0.0045 + 0.006 * std::sin(1.3 * t) + 3e-6 * std::max(0.0, t - 1.1e4); });
  EXPECT_NEAR(block_mean_at(rec, 78), -0.0045, 1e-3);
  EXPECT_NEAR(block_mean_at(rec, 1.57e5), 0.439, 0.03);
  const double T = rec.t.back();
  EXPECT_LT(fate_detail::loglog_slope_in(rec.t, rec.running_max, T / 1000, T), 0.7);

  const TailReading r = read(rec, E0);
  EXPECT_TRUE(r.growing);
  EXPECT_TRUE(r.slope_grows);
  EXPECT_TRUE(r.trend_grows);
  EXPECT_GT(r.max_slope, 1.0);
  EXPECT_GT(r.block_trend, 0.0);
  EXPECT_GT(r.block_rise, 0.4);              // 3e-6 * 0.9 T = 0.54
  EXPECT_FALSE(r.accelerating);              // t - t0 steepens less and less in log-log
  EXPECT_NEAR(r.relative, 0.57 / E0, 0.02);  // M(T) = 3e-6 (T - 1.1e4) + 0.0015
  const std::string words = fate_words(r);
  EXPECT_TRUE(starts_with(words, "drifts up (max ~t^1.")) << words;
  EXPECT_NE(words.find("39 % of |E0|"), std::string::npos) << words;
}

// E - E0 = 1e-5 S_k, S_k a walk of +-1 steps.  One decade of one path cannot
// tell a random walk from a drift, nor always from a bounded wander: the
// statistics over 20 paths are asserted, not each path.
TEST(Fate, RandomWalkReadsAsGrowingInMostPaths) {
  int growing = 0, by_slope_or_trend = 0;
  std::vector<double> slopes;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    std::uint32_t bits = 0;
    int left = 0;
    double s = 0;
    const Record rec = record([&](long k, double) {
      if (k == 0) return 0.0;
      if (left == 0) bits = rng(), left = 32;
      s += (bits & 1u) ? 1.0 : -1.0;
      bits >>= 1;
      --left;
      return 1e-5 * s;
    });
    const TailReading r = read(rec, 1.5);
    growing += r.growing;
    by_slope_or_trend += r.slope_grows || r.trend_grows;
    slopes.push_back(r.max_slope);
    // Without a systematic trend the words give no direction.
    const std::string words = fate_words(r);
    if (r.growing && !r.trend_grows) {
      EXPECT_TRUE(starts_with(words, r.wanders ? "wanders (" : "drifts (")) << words;
    }
  }
  std::sort(slopes.begin(), slopes.end());
  const double median = (slopes[9] + slopes[10]) / 2;
  EXPECT_GE(growing, 18);
  EXPECT_GE(median, 0.35);
  EXPECT_LE(median, 0.65);
  // (a) and (b) alone miss the paths whose M was reached before T/10 (~9 % of paths, 3 of these 20): (c) reads them.
  EXPECT_LT(by_slope_or_trend, growing);
}

// E - E0 = 0.01 sin(1.3 t) + 0.003 sin(0.17 t): M saturates within a few
// periods and the block means are small, trend-free noise.
TEST(Fate, BoundedOscillationReadsAsBounded) {
  const double E0 = 1.9;
  const Record rec = record([](long, double t) { return 0.01 * std::sin(1.3 * t) + 0.003 * std::sin(0.17 * t); });
  const TailReading r = read(rec, E0);
  EXPECT_FALSE(r.growing);
  EXPECT_FALSE(r.slope_grows);
  EXPECT_FALSE(r.trend_grows);
  EXPECT_FALSE(r.wanders);
  EXPECT_LT(std::abs(r.max_slope), 0.01);
  EXPECT_LT(std::abs(r.block_rise), 3 * r.block_scatter);
  EXPECT_LT(r.wander_ratio, 1.2);
  EXPECT_NEAR(r.relative, 0.013 / E0, 1e-3);
  const std::string words = fate_words(r);
  EXPECT_TRUE(starts_with(words, "bounded (0.")) << words;
  // The same error against an E0 five times smaller is above bounded_relative: large, and still not growing.
  const std::string large = fate_words(read(rec, 0.2));
  EXPECT_TRUE(starts_with(large, "large, not growing (±")) << large;
}

// E - E0 = 1e-3 (e^{t/T} - 1): over the last decade M's log-log slope goes
// from ~1.09 to ~1.32, faster than any power.  A power law t^1.5 keeps the
// same slope in both halves: growing, not accelerating.
TEST(Fate, SlowExponentialReadsAsAccelerating) {
  const double T = kH * kSteps;
  const TailReading r = read(record([&](long, double t) { return 1e-3 * std::expm1(t / T); }), 1.5);
  EXPECT_TRUE(r.growing);
  EXPECT_TRUE(r.slope_grows);
  EXPECT_TRUE(r.trend_grows);
  EXPECT_TRUE(r.accelerating);
  EXPECT_NEAR(r.max_slope_first_half, 1.09, 0.03);
  EXPECT_NEAR(r.max_slope_second_half, 1.32, 0.03);
  const std::string words = fate_words(r);
  EXPECT_TRUE(starts_with(words, "drifts up, accelerating (max ~t^1.09 then ~t^1.32")) << words;

  const TailReading p = read(record([&](long, double t) { return 1e-3 * std::pow(t / T, 1.5); }), 1.5);
  EXPECT_TRUE(p.growing);
  EXPECT_FALSE(p.accelerating);
  EXPECT_NEAR(p.max_slope_first_half, 1.5, 0.01);
  EXPECT_NEAR(p.max_slope_second_half, 1.5, 0.01);
  const std::string power = fate_words(p);
  EXPECT_TRUE(starts_with(power, "drifts up (max ~t^1.50")) << power;
}

// A chaotic run's case: 41 % of E0 = 1.33 lost by t ~ 100, then a small
// oscillation about the new level.  The old cut-off |late mean| > |E0|/2 called
// it bounded; it is large and flat.
TEST(Fate, FastLossThenBoundedReadsAsLargeNotGrowing) {
  const double E0 = 1.33;
  const Record rec =
      record([&](long, double t) { return -0.41 * E0 * -std::expm1(-t / 15) + 0.004 * std::sin(1.3 * t); });
  const TailReading r = read(rec, E0);
  EXPECT_FALSE(r.growing);
  EXPECT_NEAR(r.relative, 0.41, 0.01);
  EXPECT_NEAR(r.late_mean, -0.41 * E0, 0.01);
  EXPECT_LT(r.t90, 100);
  const std::string words = fate_words(r);
  EXPECT_TRUE(starts_with(words, "large, not growing (-41 % of |E0|)")) << words;
}

// A drift far below an oscillation's amplitude: M hardly moves (slope < 0.2),
// the block means rise steadily.  Criterion (b) alone reads it.
TEST(Fate, DriftUnderAnOscillationReadsByTheBlockTrend) {
  const TailReading r = read(record([](long, double t) { return 0.05 * std::sin(1.3 * t) + 2e-8 * t; }), 1.5);
  EXPECT_FALSE(r.slope_grows);
  EXPECT_TRUE(r.trend_grows);
  EXPECT_TRUE(r.growing);
  EXPECT_NEAR(r.block_rise, 2e-8 * 0.9 * kH * kSteps, 2e-4);
  const std::string words = fate_words(r);
  EXPECT_TRUE(starts_with(words, "drifts up (")) << words;
  EXPECT_NE(words.find("block means +0.0036 over the last decade"), std::string::npos) << words;
}

// A first integral's error: an offset reached early (2.51e-4 + 2e-5 sin t), a
// creep from 2.51e-4 at t ~ 3 to 2.75e-4 at t = 1e5 (a real run's), and a
// linear drift 1e-9 t.
TEST(Fate, IntegralOffsetIsNotADrift) {
  const Record offset = record([](long k, double t) { return k == 0 ? 0.0 : 2.51e-4 + 2e-5 * std::sin(t); });
  const IntegralReading o = read_integral(offset.t, offset.running_max);
  EXPECT_FALSE(o.drifting);
  EXPECT_NEAR(o.early, 2.71e-4, 1e-6);
  EXPECT_NEAR(o.late, 2.71e-4, 1e-6);
  EXPECT_LT(std::abs(o.slope), 0.01);
  EXPECT_TRUE(starts_with(o.words, "offset (0.00027 at t = 20, 0.00027 at t = 200000)")) << o.words;

  const Record creep = record(
      [](long, double t) { return t < 3 ? 2.51e-4 * t / 3 : 2.51e-4 + 2.4e-5 * std::log(t / 3) / std::log(1e5 / 3); },
      500000);
  const IntegralReading c = read_integral(creep.t, creep.running_max);
  EXPECT_FALSE(c.drifting);
  EXPECT_NEAR(c.late, 2.75e-4, 1e-6);
  EXPECT_LT(c.slope, 0.02);
  EXPECT_TRUE(starts_with(c.words, "offset (")) << c.words;

  const Record drift = record([](long, double t) { return 1e-9 * t; });
  const IntegralReading d = read_integral(drift.t, drift.running_max);
  EXPECT_TRUE(d.drifting);
  EXPECT_NEAR(d.slope, 1.0, 1e-3);
  EXPECT_NEAR(d.late, 2e-4, 1e-9);
  EXPECT_TRUE(starts_with(d.words, "drifts (max ~t^1.00")) << d.words;
}

// E - E0 = -0.96 (1 - e^{-t/500}), E0 = 1: the motion runs down.  And the
// other way, E - E0 = 2e-5 t, E0 = 1: past |E0| / 2 on average over the last decade.
TEST(Fate, RunawayReadsAsDissipatesOrGrows) {
  const TailReading down = read(record([](long, double t) { return -0.96 * -std::expm1(-t / 500); }), 1.0);
  EXPECT_FALSE(down.growing);  // E has settled: the words say it ran down
  const std::string d = fate_words(down);
  EXPECT_TRUE(starts_with(d, "dissipates (E - E0 = -0.96 by t = ")) << d;
  EXPECT_NE(d.find("-96 % of |E0|"), std::string::npos) << d;

  const TailReading up = read(record([](long, double t) { return 2e-5 * t; }), 1.0);
  EXPECT_TRUE(up.growing);
  const std::string u = fate_words(up);
  EXPECT_TRUE(starts_with(u, "grows (E - E0 = 3.8")) << u;  // the mean over [0.9 T, T]
}

// Records that cannot be read in full: never a crash, words that say so.
// An energy kept to round-off whose rounding errors add up (a random walk of
// 1e-16 steps, E0 = 1.5): growing, but at round-off, and read so; the same
// walk scaled to 1e-9 of E0 is a drift.
TEST(Fate, GrowingRoundOffIsNotADrift) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> coin(0, 1);
  double walk = 0;
  const Record rec = record([&](long k, double) {
    if (k > 0) walk += coin(rng) ? 1.0 : -1.0;
    return 2e-16 * walk;
  });
  const TailReading r = read(rec, 1.5);
  EXPECT_TRUE(r.growing);
  EXPECT_TRUE(r.at_roundoff);
  EXPECT_TRUE(starts_with(fate_words(r), "round-off, growing")) << fate_words(r);
  FateLevels tight;
  tight.roundoff_relative = r.relative / 2;  // the same record above the round-off level
  const TailReading r2 = read(rec, 1.5, tight);
  EXPECT_TRUE(r2.growing);
  EXPECT_FALSE(r2.at_roundoff);
  EXPECT_FALSE(starts_with(fate_words(r2, tight), "round-off")) << fate_words(r2, tight);
}

TEST(Fate, DegenerateRecordsAreReadSafely) {
  const double nan = std::nan(""), inf = HUGE_VAL;
  const TailReading empty = read_tail({}, {}, {}, {}, 1.0);
  EXPECT_FALSE(empty.growing);
  EXPECT_EQ(fate_words(empty), "no data");
  EXPECT_EQ(read_integral({}, {}).words, "no data");

  const TailReading one = read_tail({0.2}, {1e-3}, {}, {}, 1.0);
  EXPECT_FALSE(one.growing);
  EXPECT_TRUE(std::isnan(one.max_slope));
  EXPECT_EQ(fate_words(one), "too short to read (max |E - E0| = 0.001, 0.1 % of |E0|)");
  EXPECT_TRUE(starts_with(read_integral({0.2}, {1e-3}).words, "too short to read"))
      << read_integral({0.2}, {1e-3}).words;

  const TailReading blown = read_tail({0.2, 0.4, 0.6, 0.8}, {1e-3, 2e-3, nan, nan}, {}, {}, 1.0);
  EXPECT_FALSE(blown.finite);
  EXPECT_TRUE(blown.growing);
  EXPECT_EQ(fate_words(blown), "blows up (E - E0 not finite after t = 0.4)");
  EXPECT_TRUE(read_integral({0.2, 0.4, 0.6}, {1e-3, inf, inf}).drifting);
  EXPECT_EQ(read_integral({0.2, 0.4, 0.6}, {1e-3, inf, inf}).words, "not finite after t = 0.2");
  const TailReading blown_blocks = read_tail({1, 2, 3}, {1, 1, 1}, {1, 2}, {0.0, nan}, 1.0);
  EXPECT_TRUE(starts_with(fate_words(blown_blocks), "blows up")) << fate_words(blown_blocks);
  EXPECT_EQ(fate_words(read_tail({1, 2, 3}, {1, 1, 1}, {}, {}, nan)), "blows up (E0 not finite)");

  // Lengths that disagree, times that are not positive: read what is there.
  EXPECT_FALSE(read_tail({0.2, 0.4, 0.6}, {1e-3, 1e-3}, {0.5}, {}, 1.0).growing);
  EXPECT_TRUE(starts_with(fate_words(read_tail({0, 0, 0}, {1e-3, 1e-3, 1e-3}, {0, 0}, {1, 1}, 1.0)), "too short"));
  EXPECT_TRUE(starts_with(fate_words(read_tail({-3, -2, -1}, {1e-3, 1e-3, 1e-3}, {}, {}, 1.0)), "too short"));

  // An exact first integral, and an error identically zero.
  const Record zero = record([](long, double) { return 0.0; }, 20000);
  EXPECT_EQ(read_integral(zero.t, zero.running_max).words, "conserved exactly");
  EXPECT_EQ(fate_words(read(zero, 1.0)), "bounded (0 % of |E0|)");

  // E0 == 0: absolute values, said so.
  const Record osc = record([](long, double t) { return 0.01 * std::sin(1.3 * t); }, 20000);
  const std::string absolute = fate_words(read(osc, 0.0));
  EXPECT_EQ(absolute, "bounded (0.01 absolute, E0 = 0)");
  EXPECT_TRUE(read(osc, 0.0).absolute);
}

}  // namespace
}  // namespace nhi
