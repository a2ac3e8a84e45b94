# Use ccache for C++ compiles when it is installed (a 2-core machine rebuilds OpenVDB-heavy
# translation units often; ccache turns most of those into cache hits).
#
# CCACHE_BASEDIR makes the paths under the source tree relative before hashing, and CCACHE_NOHASHDIR
# leaves the build folder out of the hash of -g compiles (the sanitizer build's), so that a fresh clone
# at another path (CI's) hits the objects an earlier build of the same sources left. ccache 4.7
# (Debian 12) takes its settings from the environment only, hence `cmake -E env`.
find_program(VOLMORPH_CCACHE ccache)
if(VOLMORPH_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_CXX_COMPILER_LAUNCHER
      "${CMAKE_COMMAND}" -E env "CCACHE_BASEDIR=${PROJECT_SOURCE_DIR}" CCACHE_NOHASHDIR=1
      "${VOLMORPH_CCACHE}")
  set(CMAKE_C_COMPILER_LAUNCHER ${CMAKE_CXX_COMPILER_LAUNCHER})
  message(STATUS "volmorph: compiling through ${VOLMORPH_CCACHE} (base dir ${PROJECT_SOURCE_DIR})")
endif()
