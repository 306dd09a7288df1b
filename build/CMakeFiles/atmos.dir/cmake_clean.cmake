file(REMOVE_RECURSE
  "CMakeFiles/atmos.dir/tools/atmos/cli.c.o"
  "CMakeFiles/atmos.dir/tools/atmos/cli.c.o.d"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_bench.c.o"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_bench.c.o.d"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_render.c.o"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_render.c.o.d"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_sky.c.o"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_sky.c.o.d"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_sun.c.o"
  "CMakeFiles/atmos.dir/tools/atmos/cmd_sun.c.o.d"
  "CMakeFiles/atmos.dir/tools/atmos/main.c.o"
  "CMakeFiles/atmos.dir/tools/atmos/main.c.o.d"
  "atmos"
  "atmos.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/atmos.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
