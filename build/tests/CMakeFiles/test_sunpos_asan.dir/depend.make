# Empty dependencies file for test_sunpos_asan.
# This may be replaced when dependencies are built.
