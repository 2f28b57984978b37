// nhi: run one scene, or list what the library has.
//   nhi run SCENE.json [--set key=value]... [-o OUT.json]
//   nhi list [--markdown | --json]   systems (parameters, defaults), methods, compositions
// Exit status: 0 run ok; 3 run ended with status "failed" (the result is still
// written); 2 bad input or unwritable output (nothing written); 130 interrupted
// by SIGINT/SIGTERM (nothing written).  The output file is written to a
// temporary file in the same directory and renamed, so it is whole or absent.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

#include "nhi/output.hpp"
#include "nhi/scene.hpp"
#include "nhi/signals.hpp"

namespace {

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

std::string method_keys(const nhi::json& m) {
  std::string out = "\"method\": \"" + m["method"].get<std::string>() + "\"";
  if (!m["discretization"].is_null())
    out += ", \"discretization\": \"" + m["discretization"].get<std::string>() + "\", \"alpha\": " + num(m["alpha"]);
  if (m.contains("stages") && !m["stages"].is_null()) out += ", \"stages\": " + num(m["stages"]);
  if (m.contains("constraint") && m["constraint"] == "endpoint")
    out += ", \"constraint\": \"" + m["constraint"].get<std::string>() + "\"";
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

}  // namespace

int main(int argc, char** argv) {
  // Handlers first: from here on an interrupt is a clean "nothing written".
  nhi::install_interrupt_handlers();
  CLI::App app{"Nonholonomic integrators (Cortes & Martinez 2001): run one scene"};
  app.require_subcommand(1);
  auto* run = app.add_subcommand("run", "Run SCENE.json and write the result as JSON");
  std::string scene_path, out_path;
  std::vector<std::string> sets;
  run->add_option("scene", scene_path, "Scene file (JSON)")->required();
  run->add_option("--set", sets, "Override one scene key: key=JSON value (or a bare string)")->allow_extra_args(false);
  run->add_option("-o,--output", out_path, "Result file (default: standard output)");
  auto* list = app.add_subcommand("list", "List the systems (parameters, defaults), methods and compositions");
  bool markdown = false, as_json = false;
  auto* md_flag = list->add_flag("--markdown", markdown, "As Markdown tables (the README's)");
  list->add_flag("--json", as_json, "As JSON")->excludes(md_flag);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    return error(e.what());
  }
  if (list->parsed()) {
    const nhi::json c = nhi::catalog();
    std::cout << (as_json ? c.dump(2) + "\n" : markdown ? list_markdown(c) : list_text(c));
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
      return error(e.what(), 1);
    }
  }
  if (result["status"] != "ok") {
    std::cerr << "nhi: run failed at step " << result["failure"]["step"] << ": "
              << result["failure"]["reason"].get<std::string>() << "\n";
    return 3;
  }
  return 0;
}
