// Study 5: Poincare sections of the contact oscillators.
// For every registered scene whose system declares a section family
// (system.hpp, has_section_states: contact_oscillator and contact_oscillator_nr),
// 10 initial states on one energy level (H = 3/2, H_y = 1/2, z0 spread over
// +-0.9 sqrt 2), every "main" method of nhi::study_methods(), h = 2 sin(pi/40):
// (z, zd) each time the method's own y passes a maximum (see run_section): for
// a leapfrog-type method in y (mp06, the symmetric DLA with alpha = 0) that is
// exactly every 40 steps, as in McLachlan & Perlmutter (2006) and Modin &
// Verdier (2020); the others' discrete y oscillation has another period, and a
// section every 40 steps would drift through y's phase (11-19 times thicker
// curves for every such method, the reference's points sampled at 2 pi k
// included as 1).  Every section point also records y there (its amplitude).
// Per initial state and method: the section points, the largest drift of the
// first integrals over the sections, and a thickness of the section curve
// (median over 36 angular bins around the reference's centre of the spread
// max r - min r of the points in the bin), also as a ratio to the reference's.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include "study.hpp"

namespace {

using nhi::Vec;
using study::json;

constexpr int kStates = 10;
constexpr int kSections = 600;
constexpr int kStride = 40;
const double kH = 2 * std::sin(M_PI / kStride);
constexpr int kBins = 36;

double round6(double x) {
  if (!std::isfinite(x)) return x;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return std::strtod(buf, nullptr);
}

// Thickness of a closed section curve: see the top of this file.
double thickness(const std::vector<double>& z, const std::vector<double>& zd, double cz, double czd) {
  std::vector<double> lo(kBins, INFINITY), hi(kBins, -INFINITY);
  for (size_t i = 0; i < z.size(); ++i) {
    const double a = std::atan2(zd[i] - czd, z[i] - cz), r = std::hypot(zd[i] - czd, z[i] - cz);
    const int b = std::min(kBins - 1, static_cast<int>((a + M_PI) / (2 * M_PI) * kBins));
    lo[b] = std::min(lo[b], r);
    hi[b] = std::max(hi[b], r);
  }
  std::vector<double> spread;
  for (int b = 0; b < kBins; ++b)
    if (hi[b] >= lo[b]) spread.push_back(hi[b] - lo[b]);
  if (spread.empty()) return NAN;
  std::nth_element(spread.begin(), spread.begin() + spread.size() / 2, spread.end());
  return spread[spread.size() / 2];
}

struct Section {
  std::vector<double> z, zd, y;
  double max_y_drift = 0;
  std::vector<double> max_dI;  // per first integral: max |I - I0| at the sections
  json report;                 // study::report_json of the run
  double cpu = 0;
  bool ok() const { return report["status"] == "ok"; }
};

// A Section as a cell's JSON (study::map_cells) and back; doubles round-trip exactly.
json section_to_json(const Section& s) {
  return {{"z", s.z},           {"zd", s.zd},         {"y", s.y},    {"max_y_drift", s.max_y_drift},
          {"max_dI", s.max_dI}, {"report", s.report}, {"cpu", s.cpu}};
}
Section section_from_json(const json& j) {
  Section s;
  j.at("z").get_to(s.z);
  j.at("zd").get_to(s.zd);
  j.at("y").get_to(s.y);
  s.max_y_drift = j.at("max_y_drift").get<double>();
  j.at("max_dI").get_to(s.max_dI);
  s.report = j.at("report");
  s.cpu = j.at("cpu").get<double>();
  return s;
}

// The section: each time y passes a maximum (ydot changes sign from + to -)
// between two reported points k, k+1, the crossing time is the root of the
// cubic Hermite interpolant of ydot (slopes from the index-reduced ODE's
// acceleration), and (z, zd) there are the cubic Hermite interpolants of z
// (slopes zd) and of zd (slopes zdd): O(h^4) interpolation, far below the
// methods' own errors.  The same rule for every method, the reference solution
// included (reported every h), so that the section is taken at y's maximum of
// each method's own y oscillation.
template <class S>
Section run_section(const S& sys, const nhi::MethodSpec& spec, const Vec<double, S::n>& q0,
                    const Vec<double, S::n>& v0) {
  constexpr int c = S::section_coordinate;
  Section sec;
  const auto I0 = sys.first_integrals(q0, v0);
  sec.max_dI.assign(I0.size(), 0.0);
  Vec<double, S::n> qp = q0, vp = v0, ap = sys.acceleration(q0, v0);
  auto hermite = [](double y0, double y1, double d0, double d1, double s) {  // d = slope * h
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * d0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * d1;
  };
  const double c0 = study::thread_cpu_seconds();
  const nhi::RunReport rep =
      nhi::run_method(sys, spec, q0, v0, kH, long(kSections) * kStride, [&](const nhi::Sample<S::n, S::m>& smp) {
        if (smp.k == 0) return true;
        const Vec<double, S::n> a = sys.acceleration(smp.q, smp.v);
        if (vp[1] > 0 && smp.v[1] <= 0) {
          double lo = 0, hi = 1;  // ydot(lo) > 0 >= ydot(hi)
          for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (lo + hi);
            (hermite(vp[1], smp.v[1], ap[1] * kH, a[1] * kH, mid) > 0 ? lo : hi) = mid;
          }
          const double s = 0.5 * (lo + hi);
          Vec<double, S::n> q, v;
          for (int i = 0; i < S::n; ++i) {
            q[i] = hermite(qp[i], smp.q[i], vp[i] * kH, smp.v[i] * kH, s);
            v[i] = hermite(vp[i], smp.v[i], ap[i] * kH, a[i] * kH, s);
          }
          sec.z.push_back(q[c]);
          sec.zd.push_back(v[c]);
          sec.y.push_back(q[1]);
          sec.max_y_drift = std::max(sec.max_y_drift, std::abs(q[1] - q0[1]));
          const auto I = sys.first_integrals(smp.q, smp.v);  // at the grid point, not interpolated
          for (size_t i = 0; i < I.size(); ++i) sec.max_dI[i] = std::max(sec.max_dI[i], std::abs(I[i] - I0[i]));
        }
        qp = smp.q;
        vp = smp.v;
        ap = a;
        return true;
      });
  sec.cpu = study::thread_cpu_seconds() - c0;
  sec.report = study::report_json(rep, kH);  // every run steps kH, the reference's output included
  return sec;
}

}  // namespace

int main(int argc, char** argv) {
  const study::Options opt = study::parse(argc, argv, "Poincare sections of the contact oscillators");
  const std::vector<nhi::StudyMethod> all_methods =
      study::methods([](const nhi::StudyMethod& m) { return !m.external && m.group == "main"; });
  json result = {
      {"study", "poincare"},
      {"config",
       {{"h", kH},
        {"stride", kStride},
        {"sections", kSections},
        {"states", kStates},
        {"section",
         "(z, zd) at each maximum of the method's y (ydot from + to -), cubic Hermite interpolation between reported "
         "points; h = 2 sin(pi/40) for every method, the reference reported every h"},
        {"thickness", "median over 36 angular bins (around the reference section's centre) of max r - min r"},
        {"first_integrals", "max |I - I0| over the grid points just after each section"},
        {"precision", "section points rounded to 6 significant digits"}}}};
  for (const std::string& name : study::scene_names(opt)) {
    const json sc = study::scene(opt, name);
    nhi::visit_scene(sc, [&](const auto& sys, const auto&, const auto&) {
      using S = std::decay_t<decltype(sys)>;
      if constexpr (nhi::has_section_states<S>::value) {
        const std::vector<nhi::StudyMethod> methods = study::on<S>(all_methods);
        const auto states = sys.section_states(kStates);
        study::Cells cells;
        cells.label = "poincare " + name;
        cells.count = methods.size() * states.size();
        cells.run = [&](size_t i) {
          const auto& st = states[i % states.size()];
          return section_to_json(run_section(sys, methods[i / states.size()].spec, st.first, st.second));
        };
        cells.cost = [&](size_t i) {
          return double(kSections) * kStride * study::step_weight(methods[i / states.size()].spec);
        };
        cells.name = [&](size_t i) {
          return methods[i / states.size()].label() + ", initial state " + std::to_string(i % states.size());
        };
        std::vector<Section> secs;
        for (const json& j : study::map_cells(opt, cells)) secs.push_back(section_from_json(j));
        // Centres: the mean of the reference's section points, per state.
        size_t ref = 0;
        for (size_t m = 0; m < methods.size(); ++m)
          if (methods[m].adaptive()) ref = m;
        std::vector<double> cz(states.size()), czd(states.size()), ref_thick(states.size());
        for (size_t j = 0; j < states.size(); ++j) {
          const Section& r = secs[ref * states.size() + j];
          cz[j] = std::accumulate(r.z.begin(), r.z.end(), 0.0) / double(r.z.size());
          czd[j] = std::accumulate(r.zd.begin(), r.zd.end(), 0.0) / double(r.zd.size());
          ref_thick[j] = thickness(r.z, r.zd, cz[j], czd[j]);
        }
        const auto names = S::first_integral_names();
        json ms = json::array();
        for (size_t m = 0; m < methods.size(); ++m) {
          json runs = json::array();
          std::vector<double> ratios;
          std::vector<double> worst_dI(names.size(), 0.0);
          double worst_y = 0, cpu = 0;
          bool ok = true;
          for (size_t j = 0; j < states.size(); ++j) {
            const Section& s = secs[m * states.size() + j];
            const double th = thickness(s.z, s.zd, cz[j], czd[j]);
            if (std::isfinite(th) && ref_thick[j] > 0) ratios.push_back(th / ref_thick[j]);
            json r = s.report;
            ok = ok && s.ok();
            std::vector<double> z, zd, y;
            for (size_t k = 0; k < s.z.size(); ++k) {
              z.push_back(round6(s.z[k]));
              zd.push_back(round6(s.zd[k]));
              y.push_back(round6(s.y[k]));
            }
            r["z"] = z;
            r["zd"] = zd;
            r["y"] = y;
            r["thickness"] = std::isfinite(th) ? json(th) : json(nullptr);
            r["max_abs_y_minus_y0"] = s.max_y_drift;
            for (size_t i = 0; i < names.size(); ++i) {
              r["max_abs_" + std::string(names[i]) + "_error"] = s.max_dI[i];
              worst_dI[i] = std::max(worst_dI[i], s.max_dI[i]);
            }
            worst_y = std::max(worst_y, s.max_y_drift);
            cpu += s.cpu;
            runs.push_back(r);
          }
          json summary = {{"all_ok", ok}, {"max_abs_y_minus_y0", worst_y}, {"cpu_seconds", cpu}};
          if (!ratios.empty()) {
            std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
            summary["median_thickness_ratio"] = ratios[ratios.size() / 2];
          }
          for (size_t i = 0; i < names.size(); ++i)
            summary["max_abs_" + std::string(names[i]) + "_error"] = worst_dI[i];
          ms.push_back({{"label", methods[m].label()}, {"summary", summary}, {"runs", runs}});
        }
        json init = json::array();
        for (const auto& st : states)
          init.push_back({{"q0", study::to_json<S::n>(st.first)}, {"v0", study::to_json<S::n>(st.second)}});
        result["scenes"][name] = {{"scene", sc}, {"initial_states", init}, {"methods", ms}};
      }
      return 0;
    });
  }
  return study::finish(opt, result);
}
