/* Where the data of a classic-format NetCDF file ends, from its header.
 *
 * libnetcdf reads classic files (CDF-1, CDF-2 = 64-bit offset, CDF-5 = 64-bit data)
 * by offset and returns zeros for bytes past the end of a truncated file instead of
 * an error, so the NetCDF reader compares the file's size with the end of its data
 * before trusting what it reads. Internal (atmos__ prefix); needs no libnetcdf.
 */
#ifndef ATMOS_VOLUME_NETCDF_CLASSIC_H
#define ATMOS_VOLUME_NETCDF_CLASSIC_H

#include <stdint.h>
#include <stdio.h>

/* Parses the header of the classic-format file f (read from its start) and sets *end
 * to the offset one past the last byte of variable data the header promises: for a
 * fixed-size variable begin + size, for a record variable the end of its part of the
 * last record (numrecs from the header; none for a streaming header). Padding after
 * the last value is not counted. *size is the file's size. Returns 0; 1 if the file
 * ends inside the header; -1 if it is not a classic file or its header is malformed. */
int atmos__netcdf_classic_data_end(FILE *f, uint64_t *end, uint64_t *size);

#endif
