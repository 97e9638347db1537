# Finds Debian's Python 3 and pybind11 for the module `tessera._tessera`
# (python/CMakeLists.txt). The interpreter is /usr/bin/python3 unless
# Python_EXECUTABLE says otherwise: a `python3` first on PATH (pyenv) may lack
# numpy. TESSERA_PYTHON defaults to ON when both are found.
if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python for the tessera module")
endif()
set(PYBIND11_FINDPYTHON ON)
find_package(Python COMPONENTS Interpreter Development.Module QUIET)
if(Python_FOUND)
  find_package(pybind11 2.10 CONFIG QUIET)
endif()
if(Python_FOUND AND pybind11_FOUND)
  set(tessera_python_default ON)
else()
  set(tessera_python_default OFF)
endif()
option(TESSERA_PYTHON "Build the Python module tessera._tessera (needs pybind11)"
       ${tessera_python_default})
if(TESSERA_PYTHON)
  if(NOT pybind11_FOUND)
    message(FATAL_ERROR "TESSERA_PYTHON needs pybind11 (Debian: pybind11-dev python3-dev)")
  endif()
  set(CMAKE_POSITION_INDEPENDENT_CODE ON)
  message(STATUS "Python module: ${Python_EXECUTABLE} (${Python_VERSION}), pybind11 ${pybind11_VERSION}")
endif()
