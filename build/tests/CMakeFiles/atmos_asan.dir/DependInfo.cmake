
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/src/core/context.c" "tests/CMakeFiles/atmos_asan.dir/__/src/core/context.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/core/context.c.o.d"
  "/work/main/src/core/spectral_data.c" "tests/CMakeFiles/atmos_asan.dir/__/src/core/spectral_data.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/core/spectral_data.c.o.d"
  "/work/main/src/core/spectrum.c" "tests/CMakeFiles/atmos_asan.dir/__/src/core/spectrum.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/core/spectrum.c.o.d"
  "/work/main/src/render/camera.c" "tests/CMakeFiles/atmos_asan.dir/__/src/render/camera.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/render/camera.c.o.d"
  "/work/main/src/render/render_sky.c" "tests/CMakeFiles/atmos_asan.dir/__/src/render/render_sky.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/render/render_sky.c.o.d"
  "/work/main/src/render/sky_batch.c" "tests/CMakeFiles/atmos_asan.dir/__/src/render/sky_batch.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/render/sky_batch.c.o.d"
  "/work/main/src/sky/sky.c" "tests/CMakeFiles/atmos_asan.dir/__/src/sky/sky.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/sky/sky.c.o.d"
  "/work/main/src/sky/sunpos.c" "tests/CMakeFiles/atmos_asan.dir/__/src/sky/sunpos.c.o" "gcc" "tests/CMakeFiles/atmos_asan.dir/__/src/sky/sunpos.c.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
