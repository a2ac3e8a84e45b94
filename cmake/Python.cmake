# The Python module's dependencies: Debian's system Python 3 (/usr/bin/python3: the interpreter that
# has pyopenvdb, and the one Blender 3.4 runs) with its headers, and Boost.Python for the same
# Python, as OpenVDB's own binding uses, so that grids cross as pyopenvdb objects.
# Sets VOLMORPH_PYTHON (ON when the module is built) and, with it, position-independent code for
# every project target: the module is a shared object that links the static libraries.
set(VOLMORPH_PYTHON OFF)
if(NOT VOLMORPH_BUILD_PYTHON)
  return()
endif()
if(NOT Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3) # not a pyenv's or a venv's earlier on the PATH
endif()
find_package(Python3 3.8 COMPONENTS Interpreter Development.Module)
if(NOT Python3_FOUND)
  message(STATUS "volmorph: no Python 3 headers (python3-dev): the Python module is not built")
  return()
endif()
set(_boost_python python${Python3_VERSION_MAJOR}${Python3_VERSION_MINOR})
find_package(Boost 1.70 CONFIG COMPONENTS ${_boost_python})
if(NOT Boost_FOUND)
  message(STATUS "volmorph: no Boost.Python for Python ${Python3_VERSION} "
                 "(libboost-python-dev): the Python module is not built")
  return()
endif()
set(VOLMORPH_BOOST_PYTHON Boost::${_boost_python})
set(VOLMORPH_PYTHON ON)
set(CMAKE_POSITION_INDEPENDENT_CODE ON)
# Position-independent code without its one cost: calls between the library's own functions stay
# direct and inlinable (nothing interposes them; the module exports only its init function).
add_compile_options(-fno-semantic-interposition)
message(STATUS "volmorph: the Python module is built for ${Python3_EXECUTABLE} (${Python3_VERSION})")
