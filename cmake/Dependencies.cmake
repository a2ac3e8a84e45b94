# Dependency discovery for Debian 12's packages. Every Debian-specific workaround lives here.
# tools/install-deps.sh installs the packages this file looks for.

# TBB's own config must come before OpenVDB's FindTBB, or the two define the same targets.
find_package(TBB CONFIG REQUIRED)

# Debian ships FindOpenVDB.cmake but no OpenVDBConfig.cmake.
list(APPEND CMAKE_MODULE_PATH "/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB")
find_package(OpenVDB REQUIRED)

find_package(embree 3.13 REQUIRED)
find_package(OpenImageIO CONFIG REQUIRED)
find_package(assimp CONFIG REQUIRED)
find_package(tomlplusplus CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)

# OpenImageIO's exported target lists /usr/include/opencv4, which exists only when libopencv-dev
# is installed; CMake refuses to generate with a missing include directory. volmorph does not use
# OIIO's OpenCV interop, so drop that path.
foreach(_prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
  get_target_property(_dirs OpenImageIO::OpenImageIO ${_prop})
  if(_dirs)
    list(FILTER _dirs EXCLUDE REGEX "opencv4")
    set_target_properties(OpenImageIO::OpenImageIO PROPERTIES ${_prop} "${_dirs}")
  endif()
endforeach()

if(VOLMORPH_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(VOLMORPH_BUILD_BENCHMARKS)
  find_package(benchmark CONFIG REQUIRED)
endif()
