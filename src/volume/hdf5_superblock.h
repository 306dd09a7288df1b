/* Where a netCDF-4 (HDF5) file ends, from its superblock.
 *
 * libhdf5 answers a truncated file with a bare "HDF error"; the superblock records the
 * address one past the last byte of the file's data (its end-of-file address), so the
 * NetCDF reader compares the file's size with it and names a cut file as truncated.
 * Internal (atmos__ prefix); needs no libhdf5.
 */
#ifndef ATMOS_VOLUME_HDF5_SUPERBLOCK_H
#define ATMOS_VOLUME_HDF5_SUPERBLOCK_H

#include <stdint.h>
#include <stdio.h>

/* Finds the HDF5 superblock of f (at byte 0, 512, 1024, 2048, ...) and sets *end to the
 * end of the file's data it records (base address + end-of-file address) and *size to the
 * file's size. Returns 0; 1 if the file ends inside the superblock (*end unset); -1 if f
 * is not an HDF5 file, or its superblock is of an unknown version or records no end. */
int atmos__hdf5_data_end(FILE *f, uint64_t *end, uint64_t *size);

#endif
