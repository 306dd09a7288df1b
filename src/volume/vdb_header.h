/* What an OpenVDB file's own header lets us check before the OpenVDB library reads it.
 *
 * OpenVDB trusts the lengths and offsets in its files: a truncated file loads as an empty or
 * partial grid, and a damaged length can make it allocate without bound. vdb_header.c parses
 * the file header, the file-level metadata and the grid descriptors itself (no library) and
 * checks every length and offset against the file's size. Internal (atmos__ prefix).
 */
#ifndef ATMOS_VOLUME_VDB_HEADER_H
#define ATMOS_VOLUME_VDB_HEADER_H

#include <stddef.h>
#include <stdint.h>

/* Checks the OpenVDB file at path: the header (magic, file version 213..224), the file
 * metadata (every entry's name, type and value within the file), and, when the file has grid
 * offsets, each grid descriptor: its name and type strings, and grid start <= data start <=
 * end <= file size, each descriptor following the previous grid's end. Returns 0 when all
 * holds, -1 with a reason in why (cap bytes; "truncated: ..." when the file ends before what
 * its header promises) otherwise. *ngrids receives the number of grid descriptors (0 when the
 * file has no grid offsets). */
int atmos__vdb_check_header(const char *path, int *ngrids, char *why, size_t cap);

/* The same over a memory buffer (tests, fuzzing). */
int atmos__vdb_check_header_mem(const unsigned char *data, uint64_t size, int *ngrids, char *why, size_t cap);

#endif
