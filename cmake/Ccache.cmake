# Use ccache for C++ compiles when it is installed (a 2-core machine rebuilds OpenVDB-heavy
# translation units often; ccache turns most of those into cache hits).
find_program(VOLMORPH_CCACHE ccache)
if(VOLMORPH_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_CXX_COMPILER_LAUNCHER "${VOLMORPH_CCACHE}")
  message(STATUS "volmorph: compiling through ${VOLMORPH_CCACHE}")
endif()
