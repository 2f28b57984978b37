// Provenance recorded in every result file.
#include <ceres/version.h>
#include <sundials/sundials_config.h>

#include <CLI/Version.hpp>
#include <Eigen/Core>
#include <ctime>

#include "nhi/runner/scene.hpp"
#include "nhi_git.hpp"  // generated at build time: NHI_GIT_REVISION, NHI_GIT_DIRTY

namespace nhi {

json meta() {
  char when[32];
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);  // not gmtime's shared buffer: Python threads run scenes at once (python/)
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return {{"git_revision", NHI_GIT_REVISION},
          {"git_dirty", NHI_GIT_DIRTY},
#ifdef __clang__
          {"compiler", std::string(__VERSION__)},  // "Debian Clang 14.0.6"
#else
          {"compiler", std::string("g++ ") + __VERSION__},
#endif
          {"build_flags", NHI_BUILD_FLAGS},
          {"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
                        std::to_string(EIGEN_MINOR_VERSION)},
          {"ceres", CERES_VERSION_STRING},
          {"sundials", SUNDIALS_VERSION},
          {"nlohmann_json", std::to_string(NLOHMANN_JSON_VERSION_MAJOR) + "." +
                                std::to_string(NLOHMANN_JSON_VERSION_MINOR) + "." +
                                std::to_string(NLOHMANN_JSON_VERSION_PATCH)},
          {"cli11", CLI11_VERSION},
          {"time_utc", when}};
}

}  // namespace nhi
