// Fits shared by the studies and the tests: the least-squares slope of log y
// against log x (the order of a convergence study, the growth exponent of an
// error envelope), and the order fit of a convergence series.
#pragma once

#include <cmath>
#include <optional>
#include <vector>

namespace nhi {

inline double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double a = std::log(x[i]), b = std::log(y[i]);
    sx += a;
    sy += b;
    sxx += a * a;
    sxy += a * b;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// The order of a convergence series: errors err[j] at steps h[j] (NaN for a
// failed run).  The fit uses the points with error above `floor` (round-off and
// the reference's own error) and, of those, the `finest` smallest h (0: all):
// the asymptotic regime.  Local orders are log(e_{j-1}/e_j) / log(h_{j-1}/h_j)
// between neighbours that both ran, where e_j is above the floor.
struct OrderFit {
  std::vector<double> h, error;              // the points fitted
  std::optional<double> order;               // none with fewer than 3 points
  std::vector<std::optional<double>> local;  // h.size() - 1 entries
};

//
// With drop_floor_tail, the finest points that sit on a floor higher than
// `floor` (the accumulated error of the implicit solves, or of the reference)
// are dropped first: while the local order between the last two points differs
// by more than 0.5 from the one before it, the last point goes.
inline OrderFit fit_order(const std::vector<double>& hs, const std::vector<double>& errs, double floor,
                          size_t finest = 0, bool drop_floor_tail = false) {
  OrderFit f;
  for (size_t j = 0; j < hs.size(); ++j) {
    const bool ok = std::isfinite(errs[j]);
    if (ok && errs[j] > floor) {
      f.h.push_back(hs[j]);
      f.error.push_back(errs[j]);
    }
    if (j > 0) {
      if (ok && std::isfinite(errs[j - 1]) && errs[j] > floor)
        f.local.push_back(std::log(errs[j - 1] / errs[j]) / std::log(hs[j - 1] / hs[j]));
      else
        f.local.push_back(std::nullopt);
    }
  }
  auto order_at = [&](size_t j) { return std::log(f.error[j - 1] / f.error[j]) / std::log(f.h[j - 1] / f.h[j]); };
  while (drop_floor_tail && f.h.size() >= 4 && std::abs(order_at(f.h.size() - 1) - order_at(f.h.size() - 2)) > 0.5) {
    f.h.pop_back();
    f.error.pop_back();
  }
  if (finest > 0 && f.h.size() > finest) {  // keep the finest
    f.h.erase(f.h.begin(), f.h.end() - finest);
    f.error.erase(f.error.begin(), f.error.end() - finest);
  }
  if (f.h.size() >= 3) f.order = loglog_slope(f.h, f.error);
  return f;
}

}  // namespace nhi
