# Empty compiler generated dependencies file for atmos_asan.
# This may be replaced when dependencies are built.
