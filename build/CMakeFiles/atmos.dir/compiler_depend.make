# Empty compiler generated dependencies file for atmos.
# This may be replaced when dependencies are built.
