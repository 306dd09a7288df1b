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
#include "volume/reader_common.h"
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

static atmos_status get_att_double(const src *s, int var, const char *name, double *v)
{
    int rc = nc_get_att_double(s->nc, var, name, v);
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

/* Value at height y in one column: heights zm[0..nz) at mass levels (increasing),
 * valid between ztop_bottom[0] (ground) and [1] (model top); 0 outside. Linear
 * between mass levels, constant from the ground to the first level and from the
 * last level to the top. */
static double column_at(const float *v, const double *zm, int nz, size_t stride, const double lim[2], double y)
{
    if (y < lim[0] || y > lim[1]) return 0.0;
    if (y <= zm[0]) return v[0];
    if (y >= zm[nz - 1]) return v[(size_t)(nz - 1) * stride];
    int lo = 0, hi = nz - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (zm[mid] <= y) lo = mid;
        else hi = mid;
    }
    double f = (y - zm[lo]) / (zm[hi] - zm[lo]);
    return (1 - f) * v[(size_t)lo * stride] + f * v[(size_t)hi * stride];
}

/* Classic-format files (CDF-1/2/5) are read by offset: a truncated one yields
 * zeros past the end instead of an error. The data alone needs at least this many
 * bytes (header and padding not counted), so a shorter file is truncated. */
static atmos_status check_classic_size(const src *s)
{
    int fmt, nv, unlim = -1;
    if (nc_inq_format(s->nc, &fmt) != NC_NOERR) return ATMOS_OK;
    if (fmt != NC_FORMAT_CLASSIC && fmt != NC_FORMAT_64BIT_OFFSET && fmt != NC_FORMAT_CDF5) return ATMOS_OK;
    if (nc_inq_nvars(s->nc, &nv) != NC_NOERR) return ATMOS_OK;
    nc_inq_unlimdim(s->nc, &unlim);
    double need = 0;
    for (int v = 0; v < nv; v++) {
        int nd, dims[NC_MAX_VAR_DIMS];
        nc_type type;
        size_t tsize;
        if (nc_inq_var(s->nc, v, NULL, &type, &nd, dims, NULL) != NC_NOERR) continue;
        if (nc_inq_type(s->nc, type, NULL, &tsize) != NC_NOERR) continue;
        double n = (double)tsize;
        for (int d = 0; d < nd; d++) {
            size_t len;
            if (nc_inq_dimlen(s->nc, dims[d], &len) != NC_NOERR) len = 0;
            n *= (double)len; /* the record dimension's length is the record count */
        }
        need += n;
    }
    FILE *f = fopen(s->path, "rb");
    if (!f) return ATMOS_OK;
    double have = 0;
    if (fseek(f, 0, SEEK_END) == 0) have = (double)ftell(f);
    fclose(f);
    if (have < need)
        return atmos__error(s->ctx, ATMOS_E_FORMAT, "%s: truncated: the variables need at least %.0f bytes, the file has %.0f",
                            s->path, need, have);
    return ATMOS_OK;
}

/* ------------------------------------------------------------ the reader */

atmos_status atmos__volume_load_netcdf(atmos_context *ctx, const char *path, const atmos_volume_load_desc *desc,
                                       atmos_volume **out)
{
    static const atmos_volume_load_desc zero_desc;
    if (!out || !path) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "netcdf: path and out are required");
    *out = NULL;
    if (!desc) desc = &zero_desc;
    src s;
    memset(&s, 0, sizeof s);
    s.ctx = ctx;
    s.path = path;
    int rc = nc_open(path, NC_NOWRITE, &s.nc);
    if (rc != NC_NOERR) {
        FILE *f = fopen(path, "rb");
        if (!f) return atmos__error(ctx, ATMOS_E_IO, "%s: cannot open: %s", path, nc_strerror(rc));
        fclose(f);
        return atmos__error(ctx, ATMOS_E_FORMAT, "%s: not a readable NetCDF file: %s", path, nc_strerror(rc));
    }
    atmos_status st = ATMOS_OK;
    float *buf = NULL, *eta = NULL, *colv = NULL;
    double *zw = NULL, *zm = NULL, *zmt = NULL, *rho = NULL, *xc = NULL, *yc = NULL;
    atmos_volume *vol = NULL;
    char present[1024];
    list_vars(&s, present, sizeof present);
    if ((st = check_classic_size(&s))) goto done;

    s.wrf = has_var(&s, "PH") || has_var(&s, "QCLOUD") || has_var(&s, "QVAPOR");
    int cm1 = has_var(&s, "qc") || has_var(&s, "rho") || has_var(&s, "prs");
    if (!s.wrf && !cm1) {
        st = atmos__error(ctx, ATMOS_E_FORMAT,
                          "%s: neither WRF (QCLOUD, P, PB, T, PH, PHB, ...) nor CM1 (qc, rho or prs/th, ...) output; "
                          "variables present: %s",
                          path, present);
        goto done;
    }

    /* Which hydrometeors: those asked for (desc->grids, by model or field name), else all present. */
    int sel[NHYDRO], nsel = 0;
    for (int h = 0; h < NHYDRO; h++) {
        const char *name = s.wrf ? hydro[h].wrf : hydro[h].cm1;
        int wanted;
        if (desc->grids && *desc->grids) {
            wanted = 0;
            const char *p = desc->grids;
            while (*p) {
                const char *c = strchr(p, ',');
                size_t len = c ? (size_t)(c - p) : strlen(p);
                if ((strlen(name) == len && strncmp(p, name, len) == 0) ||
                    (strlen(hydro[h].field) == len && strncmp(p, hydro[h].field, len) == 0))
                    wanted = 1;
                p += len;
                if (*p == ',') p++;
            }
            if (wanted && !has_var(&s, name)) {
                st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: variable %s (%s) not found; variables present: %s", path,
                                  name, hydro[h].field, present);
                goto done;
            }
        } else {
            wanted = has_var(&s, name);
        }
        if (wanted) sel[nsel++] = h;
    }
    /* Every name asked for must be a hydrometeor this reader knows (by model or field
     * name): a misspelt one is an error, not silently dropped. */
    if (desc->grids && *desc->grids) {
        const char *p = desc->grids;
        while (*p) {
            const char *c = strchr(p, ',');
            size_t len = c ? (size_t)(c - p) : strlen(p);
            int known = 0;
            for (int h = 0; h < NHYDRO && len; h++) {
                const char *name = s.wrf ? hydro[h].wrf : hydro[h].cm1;
                if ((strlen(name) == len && strncmp(p, name, len) == 0) ||
                    (strlen(hydro[h].field) == len && strncmp(p, hydro[h].field, len) == 0))
                    known = 1;
            }
            if (!known) {
                st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: '%.*s' is not a hydrometeor variable (%s, or cloud, rain, "
                                  "ice, snow, graupel)", path, (int)(len < 64 ? len : 64), p,
                                  s.wrf ? "QCLOUD, QRAIN, QICE, QSNOW, QGRAUP" : "qc, qr, qi, qs, qg");
                goto done;
            }
            p += len;
            if (*p == ',') p++;
        }
    }
    if (nsel == 0) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: no hydrometeor variables (%s) %s; variables present: %s", path,
                          s.wrf ? "QCLOUD, QRAIN, QICE, QSNOW, QGRAUP" : "qc, qr, qi, qs, qg",
                          desc->grids && *desc->grids ? "match the requested list" : "found", present);
        goto done;
    }
    /* The variables the density and heights need. */
    const char *need_wrf[] = {"P", "PB", "T", "QVAPOR", "PH", "PHB"};
    int use_rho = !s.wrf && has_var(&s, "rho");
    if (s.wrf) {
        for (int i = 0; i < 6; i++)
            if (!has_var(&s, need_wrf[i])) {
                st = atmos__error(ctx, ATMOS_E_FORMAT,
                                  "%s: WRF variable %s not found (needed for air density and heights: P, PB, T, QVAPOR, "
                                  "PH, PHB); variables present: %s",
                                  path, need_wrf[i], present);
                goto done;
            }
    } else if (!use_rho && !(has_var(&s, "prs") && has_var(&s, "th"))) {
        st = atmos__error(ctx, ATMOS_E_FORMAT,
                          "%s: CM1 output needs rho, or prs and th, for the air density; variables present: %s", path,
                          present);
        goto done;
    }

    /* Extents and spacing. */
    double dx, dy;
    if (s.wrf) {
        if ((st = get_dim(&s, "west_east", &s.dim_len[0])) || (st = get_dim(&s, "south_north", &s.dim_len[1])) ||
            (st = get_dim(&s, "bottom_top", &s.dim_len[2])))
            goto done;
        if ((st = get_att_double(&s, NC_GLOBAL, "DX", &dx)) || (st = get_att_double(&s, NC_GLOBAL, "DY", &dy)))
            goto done;
    } else {
        if ((st = get_dim(&s, "ni", &s.dim_len[0])) != ATMOS_OK && (st = get_dim(&s, "xh", &s.dim_len[0])) != ATMOS_OK)
            goto done;
        if ((st = get_dim(&s, "nj", &s.dim_len[1])) != ATMOS_OK && (st = get_dim(&s, "yh", &s.dim_len[1])) != ATMOS_OK)
            goto done;
        if ((st = get_dim(&s, "nk", &s.dim_len[2])) != ATMOS_OK && (st = get_dim(&s, "zh", &s.dim_len[2])) != ATMOS_OK)
            goto done;
        dx = dy = 0; /* from xh, yh below */
    }
    if (ctx) atmos_context_clear_error(ctx);
    for (int a = 0; a < 3; a++)
        if (s.dim_len[a] < 1 || s.dim_len[a] > 100000) {
            st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: grid dimension %d has %zu points", path, a, s.dim_len[a]);
            goto done;
        }
    /* Sub-region [i0, i1) x [j0, j1) x [k0, k1) of mass points; 0 ends mean "to the end". */
    const int *r = desc->region;
    int lo[3] = {r[0], r[2], r[4]}, hi[3] = {r[1], r[3], r[5]};
    for (int a = 0; a < 3; a++) {
        if (hi[a] == 0) hi[a] = (int)s.dim_len[a];
        if (lo[a] < 0 || hi[a] > (int)s.dim_len[a] || lo[a] >= hi[a]) {
            st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: region [%d, %d) along %s is outside 0..%zu", path, lo[a],
                              hi[a], a == 0 ? "x" : a == 1 ? "y" : "z", s.dim_len[a]);
            goto done;
        }
    }
    if (s.wrf && (lo[2] != 0 && hi[2] != (int)s.dim_len[2])) {
        /* Allowed: heights come from the staggered levels bounding the chosen ones. */
    }
    s.i0 = lo[0];
    s.j0 = lo[1];
    s.k0 = lo[2];
    s.nx = hi[0] - lo[0];
    s.ny = hi[1] - lo[1];
    s.nz = hi[2] - lo[2];
    s.t = desc->time_index;
    if (s.t < 0) {
        st = atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s: negative time index %d", path, s.t);
        goto done;
    }

    /* Memory for the source slabs, checked before allocating, in the float units the
     * check takes: two float read buffers and the w-level heights (double) on the
     * staggered grid; density, mass-level heights and their copy (doubles) and one float
     * eta field per hydrometeor on the mass grid; with margin for the CM1 path's q_v. */
    const size_t ncol = (size_t)s.nx * (size_t)s.ny;
    const size_t n3 = ncol * (size_t)s.nz, n3s = ncol * (size_t)(s.nz + 1);
    const uint64_t bytes = (uint64_t)n3s * (4 + 4 + 8) + (uint64_t)n3 * (8 + 8 + 8 + 4 + 4 * (uint64_t)nsel);
    st = atmos__reader_check_memory(ctx, path, (bytes + 3) / 4, desc->max_memory);
    if (st != ATMOS_OK) goto done;
    buf = malloc(n3s * sizeof *buf);
    float *buf2 = NULL;
    rho = malloc(n3 * sizeof *rho);
    zw = malloc(n3s * sizeof *zw);
    zm = malloc(n3 * sizeof *zm);
    eta = malloc(n3 * (size_t)nsel * sizeof *eta);
    xc = malloc((size_t)(s.nx > s.ny ? s.nx : s.ny) * 2 * sizeof *xc);
    if (!buf || !rho || !zw || !zm || !eta || !xc) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        goto done;
    }
    yc = xc + (s.nx > s.ny ? s.nx : s.ny);

    /* Heights (m) of the w-levels and mass levels of each column, and air density. */
    if (s.wrf) {
        buf2 = malloc(n3s * sizeof *buf2);
        if (!buf2) {
            st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
            goto done;
        }
        /* z = (PH + PHB) / g on the staggered levels (WRF: geopotential = g z). */
        if ((st = read_var(&s, "PH", 1, buf)) || (st = read_var(&s, "PHB", 1, buf2))) {
            free(buf2);
            goto done;
        }
        for (size_t i = 0; i < n3s; i++) zw[i] = ((double)buf[i] + buf2[i]) / GRAV;
        for (size_t k = 0; k < (size_t)s.nz; k++)
            for (size_t c = 0; c < ncol; c++) {
                zm[k * ncol + c] = 0.5 * (zw[k * ncol + c] + zw[(k + 1) * ncol + c]);
                if (!(zw[(k + 1) * ncol + c] > zw[k * ncol + c])) {
                    free(buf2);
                    st = atmos__error(ctx, ATMOS_E_FORMAT,
                                      "%s: heights from PH+PHB do not increase upward (column %zu, level %zu)", path, c,
                                      k + (size_t)s.k0);
                    goto done;
                }
            }
        /* p = P + PB; theta = T + 300 K; T = theta (p/p0)^(R_d/c_p);
         * rho = p / (R_d T_v), T_v = T (1 + 0.61 q_v). */
        if ((st = read_var(&s, "P", 0, buf)) || (st = read_var(&s, "PB", 0, buf2))) {
            free(buf2);
            goto done;
        }
        for (size_t i = 0; i < n3; i++) rho[i] = (double)buf[i] + buf2[i]; /* p for now */
        if ((st = read_var(&s, "T", 0, buf)) || (st = read_var(&s, "QVAPOR", 0, buf2))) {
            free(buf2);
            goto done;
        }
        for (size_t i = 0; i < n3; i++) {
            double p = rho[i], theta = (double)buf[i] + 300.0, qv = buf2[i] > 0 ? buf2[i] : 0.0;
            double T = theta * pow(p / P0, RD / CP);
            rho[i] = p / (RD * T * (1.0 + 0.61 * qv));
            if (!(p > 0) || !(theta > 0) || !isfinite(rho[i])) {
                free(buf2);
                st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: non-physical pressure %g Pa or potential temperature %g K",
                                  path, p, theta);
                goto done;
            }
        }
        free(buf2);
        for (int i = 0; i < s.nx; i++) xc[i] = (i + 0.5) * dx;
        for (int j = 0; j < s.ny; j++) yc[j] = (j + 0.5) * dy;
    } else {
        double *zh = malloc(((size_t)s.nz + 1) * sizeof *zh);
        if (!zh) {
            st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
            goto done;
        }
        st = read_coord(&s, "zh", (size_t)s.k0, (size_t)s.nz, zh);
        if (!st) st = read_coord(&s, "xh", (size_t)s.i0, (size_t)s.nx, xc);
        if (!st) st = read_coord(&s, "yh", (size_t)s.j0, (size_t)s.ny, yc);
        if (st) {
            free(zh);
            goto done;
        }
        dx = s.nx > 1 ? (xc[s.nx - 1] - xc[0]) / (s.nx - 1) : 1000.0;
        dy = s.ny > 1 ? (yc[s.ny - 1] - yc[0]) / (s.ny - 1) : dx;
        if (s.nx == 1) dx = dy;
        /* CM1 has no terrain here (zh above ground); the column spans from the
         * ground (or half a layer below the region's first level) to half a layer
         * above its last. */
        for (int k = 0; k < s.nz; k++)
            for (size_t c = 0; c < ncol; c++) zm[(size_t)k * ncol + c] = zh[k];
        for (int k = 0; k <= s.nz; k++) {
            double z = k == 0 ? (s.k0 == 0 ? 0.0 : zh[0] - 0.5 * (s.nz > 1 ? zh[1] - zh[0] : zh[0]))
                       : k == s.nz ? zh[s.nz - 1] + 0.5 * (s.nz > 1 ? zh[s.nz - 1] - zh[s.nz - 2] : zh[0])
                                   : 0.5 * (zh[k - 1] + zh[k]);
            for (size_t c = 0; c < ncol; c++) zw[(size_t)k * ncol + c] = z;
        }
        free(zh);
        if (use_rho) {
            if ((st = read_var(&s, "rho", 0, buf))) goto done;
            for (size_t i = 0; i < n3; i++) rho[i] = buf[i];
        } else {
            if ((st = read_var(&s, "prs", 0, buf))) goto done;
            for (size_t i = 0; i < n3; i++) rho[i] = buf[i];
            if ((st = read_var(&s, "th", 0, buf))) goto done;
            int qv_ok = has_var(&s, "qv");
            float *qv = qv_ok ? malloc(n3 * sizeof *qv) : NULL;
            if (qv_ok && (!qv || (st = read_var(&s, "qv", 0, qv)))) {
                free(qv);
                if (!st) st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
                goto done;
            }
            for (size_t i = 0; i < n3; i++) {
                double p = rho[i], th = buf[i], q = qv && qv[i] > 0 ? qv[i] : 0.0;
                double T = th * pow(p / P0, RD / CP);
                rho[i] = p / (RD * T * (1.0 + 0.61 * q));
            }
            free(qv);
        }
        for (size_t i = 0; i < n3; i++)
            if (!(rho[i] > 0) || !isfinite(rho[i])) {
                st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: non-physical air density %g kg/m^3", path, rho[i]);
                goto done;
            }
    }

    /* Number densities at the mass points. Mixing ratios slightly below zero are
     * normal in model output (advection undershoots; the WRF test file has none,
     * but many runs do), so they are clamped to 0 and counted in a warning. */
    for (int si = 0; si < nsel; si++) {
        const int h = sel[si];
        const char *name = s.wrf ? hydro[h].wrf : hydro[h].cm1;
        if ((st = read_var(&s, name, 0, buf))) goto done;
        const double conv = desc->density_scale > 0 ? desc->density_scale : 0.0;
        const double mp = particle_mass(h);
        size_t neg = 0;
        double qmax = 0;
        for (size_t i = 0; i < n3; i++) {
            double q = buf[i];
            if (q < 0) {
                neg++;
                q = 0;
            }
            if (q > 1.0) {
                st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: %s = %g kg/kg is not a mixing ratio", path, name, q);
                goto done;
            }
            if (q > qmax) qmax = q;
            eta[(size_t)si * n3 + i] = (float)(conv > 0 ? q * conv : q * rho[i] / mp);
        }
        if (neg)
            atmos__log(ctx, ATMOS_LOG_WARN, "%s: %s: %zu negative mixing ratios set to 0", path, name, neg);
        atmos__log(ctx, ATMOS_LOG_INFO, "%s: %s -> field %s (particle %s, mean mass %.3g kg): max q %.3g kg/kg", path,
                   name, hydro[h].field, hydro[h].particle, mp, qmax);
    }

    /* The uniform output grid. */
    double zlo = INFINITY, zhi = -INFINITY, layer = INFINITY;
    for (size_t c = 0; c < ncol; c++) {
        if (zw[c] < zlo) zlo = zw[c];
        if (zw[(size_t)s.nz * ncol + c] > zhi) zhi = zw[(size_t)s.nz * ncol + c];
        double th = (zw[(size_t)s.nz * ncol + c] - zw[c]) / s.nz;
        if (th < layer) layer = th;
    }
    /* Default voxel: the horizontal grid spacing. On coarse grids that flattens the
     * vertical structure, hence the warning. */
    double vs = desc->voxel_size_m > 0 ? desc->voxel_size_m : fmin(dx, dy);
    if ((zhi - zlo) / vs < 8)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "%s: a voxel of %g m leaves only %.1f voxels over the model's %.0f m depth (thinnest mean layer "
                   "%.0f m); choose a smaller voxel size",
                   path, vs, (zhi - zlo) / vs, zhi - zlo, layer);
    if (!(vs > 0) || !isfinite(vs)) {
        st = atmos__error(ctx, ATMOS_E_FORMAT, "%s: cannot derive a voxel size (dx %g, dy %g)", path, dx, dy);
        goto done;
    }
    const double extent[3] = {s.nx * dx, zhi - zlo, s.ny * dy};
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    for (int a = 0; a < 3; a++) {
        double n = ceil(extent[a] / vs - 1e-9);
        if (n < 1) n = 1;
        if (n > ATMOS_VOLUME_MAX_DIM) {
            st = atmos__error(ctx, ATMOS_E_LIMIT,
                              "%s: %.0f voxels of %g m along %s exceed the limit of %d; choose a larger voxel size or "
                              "a smaller region",
                              path, n, vs, a == 0 ? "x" : a == 1 ? "y" : "z", ATMOS_VOLUME_MAX_DIM);
            goto done;
        }
        vd.dims[a] = (int)n;
    }
    vd.voxel_size_m = vs;
    vd.origin_m[0] = s.wrf ? 0.0 : xc[0] - 0.5 * dx;
    vd.origin_m[1] = zlo;
    vd.origin_m[2] = 0.0;
    vd.max_memory = desc->max_memory;
    if ((st = atmos_volume_create(ctx, &vd, &vol))) goto done;

    colv = malloc((size_t)vd.dims[1] * sizeof *colv);
    /* Mass-level heights column by column, for the per-column search. */
    zmt = malloc(n3 * sizeof *zmt);
    if (!colv || !zmt) {
        st = atmos__error(ctx, ATMOS_E_NOMEM, "%s: out of memory", path);
        goto done;
    }
    for (int si = 0; si < nsel; si++) {
        const int h = sel[si];
        int field;
        if ((st = atmos_volume_add_field(ctx, vol, hydro[h].field, hydro[h].particle, &field))) goto done;
        const float *e = eta + (size_t)si * n3;
        for (int I = 0; I < vd.dims[0]; I++) {
            /* Bilinear between mass-point columns (cell centres at (i + 0.5) dx). */
            double fx = ((I + 0.5) * vs) / dx - 0.5;
            if (fx < 0) fx = 0;
            if (fx > s.nx - 1) fx = s.nx - 1;
            int ia = (int)floor(fx), ib = ia + 1 < s.nx ? ia + 1 : ia;
            double wx = fx - ia;
            for (int K = 0; K < vd.dims[2]; K++) {
                /* z grows southward: K = 0 is the region's north edge. */
                double fy = (s.ny * dy - (K + 0.5) * vs) / dy - 0.5;
                if (fy < 0) fy = 0;
                if (fy > s.ny - 1) fy = s.ny - 1;
                int ja = (int)floor(fy), jb = ja + 1 < s.ny ? ja + 1 : ja;
                double wy = fy - ja;
                const int ci[4] = {ia, ib, ia, ib}, cj[4] = {ja, ja, jb, jb};
                const double cw[4] = {(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy};
                int nonzero = 0;
                if (I == 0 && K == 0 && si == 0)
                    for (size_t c = 0; c < ncol; c++)
                        for (int k = 0; k < s.nz; k++) zmt[c * (size_t)s.nz + k] = zm[(size_t)k * ncol + c];
                for (int J = 0; J < vd.dims[1]; J++) {
                    double y = zlo + (J + 0.5) * vs, v = 0;
                    for (int c = 0; c < 4; c++) {
                        if (cw[c] == 0) continue;
                        size_t col = (size_t)ci[c] + (size_t)s.nx * (size_t)cj[c];
                        double zcol[2] = {zw[col], zw[(size_t)s.nz * ncol + col]};
                        v += cw[c] * column_at(e + col, zmt + col * (size_t)s.nz, s.nz, ncol, zcol, y);
                    }
                    colv[J] = (float)v;
                    if (v > 0) nonzero = 1;
                }
                if (!nonzero) continue;
                const int off[3] = {I, 0, K}, size[3] = {1, vd.dims[1], 1};
                if ((st = atmos_volume_set_dense(ctx, vol, field, off, size, colv, 1.0f))) goto done;
            }
        }
    }
    st = atmos_volume_finalize(ctx, vol);

done:
    nc_close(s.nc);
    free(buf);
    free(rho);
    free(zw);
    free(zm);
    free(zmt);
    free(eta);
    free(xc);
    free(colv);
    if (st != ATMOS_OK) {
        atmos_volume_destroy(vol);
        return atmos__reader_name_error(ctx, path, st);
    }
    *out = vol;
    return ATMOS_OK;
}

#endif /* ATMOS_HAVE_NETCDF */
