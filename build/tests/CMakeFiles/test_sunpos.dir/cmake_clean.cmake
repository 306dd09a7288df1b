file(REMOVE_RECURSE
  "CMakeFiles/test_sunpos.dir/unit/test_sunpos.c.o"
  "CMakeFiles/test_sunpos.dir/unit/test_sunpos.c.o.d"
  "test_sunpos"
  "test_sunpos.pdb"
)

# Per-language clean rules from dependency scanning.
foreach(lang C)
  include(CMakeFiles/test_sunpos.dir/cmake_clean_${lang}.cmake OPTIONAL)
endforeach()
