
# Consider dependencies only in project.
set(CMAKE_DEPENDS_IN_PROJECT_ONLY OFF)

# The set of languages for which implicit dependencies are needed:
set(CMAKE_DEPENDS_LANGUAGES
  )

# The set of dependency files which are needed:
set(CMAKE_DEPENDS_DEPENDENCY_FILES
  "/work/main/tools/atmos/cli.c" "CMakeFiles/atmos.dir/tools/atmos/cli.c.o" "gcc" "CMakeFiles/atmos.dir/tools/atmos/cli.c.o.d"
  "/work/main/tools/atmos/cmd_bench.c" "CMakeFiles/atmos.dir/tools/atmos/cmd_bench.c.o" "gcc" "CMakeFiles/atmos.dir/tools/atmos/cmd_bench.c.o.d"
  "/work/main/tools/atmos/cmd_render.c" "CMakeFiles/atmos.dir/tools/atmos/cmd_render.c.o" "gcc" "CMakeFiles/atmos.dir/tools/atmos/cmd_render.c.o.d"
  "/work/main/tools/atmos/cmd_sky.c" "CMakeFiles/atmos.dir/tools/atmos/cmd_sky.c.o" "gcc" "CMakeFiles/atmos.dir/tools/atmos/cmd_sky.c.o.d"
  "/work/main/tools/atmos/cmd_sun.c" "CMakeFiles/atmos.dir/tools/atmos/cmd_sun.c.o" "gcc" "CMakeFiles/atmos.dir/tools/atmos/cmd_sun.c.o.d"
  "/work/main/tools/atmos/main.c" "CMakeFiles/atmos.dir/tools/atmos/main.c.o" "gcc" "CMakeFiles/atmos.dir/tools/atmos/main.c.o.d"
  )

# Targets to which this target links.
set(CMAKE_TARGET_LINKED_INFO_FILES
  "/work/main/build/CMakeFiles/atmos_static.dir/DependInfo.cmake"
  )

# Fortran module output directory.
set(CMAKE_Fortran_TARGET_MODULE_DIR "")
