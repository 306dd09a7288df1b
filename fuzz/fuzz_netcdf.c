/* libFuzzer target for the NetCDF reader (atmos__volume_load_netcdf), through the parser fence:
 * libnetcdf and libhdf5 read each input in a child process (src/volume/reader_fence.c), so a crash
 * there is reported as an error, not found by the fuzzer; what is fuzzed is atmos's own part
 * (the header checks, the fence, the volume rebuilt from the child's bricks).
 *
 * The checks and the temporary file: fuzz_volume_file.h. Build with -DATMOS_FUZZ=ON (clang), or
 * replay with replay.c.
 */
#include "fuzz_volume_file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return fuzz_volume_file(data, size, "fuzz_netcdf", "fuzz.nc", atmos__volume_load_netcdf);
}
