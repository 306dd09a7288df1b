# Empty compiler generated dependencies file for test_sky_batch.
# This may be replaced when dependencies are built.
