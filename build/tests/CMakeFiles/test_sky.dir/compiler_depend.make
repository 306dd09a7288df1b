# Empty compiler generated dependencies file for test_sky.
# This may be replaced when dependencies are built.
