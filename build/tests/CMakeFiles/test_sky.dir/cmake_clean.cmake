file(REMOVE_RECURSE
  "CMakeFiles/test_sky.dir/unit/test_sky.c.o"
  "CMakeFiles/test_sky.dir/unit/test_sky.c.o.d"
  "test_sky"
  "test_sky.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_sky.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
