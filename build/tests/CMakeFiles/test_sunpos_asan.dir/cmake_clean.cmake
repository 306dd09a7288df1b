file(REMOVE_RECURSE
  "CMakeFiles/test_sunpos_asan.dir/unit/test_sunpos.c.o"
  "CMakeFiles/test_sunpos_asan.dir/unit/test_sunpos.c.o.d"
  "test_sunpos_asan"
  "test_sunpos_asan.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_sunpos_asan.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
