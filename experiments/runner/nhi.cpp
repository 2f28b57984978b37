// nhi: run one scene, or list what the library has.
//   nhi run SCENE.json [--set key=value]... [-o OUT.json]
//   nhi list [--markdown | --json | --gnuplot]   systems (parameters, defaults), methods, compositions
//   nhi --version                    version, git revision, compiler, build flags
// Exit status: 0 run ok; 3 run ended with status "failed" (the result is still
// written); 2 bad input (an unknown subcommand too) or unwritable output
// (nothing written); 130 interrupted by SIGINT/SIGTERM (nothing written).  The output file is written to a
// temporary file in the same directory and renamed, so it is whole or absent.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "nhi/roles/signals.hpp"
#include "nhi/runner/output.hpp"
#include "nhi/runner/scene.hpp"
#include "nhi/runner/scene_detail.hpp"

// The CMake project version (CMakeLists.txt's project(... VERSION)); a build
// may pass it as NHI_VERSION.  tests/test_runner_edges.cpp checks that the two agree.
#ifndef NHI_VERSION
#define NHI_VERSION "0.1.0"
#endif

namespace {

const std::vector<std::string> kSubcommands = {"run", "list"};

// `nhi --version`: the version and the provenance meta() records in every result.
std::string version_text() {
  const nhi::json m = nhi::meta();
  std::string rev = m["git_revision"].get<std::string>();
  if (m["git_dirty"].get<bool>()) rev += " (dirty)";
  return std::string("nhi ") + NHI_VERSION + "\ngit revision: " + rev +
         "\ncompiler: " + m["compiler"].get<std::string>() + "\nbuild flags: " + m["build_flags"].get<std::string>();
}

// A failure reason as the user reads it: std::to_string and printf write a
// non-finite number as nan, -nan, inf or -inf; say NaN, Infinity, -Infinity.
std::string nonfinite_words(const std::string& s) {
  auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.'; };
  std::string out;
  for (size_t i = 0; i < s.size();) {
    const bool start = i == 0 || !word(s[i - 1]);
    bool done = false;
    if (start)
      for (const auto& [from, to] : {std::pair<const char*, const char*>{"-nan", "NaN"},
                                     {"nan", "NaN"},
                                     {"-inf", "-Infinity"},
                                     {"inf", "Infinity"}}) {
        const size_t k = std::strlen(from);
        if (s.compare(i, k, from) == 0 && (i + k == s.size() || !word(s[i + k]))) {
          out += to;
          i += k;
          done = true;
          break;
        }
      }
    if (!done) out += s[i++];
  }
  return out;
}

int error(const std::string& message, int code = 2) {
  std::cerr << "nhi: error: " << message << "\n";
  return code;
}

// A number as the scene file would write it.
std::string num(const nhi::json& x) {
  std::ostringstream os;
  os << x.get<double>();
  return os.str();
}

std::string params_of(const nhi::json& sys) {
  std::string out;
  for (const auto& [k, v] : sys["params"].items()) out += (out.empty() ? "" : ", ") + k + " = " + num(v);
  return out.empty() ? "-" : out;
}

// The method's scene keys with their values: "method", its own keys in their
// declared order (the catalog's "own"), then a composition if any.
std::string method_keys(const nhi::json& m) {
  std::string out = "\"method\": \"" + m["method"].get<std::string>() + "\"";
  for (const auto& key : m["own"]) {
    const nhi::json& v = m[key.get<std::string>()];
    out += ", \"" + key.get<std::string>() + "\": " + (v.is_string() ? v.dump() : num(v));
  }
  if (m["composition"] != "none") out += ", \"composition\": \"" + m["composition"].get<std::string>() + "\"";
  return out;
}

std::string yes(const nhi::json& b) { return b.get<bool>() ? "yes" : "no"; }

std::string list_text(const nhi::json& c) {
  std::ostringstream os;
  os << "systems (\"system\"; \"params\" with their defaults):\n";
  for (const auto& s : c["systems"])
    os << "  " << s["name"].get<std::string>() << "  n = " << s["n"] << ", m = " << s["m"] << "; " << params_of(s)
       << "\n";
  os << "methods (label: scene keys; order):\n";
  for (const auto& m : c["methods"])
    os << "  " << m["label"].get<std::string>() << ": " << method_keys(m) << "; order " << m["order"]
       << (m["symmetric"].get<bool>() ? ", symmetric" : "") << (m["implicit"].get<bool>() ? ", implicit" : "") << "\n";
  os << "compositions (\"composition\", of a symmetric method):\n";
  for (const auto& k : c["compositions"])
    os << "  " << k["name"].get<std::string>() << "  order " << k["order"] << ", " << k["stages"] << " stages\n";
  return os.str();
}

std::string list_markdown(const nhi::json& c) {
  std::ostringstream os;
  os << "## scenes\n\n| system | n | m | parameters (defaults) | reversible | separable |\n|---|---|---|---|---|---|\n";
  for (const auto& s : c["systems"])
    os << "| `" << s["name"].get<std::string>() << "` | " << s["n"] << " | " << s["m"] << " | " << params_of(s) << " | "
       << yes(s["reversible"]) << " | " << yes(s["separable"]) << " |\n";
  os << "\n## methods\n\nThe methods every study runs (`nhi list` adds the variants).\n\n| label | scene keys | order "
        "| symmetric | implicit | composable |\n|---|---|---|---|---|---|\n";
  for (const auto& m : c["methods"]) {
    if (m["group"] != "main") continue;
    os << "| " << m["label"].get<std::string>() << " | `" << method_keys(m) << "` | " << m["order"] << " | "
       << yes(m["symmetric"]) << " | " << yes(m["implicit"]) << " | " << yes(m["composable"]) << " |\n";
  }
  os << "\n## compositions\n\n| composition | order | stages |\n|---|---|---|\n";
  for (const auto& k : c["compositions"])
    os << "| `" << k["name"].get<std::string>() << "` | " << k["order"] << " | " << k["stages"] << " |\n";
  return os.str();
}

// plots/method_styles.gp: each study method's declared line style by its label.
std::string list_gnuplot(const nhi::json& c) {
  std::ostringstream os;
  os << "# Written by `nhi list --gnuplot` (make figures) from the line style each method declares\n"
        "# for its study entries (StudyEntry::style in its header): do not edit.  plots/style.gp\n"
        "# loads it and defines the styles and other_ls() for labels that are not methods.\n"
        "method_ls(label) = \\\n";
  for (const auto& m : c["methods"])
    os << "  label eq " << m["label"].dump() << " ? " << m["style"] << " : \\\n";
  os << "  other_ls(label)\n";
  return os.str();
}

}  // namespace

int main(int argc, char** argv) {
  // Handlers first: from here on an interrupt is a clean "nothing written".
  nhi::install_interrupt_handlers();
  CLI::App app{"Nonholonomic integrators (Cortes & Martinez 2001): run one scene"};
  app.require_subcommand(1);
  app.set_version_flag("--version", version_text, "Print the version, compiler and build flags and exit");
  auto* run = app.add_subcommand("run", "Run SCENE.json and write the result as JSON");
  std::string scene_path, out_path;
  std::vector<std::string> sets;
  run->add_option("scene", scene_path, "Scene file (JSON)")->required();
  run->add_option("--set", sets, "Override one scene key: key=JSON value (or a bare string)")->allow_extra_args(false);
  run->add_option("-o,--output", out_path, "Result file (default: standard output)");
  auto* list = app.add_subcommand("list", "List the systems (parameters, defaults), methods and compositions");
  bool markdown = false, as_json = false, gnuplot = false;
  auto* md_flag = list->add_flag("--markdown", markdown, "As Markdown tables (the README's)");
  auto* json_flag = list->add_flag("--json", as_json, "As JSON")->excludes(md_flag);
  list->add_flag("--gnuplot", gnuplot, "The methods' line styles for the figures (plots/method_styles.gp)")
      ->excludes(md_flag)
      ->excludes(json_flag);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    // The subcommand is the first argument that is not an option (nhi has no
    // options that take a value): name it if it is not one.
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.empty() || a[0] == '-') continue;
      if (std::find(kSubcommands.begin(), kSubcommands.end(), a) == kSubcommands.end())
        return error("unknown subcommand " + nhi::scene_detail::show(nhi::json(a)) + " (expected run or list)" +
                     nhi::scene_detail::did_you_mean(a, kSubcommands));
      break;
    }
    return error(e.what());
  }
  if (list->parsed()) {
    const nhi::json c = nhi::catalog();
    std::cout << (as_json    ? c.dump(2) + "\n"
                  : markdown ? list_markdown(c)
                  : gnuplot  ? list_gnuplot(c)
                             : list_text(c));
    return 0;
  }

  nhi::json resolved;
  try {
    nhi::json scene = nhi::load_scene_file(scene_path);
    for (const auto& s : sets) nhi::apply_override(&scene, s);
    resolved = nhi::validate_scene(scene);
  } catch (const nhi::SceneError& e) {
    return error(e.what());
  } catch (const nhi::json::exception& e) {
    return error(std::string("scene: ") + e.what());
  }

  // Claim the output's temporary file before running, so an unwritable path
  // fails now and not after a long run.
  std::unique_ptr<nhi::AtomicFile> out;
  if (!out_path.empty()) {
    try {
      out = std::make_unique<nhi::AtomicFile>(out_path);
    } catch (const std::exception& e) {
      return error(e.what());
    }
  }
  auto discard = [&] {
    if (out) out->discard();
  };

  nhi::json result;
  try {
    result = nhi::run_scene(resolved);
  } catch (const std::exception& e) {
    discard();
    return error(std::string("run: ") + e.what(), 1);
  }
  if (nhi::interrupt_flag().load()) {
    discard();
    return error("interrupted; no result written", 130);
  }

  const std::string text = nhi::json_lines(result);
  if (!out) {
    std::cout << text;
  } else {
    try {
      out->commit(text);
    } catch (const std::exception& e) {
      return error(e.what(), 2);  // unwritable output: nothing written (AtomicFile removes its temporary)
    }
  }
  if (result["status"] != "ok") {
    std::cerr << "nhi: run failed at step " << result["failure"]["step"] << ": "
              << nonfinite_words(result["failure"]["reason"].get<std::string>()) << "\n";
    return 3;
  }
  return 0;
}
