// The fate of a long run, read from its energy-error record: is the error of E
// (or of another first integral) bounded, large but not growing, drifting, or
// has the motion run down or blown up?  Pure functions of the series the
// long-horizon study records (its HorizonObserver): checkpoints t_i, ~40 per
// decade from h to T, with the running max M(t_i) = max_{s<=t_i} |E - E0|, and
// the means of E - E0 over blocks of 1000 steps (block_t, block_mean).
//
// Only the last decade [T/10, T] decides: an error that plateaus early and
// starts to drift late has a small log-log slope over [T/1000, T] (the plateau
// dilutes it) but the drift's own slope over the last decade.
//
// Growing, when any of
//   (a) the log-log slope p of M over [T/10, T] is >= grows_slope (M ~ t^p);
//   (b) the block means move systematically: their least-squares line over
//       [T/10, T] rises (or falls) by |rise| > trend_scatters * scatter (the rms
//       of the block means about that line) and |rise| > trend_of_max * M(T);
//   (c) the block means wander: their rms about their mean over [T/10, T] is
//       more than wander_ratio times their rms about their own means within the
//       decade's 9 windows of T/10 (a variance ratio), and more than
//       wander_of_max * M(T).
// For block means that scatter independently about a constant, the rise of the
// line through n of them has standard deviation scatter * sqrt(12 / n) (0.12
// scatter for the 900 blocks of 10^6 steps), so with trend_scatters = 3 noise
// needs ~26 standard deviations to pass (b), while a drift that stands above
// the noise passes it even when an oscillation on top keeps M flat.  Block
// means that are independent, or move with a memory much shorter than T/10,
// have a variance ratio ~1; a random walk's spread grows like the square root
// of the span, so its ratio is ~sqrt(9) = 3.  The fractions of M(T) ignore
// motions of the means too small to matter against the error itself.  A
// bounded oscillation whose M saturated early has p ~ 0 and block means that
// are independent noise about a constant: none of (a)-(c).
//   On synthetic paths of 10^6 steps, a random walk passes (a) or (b) in 91 %
// of paths (in the rest M was reached before T/10 and the path turned back)
// and (a)-(c) in 99 %; a bounded Ornstein-Uhlenbeck error passes them in 3 %
// of paths with a correlation time of 10^3 steps, 31 % with 10^4 (by (a) or
// (b)) and 44 % with 3 10^4: within one decade a memory comparable to T/10
// cannot be told from a random walk.
//
// Words (the first that applies):
//   blows up            a non-finite value in the record;
//   round-off, growing  growing, but M(T) <= roundoff_relative |E0|: an energy kept to
//                       round-off (the discrete gradient's) whose rounding errors add up;
//                       not the method's drift;
//   dissipates / grows  |mean of the last decade's block means| > runaway_relative |E0|:
//                       the motion has run down or blown up (the words give E - E0
//                       over the last tenth of the run, and when M reached 90 % of M(T));
//   drifts up / down    growing by (b), in the direction of the block trend;
//   wanders             growing by (c) but not (b): random-walk-like, no direction;
//   drifts              growing by (a) alone: M grows, the means do not move
//                       (an oscillation's amplitude grows);
//   ", accelerating"    added when the slope of M over [T/sqrt(10), T] is at least
//                       accelerate_slope (faster than linear) and exceeds the slope over
//                       [T/10, T/sqrt(10)] by accelerate_gap, the latter already
//                       >= grows_slope (M = e^{t/T} - 1 gives 1.09 then 1.32, a power
//                       law the same slope twice; a random walk's M passes in ~6 % of paths);
//   large, not growing  M(T) > bounded_relative |E0|, signed by the last decade's block
//                       mean ("±" when that mean is less than half of M(T): an
//                       oscillation about E0 rather than an offset);
//   bounded             M(T) <= bounded_relative |E0| and not growing.
// With E0 == 0 the relative levels apply to absolute values, and the words say so.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace nhi {

// The levels of the rule above (the study states them in its config).
struct FateLevels {
  double bounded_relative = 0.05;    // bounded only if M(T) <= this * |E0| (and not growing)
  double grows_slope = 0.2;          // last-decade log-log slope of M at or above this: growing
  double runaway_relative = 0.5;     // |mean of the last decade's block means| > this * |E0|: dissipates / grows
  double trend_scatters = 3;         // a block trend is systematic when its rise exceeds this many scatters
  double trend_of_max = 0.01;        // ... and this fraction of M(T)
  double wander_ratio = 1.5;         // block means wander when their spread over [T/10, T] exceeds this many of
                                     // their spread within windows of T/10
  double wander_of_max = 0.12;       // ... and this fraction of M(T)
  double accelerate_gap = 0.2;       // second-half slope of M above the first half's by this much: accelerating
  double accelerate_slope = 1;       // ... and the second half's at least this (faster than linear)
  double roundoff_relative = 1e-10;  // growing with M(T) <= this * |E0|: round-off accumulating, not a drift
};

namespace fate_detail {
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace fate_detail

// What the last decade [T/10, T] of a run shows (NaN where it cannot be read).
struct TailReading {
  double E0 = fate_detail::kNaN;
  double T = fate_detail::kNaN;  // the last finite checkpoint
  size_t points = 0;             // checkpoints in [T/10, T] with a finite, positive M
  size_t blocks = 0;             // block means in [T/10, T]
  // Log-log slopes of M over [T/10, T] and over its halves [T/10, T/sqrt(10)] and [T/sqrt(10), T].
  double max_slope = fate_detail::kNaN, max_slope_first_half = fate_detail::kNaN,
         max_slope_second_half = fate_detail::kNaN;
  // The least-squares line of the block means against t over [T/10, T]: its slope (per unit t), the rise
  // block_trend * (T - T/10) over the decade, and the rms of the block means about it.
  double block_trend = fate_detail::kNaN, block_rise = fate_detail::kNaN, block_scatter = fate_detail::kNaN;
  // The rms of the block means about their mean over [T/10, T], the pooled rms about their means within the
  // decade's windows of T/10, and the variance ratio block_spread / block_within.
  double block_spread = fate_detail::kNaN, block_within = fate_detail::kNaN, wander_ratio = fate_detail::kNaN;
  // The mean of the block means over [T/10, T], and over [0.9 T, T]: where E - E0 ended.
  double late_mean = fate_detail::kNaN, end_mean = fate_detail::kNaN;
  // M at the first checkpoint t_early at or after T/1e4, and at T; the first checkpoint with M >= 0.9 M(T).
  double t_early = fate_detail::kNaN, max_early = fate_detail::kNaN, max_late = fate_detail::kNaN,
         t90 = fate_detail::kNaN;
  double scale = 1;                     // |E0|, or 1 when E0 is 0 or not finite
  double relative = fate_detail::kNaN;  // max_late / scale
  bool absolute = false;                // scale = 1: the relative quantities are absolute
  bool finite = true;                   // no non-finite value in the record, nor in E0
  bool at_roundoff = false;  // growing, but M(T) <= roundoff_relative * |E0|: the method's error is round-off
  bool slope_grows = false, trend_grows = false, wanders = false;  // criteria (a), (b), (c)
  bool growing = false;                                            // (a), (b) or (c), or not finite
  bool accelerating = false;                                       // growing, faster than linear and steepening
};

namespace fate_detail {

// Least-squares line y = a + b x: slope b and the rms of the residuals.  NaN
// with fewer than 3 points or no spread in x.  Centred sums: x up to 1e5-1e6.
struct Line {
  double slope = kNaN, rms = kNaN;
};
inline Line fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  Line l;
  const size_t n = x.size();
  if (n < 3) return l;
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= double(n);
  my /= double(n);
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < n; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (!(sxx > 0)) return l;
  l.slope = sxy / sxx;
  double ss = 0;
  for (size_t i = 0; i < n; ++i) {
    const double r = y[i] - my - l.slope * (x[i] - mx);
    ss += r * r;
  }
  l.rms = std::sqrt(ss / double(n));
  return l;
}

// Log-log slope of y against x over the points with x in [lo, hi] and x, y
// finite and positive (the running max is 0 until the first round-off).
inline double loglog_slope_in(const std::vector<double>& x, const std::vector<double>& y, double lo, double hi,
                              size_t* count = nullptr) {
  std::vector<double> lx, ly;
  for (size_t i = 0; i < x.size() && i < y.size(); ++i)
    if (x[i] >= lo && x[i] <= hi && x[i] > 0 && y[i] > 0 && std::isfinite(x[i]) && std::isfinite(y[i])) {
      lx.push_back(std::log(x[i]));
      ly.push_back(std::log(y[i]));
    }
  if (count) *count = lx.size();
  return fit_line(lx, ly).slope;
}

// The length of the finite prefix of x and y (read up to the shorter one).
inline size_t finite_prefix(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = std::min(x.size(), y.size());
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) return i;
  return n;
}

inline bool all_finite(const std::vector<double>& x) {
  return std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
}

// A share of |E0| for the words: "30 % of |E0|" (sign: "", "-", "+" or "±"),
// or the absolute value when E0 == 0.
inline std::string share(double relative, bool absolute, const char* sign = "") {
  char buf[64];
  const double a = std::abs(relative);
  if (absolute)
    std::snprintf(buf, sizeof buf, "%s%.2g absolute, E0 = 0", sign, a);
  else if (a * 100 >= 10)
    std::snprintf(buf, sizeof buf, "%s%.0f %% of |E0|", sign, a * 100);
  else
    std::snprintf(buf, sizeof buf, "%s%.2g %% of |E0|", sign, a * 100);
  return buf;
}

inline std::string time_words(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, t >= 1 ? "%.0f" : "%.2g", t);
  return buf;
}

}  // namespace fate_detail

inline TailReading read_tail(const std::vector<double>& t, const std::vector<double>& running_max,
                             const std::vector<double>& block_t, const std::vector<double>& block_mean, double E0,
                             const FateLevels& levels = {}) {
  using namespace fate_detail;
  TailReading r;
  r.E0 = E0;
  // Read the finite prefix of the record; a non-finite value anywhere marks the run as blown up.
  const size_t n = finite_prefix(t, running_max);
  const size_t nb = finite_prefix(block_t, block_mean);
  r.finite =
      all_finite(t) && all_finite(running_max) && all_finite(block_t) && all_finite(block_mean) && std::isfinite(E0);
  r.absolute = !(std::abs(E0) > 0) || !std::isfinite(E0);
  r.scale = r.absolute ? 1.0 : std::abs(E0);
  if (n == 0) return r;  // nothing to read (T stays NaN)
  r.T = t[n - 1];
  r.max_late = running_max[n - 1];
  r.relative = r.max_late / r.scale;
  if (!(r.T > 0)) return r;  // no decade to read
  const std::vector<double> tc(t.begin(), t.begin() + n), mc(running_max.begin(), running_max.begin() + n);
  const double T = r.T, lo = T / 10, mid = T / std::sqrt(10.0);

  r.t_early = tc[0];
  r.max_early = mc[0];
  for (size_t i = 0; i < n; ++i)
    if (tc[i] >= T / 1e4) {
      r.t_early = tc[i];
      r.max_early = mc[i];
      break;
    }
  for (size_t i = 0; i < n; ++i)
    if (mc[i] >= 0.9 * r.max_late) {
      r.t90 = tc[i];
      break;
    }
  r.max_slope = loglog_slope_in(tc, mc, lo, T, &r.points);
  r.max_slope_first_half = loglog_slope_in(tc, mc, lo, mid);
  r.max_slope_second_half = loglog_slope_in(tc, mc, mid, T);

  std::vector<double> bt, bm;
  for (size_t i = 0; i < nb; ++i)
    if (block_t[i] >= lo && block_t[i] <= T) bt.push_back(block_t[i]), bm.push_back(block_mean[i]);
  r.blocks = bt.size();
  if (!bt.empty()) {
    double s = 0;
    for (double v : bm) s += v;
    r.late_mean = s / double(bm.size());
    double e = 0;
    size_t ne = 0;
    for (size_t i = 0; i < bt.size(); ++i)
      if (bt[i] >= 0.9 * T) e += bm[i], ++ne;
    r.end_mean = ne > 0 ? e / double(ne) : bm.back();
  }
  // The variance ratio of the block means: their spread over the decade against their pooled spread within
  // kWanderWindows windows of T/10.  Independent means, or any motion with a memory much shorter than T/10,
  // give ~1; a random walk's spread grows with the span, ~sqrt(9) = 3 in expectation.
  if (bm.size() >= 3) {
    constexpr int kWanderWindows = 9;
    double ss = 0;
    for (double v : bm) ss += (v - r.late_mean) * (v - r.late_mean);
    r.block_spread = std::sqrt(ss / double(bm.size()));
    std::vector<double> sum(kWanderWindows, 0.0), count(kWanderWindows, 0.0), dev(kWanderWindows, 0.0);
    auto window = [&](double ti) { return std::min(kWanderWindows - 1, int((ti - lo) / ((T - lo) / kWanderWindows))); };
    for (size_t i = 0; i < bm.size(); ++i) sum[window(bt[i])] += bm[i], count[window(bt[i])] += 1;
    for (size_t i = 0; i < bm.size(); ++i) {
      const int w = window(bt[i]);
      const double d = bm[i] - sum[w] / count[w];
      dev[w] += d * d;
    }
    double within = 0, n_within = 0;
    int windows = 0;
    for (int w = 0; w < kWanderWindows; ++w)
      if (count[w] >= 2) within += dev[w], n_within += count[w], ++windows;
    if (windows >= 2) {
      r.block_within = std::sqrt(within / n_within);
      r.wander_ratio = r.block_spread / r.block_within;
    }
  }
  const Line line = fit_line(bt, bm);
  r.block_trend = line.slope;
  r.block_rise = line.slope * (T - lo);
  r.block_scatter = line.rms;

  // The decision (the header's comment).  NaN comparisons are false: what cannot be read does not count.
  r.slope_grows = r.points >= 3 && r.max_slope >= levels.grows_slope;
  const double rise = std::abs(r.block_rise);
  r.trend_grows =
      r.blocks >= 3 && rise > levels.trend_scatters * r.block_scatter && rise > levels.trend_of_max * r.max_late;
  r.wanders = r.wander_ratio > levels.wander_ratio && r.block_spread > levels.wander_of_max * r.max_late;
  r.growing = r.slope_grows || r.trend_grows || r.wanders || !r.finite;
  r.at_roundoff = r.growing && r.finite && r.relative <= levels.roundoff_relative;
  r.accelerating = r.growing && r.max_slope_first_half >= levels.grows_slope &&
                   r.max_slope_second_half >= levels.accelerate_slope &&
                   r.max_slope_second_half - r.max_slope_first_half >= levels.accelerate_gap;
  return r;
}

// The reading in words (the header's comment gives the order and the meaning).
inline std::string fate_words(const TailReading& r, const FateLevels& levels = {}) {
  using namespace fate_detail;
  char buf[200];
  if (!std::isfinite(r.E0)) return "blows up (E0 not finite)";
  if (!std::isfinite(r.T)) return r.finite ? "no data" : "blows up (E - E0 not finite)";
  if (!r.finite) {
    std::snprintf(buf, sizeof buf, "blows up (E - E0 not finite after t = %s)", time_words(r.T).c_str());
    return buf;
  }
  const double scale = r.scale;
  if (std::abs(r.late_mean) > levels.runaway_relative * scale) {
    std::snprintf(buf, sizeof buf, "%s (E - E0 = %.3g by t = %s, %s)", r.late_mean < 0 ? "dissipates" : "grows",
                  r.end_mean, time_words(std::isfinite(r.t90) ? r.t90 : r.T).c_str(),
                  share(r.end_mean / scale, r.absolute, r.end_mean < 0 ? "-" : "+").c_str());
    return buf;
  }
  if (r.at_roundoff) {
    std::snprintf(buf, sizeof buf, "round-off, growing (max ~t^%.2f, %.2g of |E0|)", r.max_slope, r.relative);
    return buf;
  }
  if (r.growing) {
    const char* what = r.trend_grows ? (r.block_trend < 0 ? "drifts down" : "drifts up")
                       : r.wanders   ? "wanders"
                                     : "drifts";
    std::string w = std::string(what) + (r.accelerating ? ", accelerating (" : " (");
    if (r.accelerating)
      std::snprintf(buf, sizeof buf, "max ~t^%.2f then ~t^%.2f, ", r.max_slope_first_half, r.max_slope_second_half);
    else if (std::isfinite(r.max_slope))
      std::snprintf(buf, sizeof buf, "max ~t^%.2f, ", r.max_slope);
    else
      buf[0] = 0;
    w += buf;
    if (r.trend_grows && !r.slope_grows) {  // M does not show it: say what the block means did
      std::snprintf(buf, sizeof buf, "block means %+.2g over the last decade, ", r.block_rise);
      w += buf;
    } else if (!r.trend_grows && r.wanders) {
      w += "random-walk-like, ";
    } else if (!r.trend_grows && r.blocks >= 3) {
      w += "no trend in the block means, ";
    }
    return w + share(r.relative, r.absolute) + ")";
  }
  if (r.points < 3 && r.blocks < 3) {
    std::snprintf(buf, sizeof buf, "too short to read (max |E - E0| = %.2g, %s)", r.max_late,
                  share(r.relative, r.absolute).c_str());
    return buf;
  }
  if (r.max_late > levels.bounded_relative * scale) {
    const char* sign = !std::isfinite(r.late_mean) || std::abs(r.late_mean) < 0.5 * r.max_late ? "±"
                       : r.late_mean < 0                                                       ? "-"
                                                                                               : "+";
    return "large, not growing (" + share(r.relative, r.absolute, sign) + ")";
  }
  return "bounded (" + share(r.relative, r.absolute) + ")";
}

// A first integral's error I - I0, from the running max of its absolute value
// at the checkpoints: an offset when it does not grow over the last decade
// (log-log slope of the running max over [T/10, T] below grows_slope), a drift
// when it does.  early: at T/1e4 (the first checkpoint at or after it); late: at T.
struct IntegralReading {
  double early = fate_detail::kNaN, late = fate_detail::kNaN, slope = fate_detail::kNaN;
  bool drifting = false;
  std::string words;
};

inline IntegralReading read_integral(const std::vector<double>& t, const std::vector<double>& running_max_abs_error,
                                     const FateLevels& levels = {}) {
  using namespace fate_detail;
  // The tail's reading without block means: only the running max and its slope.
  const TailReading r = read_tail(t, running_max_abs_error, {}, {}, 1.0, levels);
  IntegralReading g;
  g.early = r.max_early;
  g.late = r.max_late;
  g.slope = r.max_slope;
  g.drifting = r.growing;
  char buf[200];
  if (!std::isfinite(r.T)) {
    g.words = r.finite ? "no data" : "not finite";
  } else if (!r.finite) {
    std::snprintf(buf, sizeof buf, "not finite after t = %s", time_words(r.T).c_str());
    g.words = buf;
  } else if (r.max_late == 0) {
    g.words = "conserved exactly";
  } else if (r.points < 3) {
    std::snprintf(buf, sizeof buf, "too short to read (%.2g at t = %s)", g.late, time_words(r.T).c_str());
    g.words = buf;
  } else {
    const std::string span = [&] {
      char b[120];
      std::snprintf(b, sizeof b, "%.2g at t = %s, %.2g at t = %s", g.early, time_words(r.t_early).c_str(), g.late,
                    time_words(r.T).c_str());
      return std::string(b);
    }();
    if (g.drifting) {
      std::snprintf(buf, sizeof buf, "drifts (max ~t^%.2f; %s)", g.slope, span.c_str());
      g.words = buf;
    } else {
      g.words = "offset (" + span + ")";
    }
  }
  return g;
}

}  // namespace nhi
