CMakeFiles/atmos_static.dir/src/core/spectral_data.c.o: \
 /work/main/src/core/spectral_data.c /usr/include/stdc-predef.h \
 /work/main/src/core/spectral_data.h
