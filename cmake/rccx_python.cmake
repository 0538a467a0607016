# Whether the Python module rccx (python/) is built: RCCX_PYTHON is AUTO (the default: built when
# pybind11 and a python3 with NumPy are found, with the reason said when not), ON (missing pieces
# are an error) or OFF. Sets RCCX_WITH_PYTHON and, when false, RCCX_PYTHON_REASON; when true,
# Python3_EXECUTABLE is the interpreter the module is built for and its tests run with.
set(RCCX_PYTHON AUTO CACHE STRING
    "Build the Python module rccx (python/): AUTO (when pybind11 and python3 with NumPy are found), ON or OFF")
set_property(CACHE RCCX_PYTHON PROPERTY STRINGS AUTO ON OFF)

set(RCCX_WITH_PYTHON FALSE)
set(RCCX_PYTHON_REASON "")
if(NOT RCCX_PYTHON)
  set(RCCX_PYTHON_REASON "RCCX_PYTHON is OFF")
elseif(RCCX_PYTHON STREQUAL "AUTO" AND (RCCX_FUZZ OR RCCX_TSAN))
  # The module would need the sanitizer's runtime preloaded into python3; these trees build
  # their own targets only.
  set(RCCX_PYTHON_REASON "off in RCCX_FUZZ and RCCX_TSAN builds (give -DRCCX_PYTHON=ON to build it)")
else()
  # The interpreter: the one given, else the first python3 that imports NumPy, the PATH's then
  # Debian's (a python3 from pyenv or a venv first on PATH does not see python3-numpy).
  if(NOT Python3_EXECUTABLE)
    find_program(rccx_path_python3 NAMES python3 NO_CACHE)
    foreach(candidate IN ITEMS "${rccx_path_python3}" /usr/bin/python3)
      if(candidate AND EXISTS "${candidate}")
        execute_process(COMMAND "${candidate}" -c "import numpy" RESULT_VARIABLE rc
                        OUTPUT_QUIET ERROR_QUIET)
        if(rc EQUAL 0)
          set(Python3_EXECUTABLE "${candidate}" CACHE FILEPATH "The python3 of the module rccx")
          break()
        endif()
      endif()
    endforeach()
  endif()
  if(NOT Python3_EXECUTABLE)
    set(RCCX_PYTHON_REASON "no python3 with NumPy found (apt-get install python3-numpy, or give -DPython3_EXECUTABLE=...)")
  else()
    find_package(Python3 3.9 COMPONENTS Interpreter Development.Module)
    if(NOT Python3_Development.Module_FOUND)
      set(RCCX_PYTHON_REASON "Python.h of ${Python3_EXECUTABLE} not found (apt-get install python3-dev)")
    else()
      find_package(pybind11 2.6 CONFIG QUIET)
      if(NOT pybind11_FOUND)
        set(RCCX_PYTHON_REASON "pybind11 not found (apt-get install pybind11-dev python3-pybind11)")
      else()
        set(RCCX_WITH_PYTHON TRUE)
      endif()
    endif()
  endif()
endif()

if(RCCX_WITH_PYTHON)
  message(STATUS "Python module rccx: built for ${Python3_EXECUTABLE} (${Python3_VERSION}), pybind11 ${pybind11_VERSION}")
elseif(RCCX_PYTHON STREQUAL "ON")
  message(FATAL_ERROR "RCCX_PYTHON is ON but the Python module cannot be built: ${RCCX_PYTHON_REASON}; "
                      "scripts/install-deps installs what it needs")
elseif(NOT RCCX_PYTHON)
  message(STATUS "Python module rccx NOT built: ${RCCX_PYTHON_REASON}")
else()
  message(STATUS "Python module rccx NOT built: ${RCCX_PYTHON_REASON}; scripts/install-deps installs what it needs")
endif()
