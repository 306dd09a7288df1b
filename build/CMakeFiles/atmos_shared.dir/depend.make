# Empty dependencies file for atmos_shared.
# This may be replaced when dependencies are built.
