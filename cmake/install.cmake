# `cmake --install BUILD --prefix PREFIX` puts the package in PREFIX:
#   include/nhi/...                  the headers (lib/nhi)
#   lib/libnhi.a                     the compiled library (every stepper of every
#                                    registered system, the scene runner)
#   lib/cmake/nhi/                   nhiConfig.cmake, its version file and the
#                                    exported targets nhi::nhi, nhi::nhi_core
#   bin/nhi                          the runner
#   lib/python3.X/dist-packages/     the Python module, when built (NHI_PYTHON)
# A user's project: find_package(nhi CONFIG REQUIRED), then link nhi::nhi
# (README "Use it from your code"; examples/ is such a project).
include(CMakePackageConfigHelpers)
set(NHI_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/nhi)

install(DIRECTORY ${CMAKE_SOURCE_DIR}/lib/nhi DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
install(TARGETS nhi nhi_core EXPORT nhiTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS nhi_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(EXPORT nhiTargets NAMESPACE nhi:: DESTINATION ${NHI_CMAKE_DIR})

configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/nhiConfig.cmake.in ${CMAKE_BINARY_DIR}/nhiConfig.cmake
                              INSTALL_DESTINATION ${NHI_CMAKE_DIR})
# No stability promise across minor versions yet: a 0.x package matches its own minor version.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/nhiConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/nhiConfig.cmake ${CMAKE_BINARY_DIR}/nhiConfigVersion.cmake
        DESTINATION ${NHI_CMAKE_DIR})

if(NHI_PYTHON)
  set(NHI_PYTHON_INSTALL_DIR
      ${CMAKE_INSTALL_LIBDIR}/python${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}/dist-packages
      CACHE STRING "Where cmake --install puts the Python module, relative to the prefix")
  install(TARGETS nhi_python LIBRARY DESTINATION ${NHI_PYTHON_INSTALL_DIR})
endif()
