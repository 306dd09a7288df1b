/* atmos_volume_load: picks the reader by the file's first bytes, then by its
 * extension. The readers live in raw_json.c, nanovdb*.c, netcdf*.c and the
 * OpenVDB shim; each names the file in its errors. */
#include "volume/volume_internal.h"
#include "volume/volume_units.h"
#include "core/internal.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

typedef enum { FMT_UNKNOWN, FMT_JSON, FMT_NANOVDB, FMT_OPENVDB, FMT_NETCDF } vol_format;

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (n < m) return 0;
    for (size_t i = 0; i < m; i++) {
        char c = path[n - m + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != ext[i]) return 0;
    }
    return 1;
}

static vol_format sniff(const unsigned char *b, size_t n)
{
    /* OpenVDB: int32 0x56444220 (" BDV" on disk, little-endian) at offset 0. */
    if (n >= 4 && b[0] == 0x20 && b[1] == 0x42 && b[2] == 0x44 && b[3] == 0x56) return FMT_OPENVDB;
    /* NanoVDB: the uint64 magic spells "NanoVDB0" (older files) or "NanoVDB1"/"NanoVDB2". */
    if (n >= 7 && !memcmp(b, "NanoVDB", 7)) return FMT_NANOVDB;
    /* NetCDF classic / 64-bit offset / CDF-5, and HDF5 (netCDF-4). */
    if (n >= 4 && !memcmp(b, "CDF", 3) && (b[3] == 1 || b[3] == 2 || b[3] == 5)) return FMT_NETCDF;
    if (n >= 8 && !memcmp(b, "\x89HDF\r\n\x1a\n", 8)) return FMT_NETCDF;
    size_t i = 0;
    if (n >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF) i = 3; /* UTF-8 BOM */
    while (i < n && (b[i] == ' ' || b[i] == '\t' || b[i] == '\r' || b[i] == '\n')) i++;
    if (i < n && b[i] == '{') return FMT_JSON;
    return FMT_UNKNOWN;
}

static const char *const format_names[] = {"", "raw", "nanovdb", "openvdb", "netcdf"};

/* A NetCDF model's values are mass mixing ratios and its lengths metres: the units of the
 * other formats do not apply to it. */
static atmos_status check_netcdf_units(atmos_context *ctx, const char *path, const atmos_volume_load_desc *d)
{
    if (d->density_unit != ATMOS_DENSITY_AUTO)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s: a NetCDF model's hydrometeors are mass mixing ratios, converted by the reader: "
                            "density unit %s does not apply (use density_scale)",
                            path, atmos__density_unit_name(d->density_unit));
    if (d->field && d->field[0])
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s: a NetCDF model's hydrometeors have their own particle types (QCLOUD cloud, QRAIN rain, "
                            "QICE ice, QSNOW snow, QGRAUP snow): particle \"%s\" does not apply (choose them with grids)",
                            path, d->field);
    if (d->length_scale != 0 && d->length_scale != 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s: a NetCDF model's lengths are metres: a length scale does not apply "
                            "(voxel_size_m sets the resampling voxel)",
                            path);
    return ATMOS_OK;
}

/* Reads the file with its reader, its values turned into particles per m^3 by the density
 * unit and its lengths into metres by voxel_size_m and length_scale. */
static atmos_status load_format(atmos_context *ctx, const char *path, vol_format fmt, const atmos_volume_load_desc *desc,
                                atmos_volume **out)
{
    atmos_volume_load_desc d = *desc;
    atmos_status st;
    if (!(d.length_scale >= 0 && d.length_scale <= 1e6) || !(d.voxel_size_m >= 0 && d.voxel_size_m <= 1e6))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: voxel size and length scale must be in [0, 1e6]", path);
    if (!(d.subgrid_detail >= 0 && d.subgrid_detail <= 1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: sub-grid detail must be in [0, 1], got %g", path,
                            d.subgrid_detail);
    if (fmt == FMT_NETCDF) {
        if ((st = check_netcdf_units(ctx, path, &d)) != ATMOS_OK) return st;
        st = atmos__volume_load_netcdf(ctx, path, &d, out);
        if (st == ATMOS_OK) atmos__volume_set_source_format(*out, format_names[fmt]);
        return st;
    }
    if (d.time_index != 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s: a time index (%d) applies to a NetCDF model's time steps only (a VDB or raw volume "
                            "holds one time): leave it out",
                            path, d.time_index);
    if (d.subgrid_detail != 0)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s: sub-grid detail applies to a NetCDF model's fields only (a VDB or raw volume has "
                            "its own detail)",
                            path);
    double factor = 1.0;
    const atmos_density_unit own = fmt == FMT_JSON ? ATMOS_DENSITY_PER_M3 : ATMOS_DENSITY_FRACTION;
    if ((st = atmos__volume_unit_factor(ctx, path, d.density_unit, own, d.field, &factor)) != ATMOS_OK) return st;
    /* The readers multiply by density_scale (0 = 1): a factor of 1 leaves their values as
     * they were, bit for bit. */
    if (factor != 1.0) d.density_scale = (d.density_scale > 0 ? d.density_scale : 1.0) * factor;
    d.voxel_size_m = 0;
    switch (fmt) {
    case FMT_JSON: st = atmos__volume_load_raw_json(ctx, path, &d, out); break;
    case FMT_NANOVDB: st = atmos__volume_load_nanovdb(ctx, path, &d, out); break;
    default: st = atmos__volume_load_openvdb(ctx, path, &d, out); break;
    }
    if (st != ATMOS_OK) return st;
    atmos__volume_set_source_format(*out, format_names[fmt]);
    double f = desc->voxel_size_m > 0 ? desc->voxel_size_m / atmos_volume_get_desc(*out)->voxel_size_m : 1.0;
    if (desc->length_scale > 0) f *= desc->length_scale;
    if (f != 1.0) {
        atmos__volume_rescale(*out, f);
        atmos__log(ctx, ATMOS_LOG_INFO, "%s: lengths scaled by %g: voxel %g m", path, f,
                   atmos_volume_get_desc(*out)->voxel_size_m);
    }
    return ATMOS_OK;
}

/* A name the comma-separated list of grids holds twice (its first character in list), or NULL. */
static const char *grid_twice(const char *list, size_t *len)
{
    for (const char *a = list; a && *a; a = strchr(a, ',') ? strchr(a, ',') + 1 : NULL) {
        const size_t n = strcspn(a, ",");
        for (const char *b = strchr(a, ','); b; b = strchr(b + 1, ','))
            if (strcspn(b + 1, ",") == n && n && !strncmp(a, b + 1, n)) return *len = n, a;
    }
    return NULL;
}

atmos_status atmos_volume_load(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                               atmos_volume **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume load: out is NULL");
    *out = NULL;
    if (!path || !*path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume load: path is empty");
    atmos_volume_load_desc zero;
    if (!desc) {
        memset(&zero, 0, sizeof zero);
        desc = &zero;
    }
    size_t twice_n = 0;
    const char *twice = grid_twice(desc->grids, &twice_n);
    if (twice)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: grids: '%.*s' is named twice", path, (int)twice_n, twice);
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISDIR(sb.st_mode))
        return atmos__error(ctx, ATMOS_E_IO, "%s: is a directory, not a volume file", path);
    FILE *f = fopen(path, "rb");
    if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char head[64];
    size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    vol_format fmt = sniff(head, n);
    if (fmt == FMT_UNKNOWN) {
        if (has_ext(path, ".json")) fmt = FMT_JSON;
        else if (has_ext(path, ".nvdb")) fmt = FMT_NANOVDB;
        else if (has_ext(path, ".vdb")) fmt = FMT_OPENVDB;
        else if (has_ext(path, ".nc") || has_ext(path, ".nc4") || has_ext(path, ".cdf")) fmt = FMT_NETCDF;
    }
    if (fmt != FMT_UNKNOWN) return load_format(ctx, path, fmt, desc, out);
    if (n == 0) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: empty file", path);
    return atmos__error(ctx, ATMOS_E_FORMAT,
                        "%s: not a recognised volume file (expected a JSON sidecar for raw float32, OpenVDB .vdb, "
                        "NanoVDB .nvdb or NetCDF .nc)",
                        path);
}
