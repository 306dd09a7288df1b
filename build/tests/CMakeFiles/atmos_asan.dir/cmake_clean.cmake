file(REMOVE_RECURSE
  "CMakeFiles/atmos_asan.dir/__/src/core/context.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/core/context.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/core/spectral_data.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/core/spectral_data.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/core/spectrum.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/core/spectrum.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/render/camera.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/render/camera.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/render/render_sky.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/render/render_sky.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/render/sky_batch.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/render/sky_batch.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/sky/sky.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/sky/sky.c.o.d"
  "CMakeFiles/atmos_asan.dir/__/src/sky/sunpos.c.o"
  "CMakeFiles/atmos_asan.dir/__/src/sky/sunpos.c.o.d"
  "libatmos_asan.a"
  "libatmos_asan.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/atmos_asan.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
