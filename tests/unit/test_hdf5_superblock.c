/* The end of an HDF5 file's data from its superblock (src/volume/hdf5_superblock.c), on
 * superblocks written here by the layout of the HDF5 File Format Specification (section
 * II.A): versions 0 and 2, 4- and 8-byte offsets, a user block of 512 bytes before the
 * signature, a file cut inside the superblock, an undefined end address, not HDF5. */
#include "test.h"
#include "volume/hdf5_superblock.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

static const unsigned char SIG[8] = {0x89, 'H', 'D', 'F', 0x0D, 0x0A, 0x1A, 0x0A};

static void put_le(unsigned char *p, uint64_t v, int n)
{
    for (int i = 0; i < n; i++) p[i] = (unsigned char)(v >> (8 * i));
}

/* A file of `size` bytes: `at` bytes of user block, then the superblock sb[0..n). */
static FILE *file_with(const unsigned char *sb, size_t n, size_t at, size_t size)
{
    FILE *f = tmpfile();
    if (!f) return NULL;
    for (size_t i = 0; i < size; i++) fputc(i >= at && i < at + n ? sb[i - at] : 0, f);
    rewind(f);
    return f;
}

/* Version 2: signature, version, O, size of lengths, flags, base, extension, end, root, checksum. */
static size_t v2(unsigned char *sb, int o, uint64_t base, uint64_t eof)
{
    memset(sb, 0, 64);
    memcpy(sb, SIG, 8);
    sb[8] = 2, sb[9] = (unsigned char)o, sb[10] = (unsigned char)o;
    put_le(sb + 12, base, o);
    put_le(sb + 12 + o, o == 8 ? UINT64_MAX : 0xFFFFFFFFu, o);
    put_le(sb + 12 + 2 * o, eof, o);
    return (size_t)(12 + 4 * o + 4);
}

/* Version 0: signature, 8 version bytes and sizes (O at byte 13), group K's, flags, then the
 * base, free-space, end and driver addresses. */
static size_t v0(unsigned char *sb, int o, uint64_t eof)
{
    memset(sb, 0, 64);
    memcpy(sb, SIG, 8);
    sb[13] = (unsigned char)o, sb[14] = (unsigned char)o;
    put_le(sb + 24 + o, o == 8 ? UINT64_MAX : 0xFFFFFFFFu, o);
    put_le(sb + 24 + 2 * o, eof, o);
    return (size_t)(24 + 4 * o);
}

static int run(FILE *f, uint64_t *end, uint64_t *size)
{
    if (!f) return -2;
    int rc = atmos__hdf5_data_end(f, end, size);
    fclose(f);
    return rc;
}

int main(void)
{
    unsigned char sb[64];
    uint64_t end = 0, size = 0;
    size_t n = v2(sb, 8, 0, 4096);
    CHECK(run(file_with(sb, n, 0, 100), &end, &size) == 0 && end == 4096 && size == 100);
    CHECK(run(file_with(sb, n, 0, 4096), &end, &size) == 0 && end == 4096 && size == 4096);
    n = v2(sb, 4, 512, 1000); /* a user block (base 512): the end counts the user block, as */
    CHECK(run(file_with(sb, n, 512, 700), &end, &size) == 0 && end == 1000 && size == 700); /* libhdf5 */
    n = v2(sb, 4, 0, 1000); /* found at 512 with base 0 (the file moved by 512): the end moves too */
    CHECK(run(file_with(sb, n, 512, 700), &end, &size) == 0 && end == 1512 && size == 700);
    n = v0(sb, 8, 3000);
    CHECK(run(file_with(sb, n, 0, 200), &end, &size) == 0 && end == 3000);
    n = v0(sb, 4, 3000);
    CHECK(run(file_with(sb, n, 0, 200), &end, &size) == 0 && end == 3000);
    n = v2(sb, 8, 0, 4096); /* cut inside the superblock */
    CHECK(run(file_with(sb, n, 0, 20), &end, &size) == 1 && size == 20);
    n = v2(sb, 8, 0, UINT64_MAX); /* an undefined end address: nothing to compare */
    CHECK(run(file_with(sb, n, 0, 100), &end, &size) == -1);
    sb[8] = 7; /* an unknown version */
    CHECK(run(file_with(sb, n, 0, 100), &end, &size) == -1);
    memset(sb, 'C', sizeof sb); /* not HDF5, and an empty file */
    CHECK(run(file_with(sb, sizeof sb, 0, 2000), &end, &size) == -1 && size == 2000);
    CHECK(run(file_with(sb, 0, 0, 0), &end, &size) == -1 && size == 0);
    return test_summary("hdf5_superblock");
}
