
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/src/core/context.c" "CMakeFiles/atmos_static.dir/src/core/context.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/core/context.c.o.d"
  "/work/main/src/core/spectral_data.c" "CMakeFiles/atmos_static.dir/src/core/spectral_data.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/core/spectral_data.c.o.d"
  "/work/main/src/core/spectrum.c" "CMakeFiles/atmos_static.dir/src/core/spectrum.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/core/spectrum.c.o.d"
  "/work/main/src/render/camera.c" "CMakeFiles/atmos_static.dir/src/render/camera.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/render/camera.c.o.d"
  "/work/main/src/render/render_sky.c" "CMakeFiles/atmos_static.dir/src/render/render_sky.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/render/render_sky.c.o.d"
  "/work/main/src/render/sky_batch.c" "CMakeFiles/atmos_static.dir/src/render/sky_batch.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/render/sky_batch.c.o.d"
  "/work/main/src/sky/sky.c" "CMakeFiles/atmos_static.dir/src/sky/sky.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/sky/sky.c.o.d"
  "/work/main/src/sky/sunpos.c" "CMakeFiles/atmos_static.dir/src/sky/sunpos.c.o" "gcc" "CMakeFiles/atmos_static.dir/src/sky/sunpos.c.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
