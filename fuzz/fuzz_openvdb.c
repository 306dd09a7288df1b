/* libFuzzer target for the OpenVDB reader (atmos__volume_load_openvdb), through the parser fence:
 * the OpenVDB library reads each input in a child process (src/volume/reader_fence.c), so a crash
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
    return fuzz_volume_file(data, size, "fuzz_openvdb", "fuzz.vdb", atmos__volume_load_openvdb);
}
