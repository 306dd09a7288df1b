# The Python package (python/atmos, docs/python.md): its native module is cffi's C source for
# the declarations in python/atmos/_build_ffi.py, compiled against the library in this build
# and placed in python/atmos/ so that `PYTHONPATH=python python3 -c 'import atmos'` works from
# the checkout. Needs a Python 3 with cffi, NumPy and its C headers (Debian: python3-cffi,
# python3-numpy, python3-dev; scripts/install-deps.sh installs them). The system's python3 is
# preferred to another one first on PATH.
set(ATMOS_PYTHON "" CACHE FILEPATH "Python 3 with cffi and NumPy for the bindings (empty: found)")
set(ATMOS_HAVE_PYTHON OFF)
if(NOT ATMOS_PYTHON)
  find_program(ATMOS_SYSTEM_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH)
  find_program(ATMOS_PATH_PYTHON python3)
  set(_candidates ${ATMOS_SYSTEM_PYTHON} ${ATMOS_PATH_PYTHON})
else()
  set(_candidates ${ATMOS_PYTHON})
endif()
foreach(_py ${_candidates})
  execute_process(COMMAND ${_py} -c "import cffi, numpy, sysconfig; print(sysconfig.get_paths()['include'] + ';' + sysconfig.get_config_var('EXT_SUFFIX'))"
                  RESULT_VARIABLE _rc OUTPUT_VARIABLE _out OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(_rc EQUAL 0)
    list(GET _out 0 _inc)
    list(GET _out 1 _suffix)
    if(EXISTS ${_inc}/Python.h)
      set(ATMOS_HAVE_PYTHON ON)
      set(ATMOS_PYTHON_EXE ${_py})
      break()
    endif()
  endif()
endforeach()
if(NOT ATMOS_HAVE_PYTHON)
  message(STATUS "atmos: Python bindings: NO -- install python3-cffi python3-numpy python3-dev")
  return()
endif()
message(STATUS "atmos: Python bindings: yes (${ATMOS_PYTHON_EXE}, ${_suffix})")
message(STATUS "atmos: the Python package is built for ${ATMOS_PYTHON_EXE}: run it with that interpreter "
               "(PYTHONPATH=python ${ATMOS_PYTHON_EXE} ...); -DATMOS_PYTHON=PATH picks another")
if(ATMOS_PATH_PYTHON AND NOT ATMOS_PATH_PYTHON STREQUAL ATMOS_PYTHON_EXE)
  message(STATUS "atmos: note: the python3 first on PATH is ${ATMOS_PATH_PYTHON}, not ${ATMOS_PYTHON_EXE}")
endif()
# The interpreter the build is for, named by the package's ImportError in another one.
file(WRITE ${CMAKE_SOURCE_DIR}/python/atmos/_build_info.py
     "# Written by cmake/python.cmake: the interpreter the native module was built for.\n"
     "PYTHON = \"${ATMOS_PYTHON_EXE}\"\n")

set(_gen ${CMAKE_BINARY_DIR}/python/_native.c)
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/python)
add_custom_command(OUTPUT ${_gen}
                   COMMAND ${ATMOS_PYTHON_EXE} ${CMAKE_SOURCE_DIR}/python/atmos/_build_ffi.py ${_gen} > /dev/null
                   DEPENDS ${CMAKE_SOURCE_DIR}/python/atmos/_build_ffi.py
                   COMMENT "Python: the native module's C source (cffi)")
add_library(atmos_python MODULE ${_gen})
target_include_directories(atmos_python SYSTEM PRIVATE ${_inc})
target_link_libraries(atmos_python PRIVATE atmos_shared)
set_target_properties(atmos_python PROPERTIES PREFIX "" OUTPUT_NAME _native SUFFIX ${_suffix}
                      LIBRARY_OUTPUT_DIRECTORY ${CMAKE_SOURCE_DIR}/python/atmos
                      BUILD_RPATH $<TARGET_FILE_DIR:atmos_shared>)
