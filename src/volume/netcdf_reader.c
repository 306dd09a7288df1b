/* NetCDF reader for cloud-model output: WRF (ARW) and CM1 (docs/volumes-readers.md).
 *
 * Both models store hydrometeors as mass mixing ratios q (kg per kg of dry air) on a
 * grid whose vertical levels are not uniform (WRF: terrain-following eta levels
 * whose heights come from the geopotential; CM1: stretched heights zh). The reader
 *  1. reads one time step of a sub-region (desc->time_index, desc->region),
 *  2. computes the dry-air density rho at every mass point,
 *  3. converts q to a number density eta = q rho / m_p, m_p the mean mass of one
 *     particle of that hydrometeor (table below; desc->density_scale replaces the
 *     conversion by eta = q * density_scale),
 *  4. resamples onto atmos's uniform cubic voxels: bilinear between model columns,
 *     linear in height within each column; voxels below the terrain or above the
 *     model top are empty.
 * World frame (atmos.h): x east, y up (metres above sea level for WRF, above the
 * ground for CM1), z south; x and z start at the sub-region's south-west... more
 * precisely its west and north edges, since z grows southward.
 */
#include "core/internal.h"
#include "volume/generator.h"
#include "volume/hdf5_superblock.h"
#include "volume/netcdf_classic.h"
#include "volume/reader_common.h"
#include "volume/reader_fence.h"
#include "volume/volume_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef ATMOS_HAVE_NETCDF

atmos_status atmos__volume_load_netcdf(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                       atmos_volume **out)
{
    (void)desc;
    if (out) *out = NULL;
    return atmos__error(ctx, ATMOS_E_UNSUPPORTED,
                        "%s: this build of atmos cannot read NetCDF files: install libnetcdf-dev and reconfigure", path);
}

#else

#include <netcdf.h>

/* Physical constants as WRF defines them (share/module_model_constants.F):
 * r_d = 287, cp = 7 r_d / 2, p1000mb = 1e5 Pa, g = 9.81 m/s^2. */
#define RD 287.0
#define CP (3.5 * RD)
#define P0 1.0e5
#define GRAV 9.81
#define RHO_WATER 1000.0
#define RHO_ICE 917.0
#define RHO_GRAUPEL 500.0

/* Mean mass of one particle (kg) per hydrometeor: the assumption that turns a
 * mass mixing ratio into a number density (sources in docs/volumes-readers.md). */
static double sphere_mass(double radius_m, double rho) { return 4.0 / 3.0 * ATMOS_PI * pow(radius_m, 3) * rho; }

typedef struct {
    const char *wrf, *cm1; /* variable names */
    const char *field;     /* atmos field name */
    const char *particle;  /* optics preset */
} hydrometeor;

static const hydrometeor hydro[] = {
    {"QCLOUD", "qc", "cloud", "cloud"},
    {"QRAIN", "qr", "rain", "rain"},
    {"QICE", "qi", "ice", "ice"},
    {"QSNOW", "qs", "snow", "snow"},
    /* No graupel preset: rimed, irregular, millimetre-sized ice scatters most like
     * the snow preset's roughened crystals. */
    {"QGRAUP", "qg", "graupel", "snow"},
};
#define NHYDRO ((int)(sizeof hydro / sizeof hydro[0]))

static double particle_mass(int h)
{
    switch (h) {
    case 0: return sphere_mass(10e-6, RHO_WATER);  /* cloud droplet, r = 10 um */
    case 1: return sphere_mass(1e-3, RHO_WATER);   /* raindrop, r = 1 mm */
    case 2: return sphere_mass(50e-6, RHO_ICE);    /* cloud ice, equivalent sphere r = 50 um */
    case 3: return 0.069 * 2e-3 * 2e-3;            /* snow: m = 0.069 D^2 (Thompson et al. 2008), D = 2 mm */
    default: return sphere_mass(1e-3, RHO_GRAUPEL); /* graupel, r = 1 mm, 500 kg/m^3 */
    }
}

/* ------------------------------------------------------------ helpers */

typedef struct {
    atmos_context *ctx;
    const char *path;
    int nc;
    int wrf; /* else CM1 */
    /* source sub-region (mass points): x fastest, then y (south->north), then level */
    int t, i0, j0, k0, nx, ny, nz;
    size_t dim_len[3]; /* full extents: x, y, z (mass levels) */
} src;

static atmos_status nc_fail(const src *s, int rc, const char *what)
{
    return atmos__error(s->ctx, rc == NC_ENOMEM ? ATMOS_E_NOMEM : ATMOS_E_FORMAT, "%s: %s: %s", s->path, what,
                        nc_strerror(rc));
}

static int has_var(const src *s, const char *name)
{
    int id;
    return nc_inq_varid(s->nc, name, &id) == NC_NOERR;
}

/* "QCLOUD, QRAIN, T, ..." for messages listing what the file has. */
static void list_vars(const src *s, char *buf, size_t cap)
{
    int n = 0;
    size_t len = 0;
    buf[0] = '\0';
    if (nc_inq_nvars(s->nc, &n) != NC_NOERR) return;
    for (int v = 0; v < n && len + 1 < cap; v++) {
        char name[NC_MAX_NAME + 1];
        if (nc_inq_varname(s->nc, v, name) != NC_NOERR) continue;
        int w = snprintf(buf + len, cap - len, "%s%s", len ? ", " : "", name);
        if (w < 0) break;
        len += (size_t)w;
    }
    if (len + 1 >= cap && cap > 4) strcpy(buf + cap - 4, "...");
}

/* Reads variable `name` (time, level, y, x) at the source time step and region into
 * dst (nx * ny * nz_read floats, x fastest); stag = 1 reads one more level (the
 * staggered bottom_top_stag dimension). Checks the shape and NaN/Inf. */
static atmos_status read_var(const src *s, const char *name, int stag, float *dst)
{
    int id, nd, dims[NC_MAX_VAR_DIMS];
    nc_type type;
    int rc = nc_inq_varid(s->nc, name, &id);
    if (rc != NC_NOERR) return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: variable %s not found", s->path, name);
    if ((rc = nc_inq_var(s->nc, id, NULL, &type, &nd, dims, NULL)) != NC_NOERR) return nc_fail(s, rc, name);
    if (nd != 4)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: variable %s has %d dimensions, expected 4 (time, z, y, x)",
                            s->path, name, nd);
    if (type != NC_FLOAT && type != NC_DOUBLE)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: variable %s is not floating point", s->path, name);
    size_t len[4];
    for (int d = 0; d < 4; d++)
        if ((rc = nc_inq_dimlen(s->nc, dims[d], &len[d])) != NC_NOERR) return nc_fail(s, rc, name);
    const size_t want_z = s->dim_len[2] + (size_t)stag;
    if (len[1] != want_z || len[2] != s->dim_len[1] || len[3] != s->dim_len[0])
        return atmos__error(s->ctx, ATMOS_E_FORMAT,
                            "%s: variable %s has shape (%zu, %zu, %zu), expected (%zu, %zu, %zu)%s", s->path, name,
                            len[1], len[2], len[3], want_z, s->dim_len[1], s->dim_len[0],
                            stag ? " (staggered in z)" : "");
    if ((size_t)s->t >= len[0])
        return atmos__error(s->ctx, ATMOS_E_INVALID_ARG, "%s: time index %d out of range: the file has %zu times",
                            s->path, s->t, len[0]);
    const size_t start[4] = {(size_t)s->t, (size_t)s->k0, (size_t)s->j0, (size_t)s->i0};
    const size_t count[4] = {1, (size_t)(s->nz + stag), (size_t)s->ny, (size_t)s->nx};
    if ((rc = nc_get_vara_float(s->nc, id, start, count, dst)) != NC_NOERR) return nc_fail(s, rc, name);
    const size_t n = count[1] * count[2] * count[3];
    for (size_t i = 0; i < n; i++)
        if (!isfinite(dst[i])) {
            size_t x = i % count[3], y = (i / count[3]) % count[2], z = i / (count[3] * count[2]);
            return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: variable %s: non-finite value at (t %d, z %zu, y %zu, x %zu)",
                                s->path, name, s->t, z + (size_t)s->k0, y + (size_t)s->j0, x + (size_t)s->i0);
        }
    return ATMOS_OK;
}

static atmos_status get_dim(const src *s, const char *name, size_t *len)
{
    int id;
    if (nc_inq_dimid(s->nc, name, &id) != NC_NOERR)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: dimension %s not found", s->path, name);
    int rc = nc_inq_dimlen(s->nc, id, len);
    return rc == NC_NOERR ? ATMOS_OK : nc_fail(s, rc, name);
}

/* A numeric attribute holding one value (nc_get_att_double copies all of an
 * attribute's values, so the length is checked first). */
static atmos_status get_att_double(const src *s, int var, const char *name, double *v)
{
    nc_type type;
    size_t len = 0;
    int rc = nc_inq_att(s->nc, var, name, &type, &len);
    if (rc == NC_NOERR && type != NC_CHAR && type != NC_STRING && len != 1)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: attribute %s has %zu values, expected one", s->path, name,
                            len);
    if (rc == NC_NOERR) rc = nc_get_att_double(s->nc, var, name, v);
    if (rc != NC_NOERR)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: attribute %s missing or not numeric", s->path, name);
    if (!isfinite(*v) || !(*v > 0))
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: attribute %s = %g must be > 0", s->path, name, *v);
    return ATMOS_OK;
}

/* Reads a 1-D coordinate (CM1's xh, yh, zh) in metres: CM1 writes km by default
 * (units "km"), or m. */
static atmos_status read_coord(const src *s, const char *name, size_t start, size_t count, double *dst)
{
    int id, rc;
    if ((rc = nc_inq_varid(s->nc, name, &id)) != NC_NOERR)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: coordinate variable %s not found", s->path, name);
    int nd;
    if ((rc = nc_inq_varndims(s->nc, id, &nd)) != NC_NOERR) return nc_fail(s, rc, name);
    if (nd != 1) return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: coordinate %s is not 1-D", s->path, name);
    if ((rc = nc_get_vara_double(s->nc, id, &start, &count, dst)) != NC_NOERR) return nc_fail(s, rc, name);
    char units[64] = "";
    size_t ul = 0;
    double f = 1.0;
    if (nc_inq_attlen(s->nc, id, "units", &ul) == NC_NOERR && ul < sizeof units &&
        nc_get_att_text(s->nc, id, "units", units) == NC_NOERR) {
        units[ul] = '\0';
        if (strcmp(units, "km") == 0) f = 1000.0;
        else if (strcmp(units, "m") != 0)
            return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: coordinate %s has units '%s', expected km or m", s->path,
                                name, units);
    } else {
        f = 1000.0; /* CM1's default */
    }
    for (size_t i = 0; i < count; i++) {
        dst[i] *= f;
        if (!isfinite(dst[i]))
            return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: coordinate %s is not finite", s->path, name);
        if (i > 0 && !(dst[i] > dst[i - 1]))
            return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: coordinate %s is not increasing", s->path, name);
    }
    return ATMOS_OK;
}

/* Classic-format files (CDF-1/2/5) are read by offset: a truncated one yields
 * zeros past the end instead of an error. The header says where every variable's
 * data starts and how many records there are, so a file shorter than the end of
 * its data is truncated (netcdf_classic.c). */
static atmos_status classic_truncation(atmos_context *ctx, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return ATMOS_OK;
    unsigned char magic[4] = {0};
    uint64_t need = 0, have = 0;
    int rc = -1;
    if (fread(magic, 1, 4, f) == 4 && magic[0] == 'C' && magic[1] == 'D' && magic[2] == 'F')
        rc = atmos__netcdf_classic_data_end(f, &need, &have);
    fclose(f);
    if (rc == 1)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated inside the NetCDF header (%llu bytes)", path,
                            (unsigned long long)have);
    if (rc == 0 && have < need)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated: the variables need at least %llu bytes, the file has %llu",
                            path, (unsigned long long)need, (unsigned long long)have);
    return ATMOS_OK;
}

/* A netCDF-4 (HDF5) file shorter than the end its superblock records is truncated
 * (hdf5_superblock.c): libhdf5 says only "HDF error" of it. An empty file is named so. */
static atmos_status hdf5_truncation(atmos_context *ctx, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return ATMOS_OK;
    uint64_t need = 0, have = UINT64_MAX; /* stays so when the size cannot be had (a pipe) */
    int rc = atmos__hdf5_data_end(f, &need, &have);
    fclose(f);
    if (have == 0) return atmos__error(ctx, ATMOS_E_FORMAT, "%s: the file is empty", path);
    if (rc == 1)
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: truncated inside the HDF5 superblock (%llu bytes)", path,
                            (unsigned long long)have);
    if (rc == 0 && have < need)
        return atmos__error(ctx, ATMOS_E_FORMAT,
                            "%s: truncated: the netCDF-4 (HDF5) file records %llu bytes, the file has %llu", path,
                            (unsigned long long)need, (unsigned long long)have);
    return ATMOS_OK;
}

static atmos_status check_classic_size(const src *s)
{
    int fmt;
    if (nc_inq_format(s->nc, &fmt) != NC_NOERR) return ATMOS_OK;
    if (fmt != NC_FORMAT_CLASSIC && fmt != NC_FORMAT_64BIT_OFFSET && fmt != NC_FORMAT_CDF5) return ATMOS_OK;
    return classic_truncation(s->ctx, s->path);
}

/* ------------------------------------------------------------ loader state */

/* Everything one load holds. Each step below fills part of it and returns a status;
 * loader_free releases all of it, whichever step failed. */
typedef struct {
    src s;
    int opened;                           /* s.nc is open */
    const atmos_volume_load_desc *desc;
    char present[1024];                   /* the file's variables, for messages */
    int sel[NHYDRO], nsel;                /* hydrometeors to load (indices into hydro[]) */
    int use_rho;                          /* CM1: density from rho, else from prs and th */
    double dx, dy;                        /* horizontal grid spacing, m */
    size_t ncol, n3, n3s;                 /* columns, mass points, staggered (w) points */
    float *buf, *buf2;                    /* read buffers (n3s floats; buf2 for WRF only) */
    float *qv;                            /* CM1 water vapour, when the file has it */
    double *rho;                          /* dry-air density at the mass points, kg/m^3 */
    double *zw, *zm;                      /* heights (m) of the w-levels (n3s), mass levels (n3) */
    double *zh;                           /* CM1: heights of the region's mass levels (nz + 1) */
    double *xc, *yc;                      /* column centres, m (one allocation, xc first) */
    float *eta;                           /* number densities, m^-3: nsel fields of n3 */
    double *zmt;                          /* zm transposed: each column's levels contiguous */
    float *colv;                          /* one output column */
    double *acc;                          /* the same, accumulated in double */
    unsigned char *wet;                   /* per model column: any value > 0 in the field */
    double zlo;                           /* bottom of the output grid, m */
    atmos_volume_desc vd;                 /* the output grid */
    atmos_volume *vol;
} loader;

static void loader_free(loader *L)
{
    if (L->opened) nc_close(L->s.nc);
    free(L->buf);
    free(L->buf2);
    free(L->qv);
    free(L->rho);
    free(L->zw);
    free(L->zm);
    free(L->zh);
    free(L->xc);
    free(L->eta);
    free(L->zmt);
    free(L->colv);
    free(L->acc);
    free(L->wet);
    atmos_volume_destroy(L->vol);
    L->vol = NULL;
}

static atmos_status out_of_memory(const loader *L)
{
    return atmos__error(L->s.ctx, ATMOS_E_NOMEM, "%s: out of memory", L->s.path);
}

static const char *model_var(const loader *L, int h) { return L->s.wrf ? hydro[h].wrf : hydro[h].cm1; }

static const char *model_hydro_list(const loader *L)
{
    return L->s.wrf ? "QCLOUD, QRAIN, QICE, QSNOW, QGRAUP" : "qc, qr, qi, qs, qg";
}

/* ------------------------------------------------------------ opening, identifying */

/* Opens the file; a file that exists but libnetcdf cannot read is a format error. */
static atmos_status open_file(loader *L)
{
    int rc = nc_open(L->s.path, NC_NOWRITE, &L->s.nc);
    if (rc != NC_NOERR) {
        FILE *f = fopen(L->s.path, "rb");
        if (!f) return atmos__error(L->s.ctx, ATMOS_E_IO, "%s: cannot open: %s", L->s.path, nc_strerror(rc));
        fclose(f);
        return atmos__error(L->s.ctx, ATMOS_E_FORMAT, "%s: not a readable NetCDF file: %s%s", L->s.path,
                            nc_strerror(rc), rc == NC_EHDFERR ? " (the file is damaged or truncated)" : "");
    }
    L->opened = 1;
    return ATMOS_OK;
}

/* WRF or CM1, from the variables each model always writes. */
static atmos_status identify_model(loader *L)
{
    src *s = &L->s;
    list_vars(s, L->present, sizeof L->present);
    atmos_status st = check_classic_size(s);
    if (st != ATMOS_OK) return st;
    s->wrf = has_var(s, "PH") || has_var(s, "QCLOUD") || has_var(s, "QVAPOR");
    int cm1 = has_var(s, "qc") || has_var(s, "rho") || has_var(s, "prs");
    if (!s->wrf && !cm1)
        return atmos__error(s->ctx, ATMOS_E_FORMAT,
                            "%s: neither WRF (QCLOUD, P, PB, T, PH, PHB, ...) nor CM1 (qc, rho or prs/th, ...) output; "
                            "variables present: %s",
                            s->path, L->present);
    return ATMOS_OK;
}

/* ------------------------------------------------------------ choosing variables */

/* Whether the list item p[0..len) names hydrometeor h, by the model's variable name
 * or by the atmos field name. */
static int names_hydro(const loader *L, int h, const char *p, size_t len)
{
    const char *name = model_var(L, h);
    return (strlen(name) == len && strncmp(p, name, len) == 0) ||
           (strlen(hydro[h].field) == len && strncmp(p, hydro[h].field, len) == 0);
}

/* Whether the comma-separated list asks for hydrometeor h. */
static int list_asks_for(const loader *L, const char *list, int h)
{
    int wanted = 0;
    const char *p = list;
    while (*p) {
        const char *c = strchr(p, ',');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        if (names_hydro(L, h, p, len)) wanted = 1;
        p += len;
        if (*p == ',') p++;
    }
    return wanted;
}

/* Every name asked for must be a hydrometeor this reader knows (by model or field
 * name): a misspelt one is an error, not silently dropped. */
static atmos_status check_list_names(const loader *L, const char *list)
{
    const char *p = list;
    while (*p) {
        const char *c = strchr(p, ',');
        size_t len = c ? (size_t)(c - p) : strlen(p);
        int known = 0;
        for (int h = 0; h < NHYDRO && len; h++)
            if (names_hydro(L, h, p, len)) known = 1;
        if (!known)
            return atmos__error(L->s.ctx, ATMOS_E_INVALID_ARG,
                                "%s: '%.*s' is not a hydrometeor variable (%s, or cloud, rain, ice, snow, graupel)",
                                L->s.path, (int)(len < 64 ? len : 64), p, model_hydro_list(L));
        p += len;
        if (*p == ',') p++;
    }
    return ATMOS_OK;
}

/* Which hydrometeors: those asked for (desc->grids, by model or field name), else all
 * present. */
static atmos_status choose_hydrometeors(loader *L)
{
    const char *list = L->desc->grids && *L->desc->grids ? L->desc->grids : NULL;
    L->nsel = 0;
    for (int h = 0; h < NHYDRO; h++) {
        int wanted;
        if (list) {
            wanted = list_asks_for(L, list, h);
            if (wanted && !has_var(&L->s, model_var(L, h)))
                return atmos__error(L->s.ctx, ATMOS_E_FORMAT, "%s: variable %s (%s) not found; variables present: %s",
                                    L->s.path, model_var(L, h), hydro[h].field, L->present);
        } else {
            wanted = has_var(&L->s, model_var(L, h));
        }
        if (wanted) L->sel[L->nsel++] = h;
    }
    if (list) {
        atmos_status st = check_list_names(L, list);
        if (st != ATMOS_OK) return st;
    }
    if (L->nsel == 0)
        return atmos__error(L->s.ctx, ATMOS_E_FORMAT, "%s: no hydrometeor variables (%s) %s; variables present: %s",
                            L->s.path, model_hydro_list(L), list ? "match the requested list" : "found", L->present);
    return ATMOS_OK;
}

/* The variables the air density and the heights need. */
static atmos_status check_density_vars(loader *L)
{
    static const char *const need_wrf[] = {"P", "PB", "T", "QVAPOR", "PH", "PHB"};
    const src *s = &L->s;
    L->use_rho = !s->wrf && has_var(s, "rho");
    if (s->wrf) {
        for (int i = 0; i < 6; i++)
            if (!has_var(s, need_wrf[i]))
                return atmos__error(s->ctx, ATMOS_E_FORMAT,
                                    "%s: WRF variable %s not found (needed for air density and heights: P, PB, T, "
                                    "QVAPOR, PH, PHB); variables present: %s",
                                    s->path, need_wrf[i], L->present);
    } else if (!L->use_rho && !(has_var(s, "prs") && has_var(s, "th"))) {
        return atmos__error(s->ctx, ATMOS_E_FORMAT,
                            "%s: CM1 output needs rho, or prs and th, for the air density; variables present: %s",
                            s->path, L->present);
    }
    return ATMOS_OK;
}

/* ------------------------------------------------------------ dimensions and region */

/* CM1 names its dimensions ni/nj/nk, or after the coordinates xh/yh/zh. */
static atmos_status get_dim_either(const src *s, const char *a, const char *b, size_t *len)
{
    atmos_status st = get_dim(s, a, len);
    return st == ATMOS_OK ? st : get_dim(s, b, len);
}

/* Full extents of the mass grid, and WRF's spacing (CM1's comes from its coordinates). */
static atmos_status read_extents(loader *L)
{
    src *s = &L->s;
    atmos_status st;
    if (s->wrf) {
        if ((st = get_dim(s, "west_east", &s->dim_len[0])) || (st = get_dim(s, "south_north", &s->dim_len[1])) ||
            (st = get_dim(s, "bottom_top", &s->dim_len[2])))
            return st;
        if ((st = get_att_double(s, NC_GLOBAL, "DX", &L->dx)) || (st = get_att_double(s, NC_GLOBAL, "DY", &L->dy)))
            return st;
    } else {
        if ((st = get_dim_either(s, "ni", "xh", &s->dim_len[0])) || (st = get_dim_either(s, "nj", "yh", &s->dim_len[1])) ||
            (st = get_dim_either(s, "nk", "zh", &s->dim_len[2])))
            return st;
        L->dx = L->dy = 0; /* from xh, yh once read */
    }
    /* A first CM1 name that failed left a message behind. */
    if (s->ctx) atmos_context_clear_error(s->ctx);
    for (int a = 0; a < 3; a++)
        if (s->dim_len[a] < 1 || s->dim_len[a] > 100000)
            return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: grid dimension %d has %zu points", s->path, a,
                                s->dim_len[a]);
    return ATMOS_OK;
}

/* Sub-region [i0, i1) x [j0, j1) x [k0, k1) of mass points (0 ends mean "to the end")
 * and the time step. A WRF region may start above the lowest level: its heights come
 * from the staggered levels bounding the chosen ones. */
static atmos_status choose_region(loader *L)
{
    src *s = &L->s;
    const int *r = L->desc->region;
    int lo[3] = {r[0], r[2], r[4]}, hi[3] = {r[1], r[3], r[5]};
    for (int a = 0; a < 3; a++) {
        if (hi[a] == 0) hi[a] = (int)s->dim_len[a];
        if (lo[a] < 0 || hi[a] > (int)s->dim_len[a] || lo[a] >= hi[a])
            return atmos__error(s->ctx, ATMOS_E_INVALID_ARG, "%s: region [%d, %d) along %s is outside 0..%zu", s->path,
                                lo[a], hi[a], a == 0 ? "x" : a == 1 ? "y" : "z", s->dim_len[a]);
    }
    s->i0 = lo[0];
    s->j0 = lo[1];
    s->k0 = lo[2];
    s->nx = hi[0] - lo[0];
    s->ny = hi[1] - lo[1];
    s->nz = hi[2] - lo[2];
    s->t = L->desc->time_index;
    if (s->t < 0) return atmos__error(s->ctx, ATMOS_E_INVALID_ARG, "%s: negative time index %d", s->path, s->t);
    L->ncol = (size_t)s->nx * (size_t)s->ny;
    L->n3 = L->ncol * (size_t)s->nz;
    L->n3s = L->ncol * (size_t)(s->nz + 1);
    return ATMOS_OK;
}

/* Memory for the source slabs, checked before allocating, in the float units the
 * check takes: two float read buffers and the w-level heights (double) on the
 * staggered grid; density, mass-level heights and their copy (doubles) and one float
 * eta field per hydrometeor on the mass grid; with margin for the CM1 path's q_v. */
static atmos_status allocate_slabs(loader *L)
{
    const uint64_t bytes =
        (uint64_t)L->n3s * (4 + 4 + 8) + (uint64_t)L->n3 * (8 + 8 + 8 + 4 + 4 * (uint64_t)L->nsel);
    atmos_status st = atmos__reader_check_memory(L->s.ctx, L->s.path, (bytes + 3) / 4, L->desc->max_memory);
    if (st != ATMOS_OK) return st;
    const size_t nxy = (size_t)(L->s.nx > L->s.ny ? L->s.nx : L->s.ny);
    L->buf = malloc(L->n3s * sizeof *L->buf);
    L->rho = malloc(L->n3 * sizeof *L->rho);
    L->zw = malloc(L->n3s * sizeof *L->zw);
    L->zm = malloc(L->n3 * sizeof *L->zm);
    L->eta = malloc(L->n3 * (size_t)L->nsel * sizeof *L->eta);
    L->xc = malloc(nxy * 2 * sizeof *L->xc);
    if (!L->buf || !L->rho || !L->zw || !L->zm || !L->eta || !L->xc) return out_of_memory(L);
    L->yc = L->xc + nxy;
    return ATMOS_OK;
}

/* ------------------------------------------------------------ heights and air density */

/* WRF: z = (PH + PHB) / g on the staggered levels (geopotential = g z); mass levels
 * halfway between. */
static atmos_status wrf_heights(loader *L)
{
    const src *s = &L->s;
    const size_t ncol = L->ncol;
    atmos_status st;
    if ((st = read_var(s, "PH", 1, L->buf)) || (st = read_var(s, "PHB", 1, L->buf2))) return st;
    for (size_t i = 0; i < L->n3s; i++) L->zw[i] = ((double)L->buf[i] + L->buf2[i]) / GRAV;
    for (size_t k = 0; k < (size_t)s->nz; k++)
        for (size_t c = 0; c < ncol; c++) {
            L->zm[k * ncol + c] = 0.5 * (L->zw[k * ncol + c] + L->zw[(k + 1) * ncol + c]);
            if (!(L->zw[(k + 1) * ncol + c] > L->zw[k * ncol + c]))
                return atmos__error(s->ctx, ATMOS_E_FORMAT,
                                    "%s: heights from PH+PHB do not increase upward (column %zu, level %zu)", s->path,
                                    c, k + (size_t)s->k0);
        }
    return ATMOS_OK;
}

/* WRF: p = P + PB; theta = T + 300 K; T = theta (p/p0)^(R_d/c_p);
 * rho = p / (R_d T_v), T_v = T (1 + 0.61 q_v). */
static atmos_status wrf_density(loader *L)
{
    const src *s = &L->s;
    float *buf = L->buf, *buf2 = L->buf2;
    double *rho = L->rho;
    atmos_status st;
    if ((st = read_var(s, "P", 0, buf)) || (st = read_var(s, "PB", 0, buf2))) return st;
    for (size_t i = 0; i < L->n3; i++) rho[i] = (double)buf[i] + buf2[i]; /* p for now */
    if ((st = read_var(s, "T", 0, buf)) || (st = read_var(s, "QVAPOR", 0, buf2))) return st;
    for (size_t i = 0; i < L->n3; i++) {
        double p = rho[i], theta = (double)buf[i] + 300.0, qv = buf2[i] > 0 ? buf2[i] : 0.0;
        double T = theta * pow(p / P0, RD / CP);
        rho[i] = p / (RD * T * (1.0 + 0.61 * qv));
        if (!(p > 0) || !(theta > 0) || !isfinite(rho[i]))
            return atmos__error(s->ctx, ATMOS_E_FORMAT,
                                "%s: non-physical pressure %g Pa or potential temperature %g K", s->path, p, theta);
    }
    return ATMOS_OK;
}

static atmos_status wrf_columns(loader *L)
{
    L->buf2 = malloc(L->n3s * sizeof *L->buf2);
    if (!L->buf2) return out_of_memory(L);
    atmos_status st = wrf_heights(L);
    if (st == ATMOS_OK) st = wrf_density(L);
    if (st != ATMOS_OK) return st;
    for (int i = 0; i < L->s.nx; i++) L->xc[i] = (i + 0.5) * L->dx;
    for (int j = 0; j < L->s.ny; j++) L->yc[j] = (j + 0.5) * L->dy;
    return ATMOS_OK;
}

/* CM1: coordinates xh, yh, zh, the spacing from them, and the heights. CM1 has no
 * terrain here (zh above ground); the column spans from the ground (or half a layer
 * below the region's first level) to half a layer above its last. */
static atmos_status cm1_heights(loader *L)
{
    const src *s = &L->s;
    const size_t ncol = L->ncol;
    L->zh = malloc(((size_t)s->nz + 1) * sizeof *L->zh);
    if (!L->zh) return out_of_memory(L);
    double *zh = L->zh, *xc = L->xc, *yc = L->yc;
    atmos_status st = read_coord(s, "zh", (size_t)s->k0, (size_t)s->nz, zh);
    if (!st) st = read_coord(s, "xh", (size_t)s->i0, (size_t)s->nx, xc);
    if (!st) st = read_coord(s, "yh", (size_t)s->j0, (size_t)s->ny, yc);
    if (st) return st;
    /* CM1's zh is the height of the scalar levels above the ground: positive, increasing. */
    for (int k = 0; k < s->nz; k++)
        if (!(zh[k] >= 0) || (k > 0 && !(zh[k] > zh[k - 1])))
            return atmos__error(s->ctx, ATMOS_E_FORMAT,
                                "%s: zh[%d] = %g m%s: CM1 heights above the ground must be >= 0 and increase upward",
                                s->path, s->k0 + k, zh[k], zh[k] >= 0 ? " (not above the level below)" : "");
    L->dx = s->nx > 1 ? (xc[s->nx - 1] - xc[0]) / (s->nx - 1) : 1000.0;
    L->dy = s->ny > 1 ? (yc[s->ny - 1] - yc[0]) / (s->ny - 1) : L->dx;
    if (s->nx == 1) L->dx = L->dy;
    for (int k = 0; k < s->nz; k++)
        for (size_t c = 0; c < ncol; c++) L->zm[(size_t)k * ncol + c] = zh[k];
    for (int k = 0; k <= s->nz; k++) {
        double z = k == 0 ? (s->k0 == 0 ? 0.0 : zh[0] - 0.5 * (s->nz > 1 ? zh[1] - zh[0] : zh[0]))
                   : k == s->nz ? zh[s->nz - 1] + 0.5 * (s->nz > 1 ? zh[s->nz - 1] - zh[s->nz - 2] : zh[0])
                                : 0.5 * (zh[k - 1] + zh[k]);
        for (size_t c = 0; c < ncol; c++) L->zw[(size_t)k * ncol + c] = z;
    }
    return ATMOS_OK;
}

/* CM1: rho itself, or from prs, th and (when present) qv as for WRF. */
static atmos_status cm1_density(loader *L)
{
    const src *s = &L->s;
    double *rho = L->rho;
    atmos_status st;
    if (L->use_rho) {
        if ((st = read_var(s, "rho", 0, L->buf))) return st;
        for (size_t i = 0; i < L->n3; i++) rho[i] = L->buf[i];
    } else {
        if ((st = read_var(s, "prs", 0, L->buf))) return st;
        for (size_t i = 0; i < L->n3; i++) rho[i] = L->buf[i];
        if ((st = read_var(s, "th", 0, L->buf))) return st;
        if (has_var(s, "qv")) {
            L->qv = malloc(L->n3 * sizeof *L->qv);
            if (!L->qv) return out_of_memory(L);
            if ((st = read_var(s, "qv", 0, L->qv))) return st;
        }
        const float *qv = L->qv;
        for (size_t i = 0; i < L->n3; i++) {
            double p = rho[i], th = L->buf[i], q = qv && qv[i] > 0 ? qv[i] : 0.0;
            double T = th * pow(p / P0, RD / CP);
            rho[i] = p / (RD * T * (1.0 + 0.61 * q));
        }
    }
    for (size_t i = 0; i < L->n3; i++)
        if (!(rho[i] > 0) || !isfinite(rho[i]))
            return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: non-physical air density %g kg/m^3", s->path, rho[i]);
    return ATMOS_OK;
}

/* Heights (m) of the w-levels and mass levels of each column, and the air density. */
static atmos_status read_columns(loader *L)
{
    if (L->s.wrf) return wrf_columns(L);
    atmos_status st = cm1_heights(L);
    return st == ATMOS_OK ? cm1_density(L) : st;
}

/* ------------------------------------------------------------ mixing ratio to number density */

/* eta = q rho / m_p (or q * density_scale) at the mass points of hydrometeor sel[si].
 * Mixing ratios slightly below zero are normal in model output (advection
 * undershoots; the WRF test file has none, but many runs do), so they are clamped to
 * 0 and counted in a warning. */
static atmos_status number_density(loader *L, int si)
{
    const int h = L->sel[si];
    const char *name = model_var(L, h);
    atmos_status st = read_var(&L->s, name, 0, L->buf);
    if (st != ATMOS_OK) return st;
    const double conv = L->desc->density_scale > 0 ? L->desc->density_scale : 0.0;
    const double mp = particle_mass(h);
    float *eta = L->eta + (size_t)si * L->n3;
    size_t neg = 0;
    double qmax = 0;
    for (size_t i = 0; i < L->n3; i++) {
        double q = L->buf[i];
        if (q < 0) {
            neg++;
            q = 0;
        }
        if (q > 1.0)
            return atmos__error(L->s.ctx, ATMOS_E_FORMAT, "%s: %s = %g kg/kg is not a mixing ratio", L->s.path, name,
                                q);
        if (q > qmax) qmax = q;
        eta[i] = (float)(conv > 0 ? q * conv : q * L->rho[i] / mp);
        if (!isfinite(eta[i]))
            return atmos__error(L->s.ctx, ATMOS_E_FORMAT,
                                "%s: %s = %g kg/kg at point %zu gives a number density of %g m^-3 (air density %g "
                                "kg/m^3): not a float; is the air density (rho, or prs and th) right?",
                                L->s.path, name, q, i, conv > 0 ? q * conv : q * L->rho[i] / mp, L->rho[i]);
    }
    if (neg)
        atmos__log(L->s.ctx, ATMOS_LOG_WARN, "%s: %s: %zu negative mixing ratios set to 0", L->s.path, name, neg);
    atmos__log(L->s.ctx, ATMOS_LOG_INFO, "%s: %s -> field %s (particle %s, mean mass %.3g kg): max q %.3g kg/kg",
               L->s.path, name, hydro[h].field, hydro[h].particle, mp, qmax);
    return ATMOS_OK;
}

/* ------------------------------------------------------------ the voxel grid */

/* The default voxel: the model's vertical resolution (its mean layer depth) unless the
 * horizontal spacing is finer, but no smaller than keeps the grid within DEFAULT_VOXELS
 * voxels (a coarse model over a wide domain: the vertical resolution then gives way), and
 * never so large that fewer than MIN_DEPTH_VOXELS span the model's depth (a model of a few
 * levels: output_grid warns of a voxel that coarse). */
#define DEFAULT_VOXELS 8388608.0
#define MIN_DEPTH_VOXELS 8.0
static double default_voxel(const loader *L, double depth)
{
    const src *s = &L->s;
    double vs = fmin(fmin(L->dx, L->dy), depth / s->nz);
    const double budget = cbrt(s->nx * L->dx * s->ny * L->dy * depth / DEFAULT_VOXELS);
    return fmin(fmax(vs, budget), depth / MIN_DEPTH_VOXELS);
}

/* The uniform output grid: from the lowest ground to the highest model top, voxels of
 * desc->voxel_size_m or by default_voxel (a voxel too large for the model's depth
 * flattens its vertical structure, hence the warning). */
static atmos_status output_grid(loader *L)
{
    const src *s = &L->s;
    const size_t top = (size_t)s->nz * L->ncol;
    double zlo = INFINITY, zhi = -INFINITY, layer = INFINITY;
    for (size_t c = 0; c < L->ncol; c++) {
        if (L->zw[c] < zlo) zlo = L->zw[c];
        if (L->zw[top + c] > zhi) zhi = L->zw[top + c];
        double th = (L->zw[top + c] - L->zw[c]) / s->nz;
        if (th < layer) layer = th;
    }
    const double dx = L->dx, dy = L->dy;
    double vs = L->desc->voxel_size_m > 0 ? L->desc->voxel_size_m : default_voxel(L, zhi - zlo);
    if ((zhi - zlo) / vs < MIN_DEPTH_VOXELS * (1 - 1e-9))
        atmos__log(s->ctx, ATMOS_LOG_WARN,
                   "%s: a voxel of %g m leaves only %.1f voxels over the model's %.0f m depth (thinnest mean layer "
                   "%.0f m); choose a smaller voxel size",
                   s->path, vs, (zhi - zlo) / vs, zhi - zlo, layer);
    if (!(vs > 0) || !isfinite(vs))
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: cannot derive a voxel size (dx %g, dy %g)", s->path, dx, dy);
    const double extent[3] = {s->nx * dx, zhi - zlo, s->ny * dy};
    atmos_volume_desc *vd = &L->vd;
    memset(vd, 0, sizeof *vd);
    for (int a = 0; a < 3; a++) {
        double n = ceil(extent[a] / vs - 1e-9);
        if (n < 1) n = 1;
        if (n > ATMOS_VOLUME_MAX_DIM)
            return atmos__error(s->ctx, ATMOS_E_LIMIT,
                                "%s: %.*g voxels of %g m along %s exceed the limit of %d; choose a larger voxel size "
                                "or a smaller region",
                                s->path, n < 1e9 ? 10 : 3, n, vs, a == 0 ? "x" : a == 1 ? "y" : "z", ATMOS_VOLUME_MAX_DIM);
        vd->dims[a] = (int)n;
    }
    vd->voxel_size_m = vs;
    vd->origin_m[0] = s->wrf ? 0.0 : L->xc[0] - 0.5 * dx;
    vd->origin_m[1] = zlo;
    vd->origin_m[2] = 0.0;
    vd->max_memory = L->desc->max_memory;
    L->zlo = zlo;
    return atmos_volume_create(s->ctx, vd, &L->vol);
}

/* Buffers of the resampling: one output column, and the mass-level heights column by
 * column for the per-column search. */
static atmos_status resample_buffers(loader *L)
{
    const int nz = L->s.nz;
    L->colv = malloc((size_t)L->vd.dims[1] * sizeof *L->colv);
    L->acc = malloc((size_t)L->vd.dims[1] * sizeof *L->acc);
    L->wet = malloc(L->ncol);
    L->zmt = malloc(L->n3 * sizeof *L->zmt);
    if (!L->colv || !L->acc || !L->wet || !L->zmt) return out_of_memory(L);
    for (size_t c = 0; c < L->ncol; c++)
        for (int k = 0; k < nz; k++) L->zmt[c * (size_t)nz + k] = L->zm[(size_t)k * L->ncol + c];
    return ATMOS_OK;
}

/* Adds w times model column col (values v[k * ncol], k over its mass levels) at the
 * output voxels' heights to L->acc: linear between mass levels, constant from the ground
 * to the first level and from the last level to the model top, 0 below the ground and
 * above the top. The heights grow with J, so the level pair is found by one walk up. */
static void add_column(const loader *L, const float *v, size_t col, double w)
{
    const int nz = L->s.nz;
    const size_t stride = L->ncol;
    const double *zm = L->zmt + col * (size_t)nz;
    const double ground = L->zw[col], top = L->zw[(size_t)nz * L->ncol + col], vs = L->vd.voxel_size_m;
    int lo = 0;
    for (int J = 0; J < L->vd.dims[1]; J++) {
        const double y = L->zlo + (J + 0.5) * vs;
        if (y < ground) continue;
        if (y > top) break;
        double val;
        if (y <= zm[0]) {
            val = v[0];
        } else if (y >= zm[nz - 1]) {
            val = v[(size_t)(nz - 1) * stride];
        } else {
            while (lo + 2 < nz && zm[lo + 1] <= y) lo++;
            const double f = (y - zm[lo]) / (zm[lo + 1] - zm[lo]);
            val = (1 - f) * v[(size_t)lo * stride] + f * v[(size_t)(lo + 1) * stride];
        }
        L->acc[J] += w * val;
    }
}

/* The four columns and Catmull-Rom weights at fractional column index f (clamped to
 * [0, n - 1]; columns past the edges repeat the edge's). The cubic passes through the
 * columns' values and its slope is continuous across them (C1): a smooth field, not the
 * pyramids of bilinear interpolation, whose slope jumps at every column. */
static void cubic_taps(double f, int n, int idx[4], double w[4])
{
    if (f < 0) f = 0;
    if (f > n - 1) f = n - 1;
    int a = (int)floor(f);
    if (a > n - 2) a = n - 2 > 0 ? n - 2 : 0;
    const double t = f - a, t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t + 2 * t2 - t3);
    w[1] = 0.5 * (2 - 5 * t2 + 3 * t3);
    w[2] = 0.5 * (t + 4 * t2 - 3 * t3);
    w[3] = 0.5 * (t3 - t2);
    for (int k = 0; k < 4; k++) {
        int i = a - 1 + k;
        idx[k] = i < 0 ? 0 : i > n - 1 ? n - 1 : i;
    }
}

/* One output column (voxels I, *, K) of field values e at the mass points: each model
 * column interpolated linearly in height at its own (terrain-following) levels, then the
 * 4 x 4 nearest columns (cell centres at (i + 0.5) dx) combined by bicubic Catmull-Rom
 * weights; the cubic's small overshoots below zero are cut at zero. Returns whether any
 * value is > 0. */
static int resample_column(const loader *L, const float *e, int I, int K)
{
    const src *s = &L->s;
    const double vs = L->vd.voxel_size_m;
    int ix[4], jy[4];
    double wx[4], wy[4];
    cubic_taps(((I + 0.5) * vs) / L->dx - 0.5, s->nx, ix, wx);
    /* z grows southward: K = 0 is the region's north edge. */
    cubic_taps((s->ny * L->dy - (K + 0.5) * vs) / L->dy - 0.5, s->ny, jy, wy);
    const int nJ = L->vd.dims[1];
    int any = 0;
    for (int J = 0; J < nJ; J++) L->acc[J] = 0;
    for (int c = 0; c < 16; c++) {
        const double cw = wx[c & 3] * wy[c >> 2];
        const size_t col = (size_t)ix[c & 3] + (size_t)s->nx * (size_t)jy[c >> 2];
        if (cw == 0 || !L->wet[col]) continue;
        add_column(L, e + col, col, cw);
        any = 1;
    }
    int nonzero = 0;
    for (int J = 0; J < nJ; J++) {
        const double v = any && L->acc[J] > 0 ? L->acc[J] : 0.0;
        L->colv[J] = (float)v;
        if (v > 0) nonzero = 1;
    }
    return nonzero;
}

/* Artists' sub-grid detail (desc->subgrid_detail = a > 0): the column's values times
 * 1 + a (2 n - 1), n a fractal value noise in [0, 1] (mean 1/2: the factor's mean is 1) whose
 * largest features are half the model's grid spacing and whose octaves reach the voxel. One
 * noise for all fields (the same texture in cloud and rain), fixed seed: the same volume
 * every time. */
static void add_detail(const loader *L, int I, int K)
{
    const double a = L->desc->subgrid_detail, vs = L->vd.voxel_size_m;
    const double cell = 0.5 * fmin(L->dx, L->dy);
    int octaves = 1;
    while (octaves < 6 && cell / (1 << octaves) > vs) octaves++;
    for (int J = 0; J < L->vd.dims[1]; J++) {
        if (!(L->colv[J] > 0)) continue;
        const double n = atmos__gen_fbm3(0x5EED, (I + 0.5) * vs / cell, (J + 0.5) * vs / cell, (K + 0.5) * vs / cell,
                                         octaves, 0.5);
        const double f = 1 + a * (2 * n - 1);
        L->colv[J] = (float)(L->colv[J] * (f > 0 ? f : 0));
    }
}

/* Adds hydrometeor sel[si] as a field and writes its non-empty columns. */
static atmos_status resample_field(loader *L, int si)
{
    const int h = L->sel[si];
    int field;
    atmos_status st = atmos_volume_add_field(L->s.ctx, L->vol, hydro[h].field, hydro[h].particle, &field);
    if (st != ATMOS_OK) return st;
    const float *e = L->eta + (size_t)si * L->n3;
    int wet = 0;
    for (size_t c = 0; c < L->ncol; c++) {
        L->wet[c] = 0;
        for (int k = 0; k < L->s.nz && !L->wet[c]; k++) L->wet[c] = e[(size_t)k * L->ncol + c] > 0;
        wet |= L->wet[c];
    }
    if (!wet) return ATMOS_OK; /* a dry field: no column to write */
    for (int I = 0; I < L->vd.dims[0]; I++)
        for (int K = 0; K < L->vd.dims[2]; K++) {
            if (!resample_column(L, e, I, K)) continue;
            if (L->desc->subgrid_detail > 0) add_detail(L, I, K);
            const int off[3] = {I, 0, K}, size[3] = {1, L->vd.dims[1], 1};
            if ((st = atmos_volume_set_dense(L->s.ctx, L->vol, field, off, size, L->colv, 1.0f))) return st;
        }
    return ATMOS_OK;
}

/* ------------------------------------------------------------ the reader */

static atmos_status load(loader *L)
{
    atmos_status st;
    if ((st = open_file(L)) || (st = identify_model(L)) || (st = choose_hydrometeors(L)) ||
        (st = check_density_vars(L)) || (st = read_extents(L)) || (st = choose_region(L)) ||
        (st = allocate_slabs(L)) || (st = read_columns(L)))
        return st;
    const double steps = 2.0 * L->nsel + 2;
    atmos__progress(L->s.ctx, "volume load", 1 / steps);
    for (int si = 0; si < L->nsel; si++) {
        if ((st = number_density(L, si))) return st;
        atmos__progress(L->s.ctx, "volume load", (2.0 + si) / steps);
    }
    if ((st = output_grid(L)) || (st = resample_buffers(L))) return st;
    if (L->desc->subgrid_detail > 0)
        atmos__log(L->s.ctx, ATMOS_LOG_WARN,
                   "%s: sub-grid detail added (amplitude %g): an artistic texture below the model's %.0f m grid, "
                   "not model data",
                   L->s.path, L->desc->subgrid_detail, fmin(L->dx, L->dy));
    for (int si = 0; si < L->nsel; si++) {
        if ((st = resample_field(L, si))) return st;
        atmos__progress(L->s.ctx, "volume load", (2.0 + L->nsel + si) / steps);
    }
    return atmos_volume_finalize(L->s.ctx, L->vol);
}

/* The load itself, run in the fence's child process. */
static atmos_status load_direct(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                atmos_volume **out)
{
    static const atmos_volume_load_desc zero_desc;
    loader L;
    memset(&L, 0, sizeof L);
    L.s.ctx = ctx;
    L.s.path = path;
    L.desc = desc ? desc : &zero_desc;
    atmos_status st = load(&L);
    if (st == ATMOS_OK) {
        *out = L.vol;
        L.vol = NULL;
    }
    loader_free(&L);
    return st == ATMOS_OK ? ATMOS_OK : atmos__reader_name_error(ctx, path, st);
}

/* libnetcdf and libhdf5 parse the file behind the fence (reader_fence.h): a damaged
 * netCDF-4 file can make libhdf5 free an invalid pointer. */
atmos_status atmos__volume_load_netcdf(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                       atmos_volume **out)
{
    if (!out || !path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "netcdf: path and out are required");
    *out = NULL;
    /* atmos's own check of a classic file's size needs no library: done here, it spares a
     * truncated file the child process */
    atmos_status st = classic_truncation(ctx, path);
    if (st == ATMOS_OK) st = hdf5_truncation(ctx, path);
    if (st != ATMOS_OK) return st;
    return atmos__reader_fenced(ctx, path, desc, "NetCDF/HDF5", load_direct, out);
}

#endif /* ATMOS_HAVE_NETCDF */
