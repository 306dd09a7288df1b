file(REMOVE_RECURSE
  "CMakeFiles/atmos_static.dir/src/core/context.c.o"
  "CMakeFiles/atmos_static.dir/src/core/context.c.o.d"
  "CMakeFiles/atmos_static.dir/src/core/spectral_data.c.o"
  "CMakeFiles/atmos_static.dir/src/core/spectral_data.c.o.d"
  "CMakeFiles/atmos_static.dir/src/core/spectrum.c.o"
  "CMakeFiles/atmos_static.dir/src/core/spectrum.c.o.d"
  "CMakeFiles/atmos_static.dir/src/render/camera.c.o"
  "CMakeFiles/atmos_static.dir/src/render/camera.c.o.d"
  "CMakeFiles/atmos_static.dir/src/render/render_sky.c.o"
  "CMakeFiles/atmos_static.dir/src/render/render_sky.c.o.d"
  "CMakeFiles/atmos_static.dir/src/render/sky_batch.c.o"
  "CMakeFiles/atmos_static.dir/src/render/sky_batch.c.o.d"
  "CMakeFiles/atmos_static.dir/src/sky/sky.c.o"
  "CMakeFiles/atmos_static.dir/src/sky/sky.c.o.d"
  "CMakeFiles/atmos_static.dir/src/sky/sunpos.c.o"
  "CMakeFiles/atmos_static.dir/src/sky/sunpos.c.o.d"
  "libatmos_static.a"
  "libatmos_static.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/atmos_static.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
