// nhi: run one scene.
//   nhi run SCENE.json [--set key=value]... [-o OUT.json]
// Exit status: 0 run ok; 3 run ended with status "failed" (the result is still
// written); 2 bad input or unwritable output (nothing written); 130 interrupted
// by SIGINT/SIGTERM (nothing written).  The output file is written to a
// temporary file in the same directory and renamed, so it is whole or absent.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>

#include "nhi/output.hpp"
#include "nhi/scene.hpp"
#include "nhi/signals.hpp"

namespace {

int error(const std::string& message, int code = 2) {
  std::cerr << "nhi: error: " << message << "\n";
  return code;
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
  run->add_option("--set", sets, "Override one scene key: key=JSON value (or a bare string)")
      ->allow_extra_args(false);
  run->add_option("-o,--output", out_path, "Result file (default: standard output)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    return error(e.what());
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

  const std::string text = result.dump() + "\n";
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
