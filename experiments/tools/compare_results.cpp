// compare_results: checks that the JSON files an experiment run writes into results/
// agree with those of a previous run to round-off. Used while refactoring: run the
// studies into a fresh directory, then
//
//   compare_results OLD_DIR NEW_DIR [--tol 1e-9] [--atol 0] [--ignore-key NAME]... [--per-key]
//
// --atol A: numbers closer than A in absolute value count as equal (for values
// that are themselves round-off, such as a discrete constraint of 1e-16).
//
// Every *.json file of OLD_DIR (sorted by name) is compared with NEW_DIR/<same name>;
// both trees are walked in parallel. Numbers are compared by relative difference
// |a-b| / max(|a|, |b|, 1e-300) (integers and floats alike); a file's line counts those
// above tol. Strings must be equal, but a string mismatch is only reported as a "text
// difference" (method labels may be renamed on purpose). An array of entries, objects
// that one key identifies (the first of ID_KEYS below whose values are strings, unique
// on both sides: a method's `label`, a work-precision run's `keys`), is matched by that
// key, not by position: an entry on one side only is "new" or "gone", listed but not a
// difference, so a row inserted into a method list moves no other row (and a renamed
// label is one gone and one new entry). Other arrays are compared by position. Missing
// keys, positional arrays of different length, type mismatches (null vs number
// included) and changed booleans are "structural" differences. Timing, provenance and
// machine-dependent keys are skipped (see the constants below), and so is a study's
// `stats` (how the run was split over ranks and threads).
//
// Exit status: 0 if no file is missing, there are no structural differences and every
// max rel diff <= tol (new and gone entries do not count); 1 otherwise; 2 on a usage
// error or unreadable JSON.
#include <nlohmann/json.hpp>

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;

// ---- What is not compared ------------------------------------------------------------
// Object keys skipped wherever they occur (timing, provenance, machine dependent).
const std::set<std::string> SKIP_KEYS = {
    "meta",       "wall_seconds", "cpu_seconds", "cpu_ns",           "real_ns",         "cpu_final",
    "cpu_energy", "peak_rss_kb",  "time_utc",    "cpu_energy_short", "cpu_energy_long", "busy_seconds",
};
// Object keys skipped only inside one file: {file name, key}.
const std::set<std::pair<std::string, std::string>> SKIP_KEYS_IN_FILE = {
    {"step_costs.json", "iterations"},  // Google Benchmark iteration counts
};
// Files not compared at all (Google Benchmark timings only).
const std::set<std::string> SKIP_FILES = {"step_costs.json"};
// Keys that identify an entry of an array, tried in this order (see the top).
const std::vector<std::string> ID_KEYS = {"label", "name", "scene", "method", "system", "keys"};
// Paths printed per kind of difference.
constexpr int MAX_LISTED = 3;

struct FileReport {
  long numbers = 0;
  double max_rel = 0.0;
  std::string max_path;
  double max_old = 0.0, max_new = 0.0;
  long above_tol = 0;  // numbers with rel diff > tol
  long structural = 0, text = 0;
  std::vector<std::string> structural_list, text_list;
  long added = 0, gone = 0;  // entries of keyed arrays on one side only
  std::vector<std::string> added_list, gone_list;
  std::map<std::string, std::pair<double, long>> per_key;  // leaf key -> (max rel, count)
};

struct Comparer {
  std::string file;
  std::set<std::string> extra_skip;  // from --ignore-key
  FileReport r;
  double atol = 0.0;  // from --atol
  double tol = 1e-9;  // from --tol

  bool skipped(const std::string& key) const {
    // --ignore-key takes a shell pattern ('cpu_*').
    const bool ignored = std::any_of(extra_skip.begin(), extra_skip.end(),
                                     [&](const std::string& p) { return fnmatch(p.c_str(), key.c_str(), 0) == 0; });
    return SKIP_KEYS.count(key) || ignored || SKIP_KEYS_IN_FILE.count({file, key});
  }
  // A study's `stats` (ranks, threads, per-rank cells and busy times: how
  // the run was split, not what it computed); a run's `stats` (Newton
  // counts, steps) is compared.
  static bool study_stats(const std::string& key, const json& a, const json& b) {
    auto is = [](const json& j) { return j.is_object() && j.contains("ranks") && j.contains("busy_seconds"); };
    return key == "stats" && (is(a) || is(b));
  }
  void structural(const std::string& path, const std::string& what) {
    if (r.structural++ < MAX_LISTED) r.structural_list.push_back((path.empty() ? "(root)" : path) + ": " + what);
  }
  static std::string kind(const json& v) { return v.is_number() ? "number" : v.type_name(); }

  // The first of ID_KEYS that identifies every entry of both arrays ("" if none).
  static std::string id_key(const json& a, const json& b) {
    if (a.empty() && b.empty()) return "";
    for (const std::string& k : ID_KEYS) {
      bool ok = true;
      for (const json* arr : {&a, &b}) {
        std::set<std::string> seen;
        for (const json& e : *arr)
          if (!e.is_object() || !e.contains(k) || !e.at(k).is_string() ||
              !seen.insert(e.at(k).get<std::string>()).second) {
            ok = false;
            break;
          }
        if (!ok) break;
      }
      if (ok) return k;
    }
    return "";
  }
  static void note(long& count, std::vector<std::string>& list, const std::string& what) {
    if (count++ < MAX_LISTED) list.push_back(what);
  }

  // `leaf` is the name of the nearest enclosing object key (used by --per-key).
  void walk(const json& a, const json& b, std::string& path, const std::string& leaf) {
    if (a.is_number() && b.is_number()) {
      const double x = a.get<double>(), y = b.get<double>();
      double rel = 0.0;
      if (x != y && std::fabs(x - y) > atol) rel = std::fabs(x - y) / std::max({std::fabs(x), std::fabs(y), 1e-300});
      ++r.numbers;
      auto& pk = r.per_key[leaf.empty() ? "(root)" : leaf];
      pk.first = std::max(pk.first, rel);
      ++pk.second;
      if (rel > tol) ++r.above_tol;
      if (rel > r.max_rel) {
        r.max_rel = rel;
        r.max_path = path;
        r.max_old = x;
        r.max_new = y;
      }
    } else if (kind(a) != kind(b)) {
      structural(path, "type " + kind(a) + " -> " + kind(b));
    } else if (a.is_object()) {
      const size_t len = path.size();
      for (auto it = a.begin(); it != a.end(); ++it) {
        if (skipped(it.key())) continue;
        if (study_stats(it.key(), it.value(), b.contains(it.key()) ? b.at(it.key()) : json())) continue;
        path += (len ? "." : "") + it.key();
        if (!b.contains(it.key()))
          structural(path, "missing in new");
        else
          walk(it.value(), b.at(it.key()), path, it.key());
        path.resize(len);
      }
      for (auto it = b.begin(); it != b.end(); ++it)
        if (!skipped(it.key()) && !study_stats(it.key(), it.value(), json()) && !a.contains(it.key()))
          structural(path + (len ? "." : "") + it.key(), "missing in old");
    } else if (a.is_array()) {
      const std::string k = id_key(a, b);
      if (!k.empty()) {  // matched by k
        std::map<std::string, const json*> in_new;
        for (const json& e : b) in_new[e.at(k).get<std::string>()] = &e;
        const size_t len = path.size();
        for (const json& e : a) {
          const std::string id = e.at(k).get<std::string>();
          path += "[" + k + "=" + id + "]";
          const auto it = in_new.find(id);
          if (it == in_new.end())
            note(r.gone, r.gone_list, path);
          else
            walk(e, *it->second, path, leaf);
          path.resize(len);
        }
        std::set<std::string> in_old;
        for (const json& e : a) in_old.insert(e.at(k).get<std::string>());
        for (const json& e : b)
          if (!in_old.count(e.at(k).get<std::string>()))
            note(r.added, r.added_list, path + "[" + k + "=" + e.at(k).get<std::string>() + "]");
      } else {  // by position
        if (a.size() != b.size())
          structural(path, "array length " + std::to_string(a.size()) + " -> " + std::to_string(b.size()));
        const size_t len = path.size(), n = std::min(a.size(), b.size());
        for (size_t i = 0; i < n; ++i) {
          path += "[" + std::to_string(i) + "]";
          walk(a[i], b[i], path, leaf);
          path.resize(len);
        }
      }
    } else if (a.is_string()) {
      if (a != b && r.text++ < MAX_LISTED) r.text_list.push_back(path + ": " + a.dump() + " -> " + b.dump());
    } else if (a != b) {  // booleans (null == null)
      structural(path, "value " + a.dump() + " -> " + b.dump());
    }
  }
};

static bool load(const fs::path& p, json& out) {
  std::ifstream in(p);
  if (!in) {
    std::printf("%s: cannot open\n", p.string().c_str());
    return false;
  }
  try {
    out = json::parse(in);
  } catch (const std::exception& e) {
    std::printf("%s: unreadable JSON: %s\n", p.string().c_str(), e.what());
    return false;
  }
  return true;
}

static std::vector<std::string> json_files(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".json") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

static int usage(const char* msg) {
  std::fprintf(
      stderr, "%s\nusage: compare_results OLD_DIR NEW_DIR [--tol 1e-9] [--atol 0] [--ignore-key NAME]... [--per-key]\n",
      msg);
  return 2;
}

int main(int argc, char** argv) {
  std::vector<std::string> dirs;
  double tol = 1e-9, atol = 0.0;
  bool per_key = false;
  std::set<std::string> ignore;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--tol" || arg == "--atol" || arg == "--ignore-key") {
      if (i + 1 >= argc) return usage(("missing value after " + arg).c_str());
      const std::string val = argv[++i];
      if (arg == "--ignore-key") {
        ignore.insert(val);
        continue;
      }
      char* end = nullptr;
      const double x = std::strtod(val.c_str(), &end);
      if (val.empty() || *end != '\0' || !(x >= 0)) return usage(("bad " + arg + " value: " + val).c_str());
      (arg == "--tol" ? tol : atol) = x;
    } else if (arg == "--per-key") {
      per_key = true;
    } else if (arg.rfind("--", 0) == 0) {
      return usage(("unknown option: " + arg).c_str());
    } else {
      dirs.push_back(arg);
    }
  }
  if (dirs.size() != 2) return usage("need exactly two directories");
  const fs::path old_dir = dirs[0], new_dir = dirs[1];
  for (const auto& d : {old_dir, new_dir})
    if (!fs::is_directory(d)) return usage(("not a directory: " + d.string()).c_str());

  const auto old_files = json_files(old_dir), new_files = json_files(new_dir);
  bool fail = false, unreadable = false;
  double overall = 0.0;
  std::string overall_where = "-";
  long files_compared = 0, missing = 0, added = 0, gone = 0;

  for (const auto& f : old_files) {
    if (SKIP_FILES.count(f)) {
      std::printf("%s: skipped (timings)\n", f.c_str());
      continue;
    }
    if (!fs::exists(new_dir / f)) {
      std::printf("%s: missing in %s\n", f.c_str(), new_dir.c_str());
      ++missing;
      fail = true;
      continue;
    }
    json a, b;
    const bool read_old = load(old_dir / f, a), read_new = load(new_dir / f, b);  // both, for both messages
    if (!read_old || !read_new) {
      unreadable = true;
      continue;
    }
    Comparer c{f, ignore, {}, atol, tol};
    std::string path;
    c.walk(a, b, path, "");
    const FileReport& r = c.r;
    ++files_compared;
    if (r.max_rel == 0.0 && r.structural == 0 && r.text == 0 && r.added == 0 && r.gone == 0) {
      std::printf("%s: %ld numbers, identical\n", f.c_str(), r.numbers);
    } else {
      std::printf("%s: %ld numbers, max rel diff %.3g", f.c_str(), r.numbers, r.max_rel);
      if (r.max_rel > 0)
        std::printf(" at %s (old %.17g, new %.17g), %ld above tol", r.max_path.c_str(), r.max_old, r.max_new,
                    r.above_tol);
      std::printf("; %ld structural, %ld text differences", r.structural, r.text);
      if (r.added || r.gone) std::printf("; %ld new, %ld gone entries", r.added, r.gone);
      std::printf("%s\n", r.max_rel > tol ? "  [> tol]" : "");
      for (const auto& s : r.structural_list) std::printf("    structural: %s\n", s.c_str());
      for (const auto& s : r.text_list) std::printf("    text: %s\n", s.c_str());
      for (const auto& s : r.added_list) std::printf("    new: %s\n", s.c_str());
      for (const auto& s : r.gone_list) std::printf("    gone: %s\n", s.c_str());
    }
    if (per_key) {  // largest difference first, so the quantity that moved is on top
      std::vector<std::pair<std::string, std::pair<double, long>>> keys(r.per_key.begin(), r.per_key.end());
      std::stable_sort(keys.begin(), keys.end(),
                       [](const auto& x, const auto& y) { return x.second.first > y.second.first; });
      for (const auto& [key, v] : keys)
        std::printf("    %-28s max rel diff %-10.3g (%ld numbers)\n", key.c_str(), v.first, v.second);
    }
    if (r.max_rel > tol || r.structural > 0) fail = true;
    added += r.added;
    gone += r.gone;
    if (r.max_rel > overall) {
      overall = r.max_rel;
      overall_where = f + " " + r.max_path;
    }
  }
  for (const auto& f : new_files)
    if (!std::binary_search(old_files.begin(), old_files.end(), f))
      std::printf("%s: new (only in %s)\n", f.c_str(), new_dir.c_str());

  std::printf("\noverall max rel diff %.3g (%s); tol %.3g; %ld files compared, %ld missing", overall,
              overall_where.c_str(), tol, files_compared, missing);
  if (added || gone) std::printf("; %ld new, %ld gone entries", added, gone);
  std::printf("\n");
  if (unreadable) {
    std::printf("verdict: ERROR (unreadable JSON)\n");
    return 2;
  }
  std::printf("verdict: %s\n", fail ? "DIFFERENT (see above)" : "AGREE to tol");
  return fail ? 1 : 0;
}
