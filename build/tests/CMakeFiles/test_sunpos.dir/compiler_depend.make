# Empty compiler generated dependencies file for test_sunpos.
# This may be replaced when dependencies are built.
