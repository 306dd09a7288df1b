# Empty dependencies file for atmos_static.
# This may be replaced when dependencies are built.
