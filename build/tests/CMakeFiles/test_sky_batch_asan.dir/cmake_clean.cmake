file(REMOVE_RECURSE
  "CMakeFiles/test_sky_batch_asan.dir/unit/test_sky_batch.c.o"
  "CMakeFiles/test_sky_batch_asan.dir/unit/test_sky_batch.c.o.d"
  "test_sky_batch_asan"
  "test_sky_batch_asan.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_sky_batch_asan.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
