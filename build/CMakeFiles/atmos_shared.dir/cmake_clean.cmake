file(REMOVE_RECURSE
  "CMakeFiles/atmos_shared.dir/src/core/context.c.o"
  "CMakeFiles/atmos_shared.dir/src/core/context.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/core/spectral_data.c.o"
  "CMakeFiles/atmos_shared.dir/src/core/spectral_data.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/core/spectrum.c.o"
  "CMakeFiles/atmos_shared.dir/src/core/spectrum.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/render/camera.c.o"
  "CMakeFiles/atmos_shared.dir/src/render/camera.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/render/render_sky.c.o"
  "CMakeFiles/atmos_shared.dir/src/render/render_sky.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/render/sky_batch.c.o"
  "CMakeFiles/atmos_shared.dir/src/render/sky_batch.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/sky/sky.c.o"
  "CMakeFiles/atmos_shared.dir/src/sky/sky.c.o.d"
  "CMakeFiles/atmos_shared.dir/src/sky/sunpos.c.o"
  "CMakeFiles/atmos_shared.dir/src/sky/sunpos.c.o.d"
  "libatmos.pdb"
  "libatmos.so"
  "libatmos.so.0"
  "libatmos.so.0.1.0"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/atmos_shared.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
