/* The end of an HDF5 file's data, from its superblock (see hdf5_superblock.h).
 *
 * Layout (HDF5 File Format Specification, section II.A "Disk Format: Level 0A - Format
 * Signature and Superblock"; little-endian; O = size of offsets):
 *   signature 89 'H' 'D' 'F' 0D 0A 1A 0A, at byte 0 or at 512, 1024, 2048, ... (user block)
 *   version 0 or 1: version, free-space version, root group version, reserved, shared
 *     header version, O (byte 13), size of lengths, reserved, group K (2+2 bytes), flags
 *     (4 bytes), version 1 only: indexed storage K (2) and reserved (2); then the base
 *     address, the free-space address and the end-of-file address, O bytes each;
 *   version 2 or 3: version, O (byte 9), size of lengths, flags; then the base address,
 *     the superblock extension address and the end-of-file address, O bytes each.
 * The end-of-file address is the file's size as the library that wrote it left it, user block
 * included (libhdf5 compares it with the size on disk, not with the size past the base address);
 * where a superblock was found elsewhere than its base address says, by that shift. All ones is
 * "undefined".
 */
#define _POSIX_C_SOURCE 200809L /* fseeko, ftello */
#include "volume/hdf5_superblock.h"

#include <string.h>
#include <sys/types.h>

static const unsigned char signature[8] = {0x89, 'H', 'D', 'F', 0x0D, 0x0A, 0x1A, 0x0A};

static uint64_t le(const unsigned char *p, int n)
{
    uint64_t v = 0;
    for (int i = n - 1; i >= 0; i--) v = v << 8 | p[i];
    return v;
}

/* The superblock's bytes at offset at: 1 if the signature is there (up to sizeof sb read,
 * *got of them), 0 if not. */
static int read_at(FILE *f, uint64_t at, unsigned char *sb, size_t cap, size_t *got)
{
    if (fseeko(f, (off_t)at, SEEK_SET) != 0) return 0;
    *got = fread(sb, 1, cap, f);
    return *got >= sizeof signature && memcmp(sb, signature, sizeof signature) == 0;
}

int atmos__hdf5_data_end(FILE *f, uint64_t *end, uint64_t *size)
{
    if (fseeko(f, 0, SEEK_END) != 0) return -1;
    off_t sz = ftello(f);
    if (sz < 0) return -1;
    *size = (uint64_t)sz;
    unsigned char sb[64];
    size_t got = 0;
    uint64_t at = 0;
    while (!read_at(f, at, sb, sizeof sb, &got)) {
        at = at ? at * 2 : 512;
        if (at + sizeof signature > *size) return -1;
    }
    if (got < 10) return 1;
    int version = sb[8];
    size_t base_pos, o;
    if (version == 0 || version == 1) {
        if (got < 14) return 1;
        o = sb[13];
        base_pos = version == 0 ? 24 : 28;
    } else if (version == 2 || version == 3) {
        o = sb[9];
        base_pos = 12;
    } else {
        return -1;
    }
    if (o != 2 && o != 4 && o != 8) return -1;
    if (got < base_pos + 3 * o) return 1;
    uint64_t undefined = o == 8 ? UINT64_MAX : ((uint64_t)1 << (8 * o)) - 1;
    uint64_t base = le(sb + base_pos, (int)o), eof = le(sb + base_pos + 2 * o, (int)o);
    if (eof == undefined || base == undefined) return -1;
    uint64_t shift = at > base ? at - base : 0;
    *end = eof + shift < eof ? UINT64_MAX : eof + shift;
    return 0;
}
