// nhi: run one scene.
//   nhi run SCENE.json [--set key=value]... [-o OUT.json]
// Exit status: 0 run ok; 3 run ended with status "failed" (the result is still
// written); 2 bad input or unwritable output (nothing written); 130 interrupted
// by SIGINT/SIGTERM (nothing written).  The output file is written to a
// temporary file in the same directory and renamed, so it is whole or absent.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <iostream>

#include "nhi/integrate.hpp"
#include "nhi/scene.hpp"

namespace {

void on_signal(int) { nhi::interrupt_flag().store(true); }

int error(const std::string& message, int code = 2) {
  std::cerr << "nhi: error: " << message << "\n";
  return code;
}

bool write_all(int fd, const std::string& s) {
  size_t done = 0;
  while (done < s.size()) {
    const ssize_t k = ::write(fd, s.data() + done, s.size() - done);
    if (k < 0) return false;
    done += static_cast<size_t>(k);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
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
  std::string tmp_path;
  int fd = -1;
  if (!out_path.empty()) {
    struct stat st {};
    if (::stat(out_path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
      return error("output '" + out_path + "' is a directory");
    tmp_path = out_path + ".tmp." + std::to_string(::getpid());
    fd = ::open(tmp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0) return error("cannot write output '" + out_path + "': " + std::strerror(errno));
  }
  auto discard = [&] {
    if (fd >= 0) {
      ::close(fd);
      ::unlink(tmp_path.c_str());
    }
  };

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
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
  if (fd < 0) {
    std::cout << text;
  } else {
    if (!write_all(fd, text) || ::fsync(fd) != 0 || ::close(fd) != 0) {
      ::unlink(tmp_path.c_str());
      return error("cannot write output '" + out_path + "': " + std::strerror(errno), 1);
    }
    if (std::rename(tmp_path.c_str(), out_path.c_str()) != 0) {
      ::unlink(tmp_path.c_str());
      return error("cannot rename to '" + out_path + "': " + std::strerror(errno), 1);
    }
  }
  if (result["status"] != "ok") {
    std::cerr << "nhi: run failed at step " << result["failure"]["step"] << ": "
              << result["failure"]["reason"].get<std::string>() << "\n";
    return 3;
  }
  return 0;
}
