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
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
# OpenMesh (BSD): half-edge meshes and their decimater, for the spherical parameterization.
find_package(OpenMesh CONFIG REQUIRED)
# The editor (volmorph edit): its JSON API and its local HTTP server. Debian's cpp-httplib is the
# split build (a header and libcpp-httplib.so, built with OpenSSL, zlib and Brotli); it has a
# pkg-config file and no CMake config.
find_package(nlohmann_json 3.10 CONFIG REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)

# libnifti2 (NIfTI volumes). Debian 12's NIFTIConfig.cmake points at /usr/lib/libnifti2.so.2.1.0,
# which the package installs under /usr/lib/<arch>/: find the library and headers directly.
find_path(NIFTI_INCLUDE_DIR nifti2_io.h PATH_SUFFIXES nifti REQUIRED)
find_library(NIFTI2_LIBRARY nifti2 REQUIRED)
find_library(ZNZ_LIBRARY znz REQUIRED)
find_package(ZLIB REQUIRED)
add_library(volmorph_nifti INTERFACE)
target_include_directories(volmorph_nifti SYSTEM INTERFACE ${NIFTI_INCLUDE_DIR})
target_link_libraries(volmorph_nifti INTERFACE ${NIFTI2_LIBRARY} ${ZNZ_LIBRARY} ZLIB::ZLIB m)

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
