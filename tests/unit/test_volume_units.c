/* What a volume file's values and lengths are, and where it goes: density units (number
 * density, water content, 0..1 fraction), voxel size and length scale applied to files,
 * the scene keys a kind of volume would ignore refused, an artist's volume placed at a
 * cloud's altitude and framed by the camera, the WRF resampling's smoothness (no slope
 * jump at the model's columns) and its optional sub-grid detail for artists. */
#define _POSIX_C_SOURCE 200809L
#include "atmos/atmos.h"
#include "test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef ATMOS_HAVE_NETCDF
#include <netcdf.h>
#endif

static atmos_context *ctx;

/* A 4 x 3 x 2 raw volume (one field, value 0.5 everywhere but one voxel of 1), voxel
 * 10 m, origin (-20, -15, -10): written as float32 + sidecar. */
static void write_raw(char *json, size_t cap)
{
    char raw[1024];
    test_tmp_path(json, cap, "units.json");
    test_tmp_path(raw, sizeof raw, "units.raw");
    float v[24];
    for (int i = 0; i < 24; i++) v[i] = 0.5f;
    v[5] = 1.0f;
    FILE *f = fopen(raw, "wb");
    CHECK(f && fwrite(v, sizeof v[0], 24, f) == 24);
    if (f) fclose(f);
    f = fopen(json, "w");
    CHECK(f != NULL);
    if (f) {
        fprintf(f, "{\"file\": \"units.raw\", \"dims\": [4, 3, 2], \"voxel_size_m\": 10, "
                   "\"origin_m\": [-20, -15, -10]}\n");
        fclose(f);
    }
}

static double field_max(const atmos_volume *v)
{
    atmos_volume_field_stats st;
    CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &st));
    return st.max;
}

static atmos_volume *load(const char *path, atmos_density_unit unit, double voxel, double length_scale)
{
    atmos_volume_load_desc d;
    memset(&d, 0, sizeof d);
    d.density_unit = unit;
    d.voxel_size_m = voxel;
    d.length_scale = length_scale;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_load(ctx, path, &d, &v));
    return v;
}

/* Units: raw's own is a number density; fraction is 1e8 m^-3 per unit; g/m^3 divides by
 * the droplet's mass (r = 10 um: 4.19e-12 kg, so 1 g/m^3 = 2.39e8 droplets per m^3). */
static void test_units(const char *json)
{
    const double m_drop = 4.0 / 3.0 * 3.14159265358979 * 1e-15 * 1000.0;
    CHECK_REL(atmos_particle_mean_mass("cloud"), m_drop, 1e-12);
    CHECK(atmos_particle_mean_mass("glory_droplets") == 0);
    atmos_volume *v = load(json, ATMOS_DENSITY_AUTO, 0, 0);
    if (v) CHECK_REL(field_max(v), 1.0, 1e-7);
    atmos_volume_destroy(v);
    v = load(json, ATMOS_DENSITY_FRACTION, 0, 0);
    if (v) CHECK_REL(field_max(v), 1e8, 1e-6);
    atmos_volume_destroy(v);
    v = load(json, ATMOS_DENSITY_G_M3, 0, 0);
    if (v) CHECK_REL(field_max(v), 1e-3 / m_drop, 1e-6);
    atmos_volume_destroy(v);
    /* g/m^3 needs a known mass: a scene-defined type is refused by name. */
    atmos_volume_load_desc d;
    memset(&d, 0, sizeof d);
    d.density_unit = ATMOS_DENSITY_G_M3;
    d.field = "glory_droplets";
    v = NULL;
    CHECK(atmos_volume_load(ctx, json, &d, &v) == ATMOS_E_INVALID_ARG && !v);
    CHECK(strstr(atmos_context_error(ctx), "glory_droplets") != NULL);
    /* sub-grid detail is for model fields: refused for a raw (or VDB) file */
    memset(&d, 0, sizeof d);
    d.subgrid_detail = 0.5;
    CHECK(atmos_volume_load(ctx, json, &d, &v) == ATMOS_E_INVALID_ARG && !v);
}

/* Lengths: voxel_size_m replaces the file's voxel (origin scaled alike), length_scale
 * multiplies after it; the field's box follows. */
static void test_lengths(const char *json)
{
    atmos_volume *v = load(json, ATMOS_DENSITY_AUTO, 25, 0);
    if (v) {
        const atmos_volume_desc *d = atmos_volume_get_desc(v);
        CHECK_NEAR(d->voxel_size_m, 25, 1e-12);
        CHECK_NEAR(d->origin_m[0], -50, 1e-9);
        CHECK_NEAR(d->origin_m[1], -37.5, 1e-9);
        double lo[3], hi[3];
        atmos_volume_bounds(v, lo, hi);
        CHECK_NEAR(hi[0] - lo[0], 100, 1e-9);
        atmos_volume_field_stats st;
        CHECK_OK(atmos_volume_field_stats_get(ctx, v, 0, &st));
        CHECK_NEAR(st.bounds_m[0][0], -50, 1e-9);
        CHECK_NEAR(st.bounds_m[1][2], 25, 1e-9);
        /* the sampled value sits at the scaled place: voxel (1, 1, 0) is index 5 */
        const double p[3] = {-50 + 1.5 * 25, -37.5 + 1.5 * 25, -25 + 0.5 * 25};
        CHECK_REL(atmos_volume_sample(v, 0, p), 1.0, 1e-6);
        atmos_volume_destroy(v);
    }
    v = load(json, ATMOS_DENSITY_AUTO, 0, 0.01); /* a file in centimetres */
    if (v) CHECK_NEAR(atmos_volume_get_desc(v)->voxel_size_m, 0.1, 1e-12);
    atmos_volume_destroy(v);
    v = load(json, ATMOS_DENSITY_AUTO, 25, 2);
    if (v) CHECK_NEAR(atmos_volume_get_desc(v)->voxel_size_m, 50, 1e-12);
    atmos_volume_destroy(v);
}

static atmos_status parse(const char *text, atmos_scene *s)
{
    atmos_scene_defaults(s);
    return atmos_scene_parse(ctx, text, strlen(text), "t.json", s);
}

/* The parser refuses what a kind of volume ignores and reads the unit. */
static void test_scene_keys(void)
{
    atmos_scene s;
    CHECK(parse("{\"volume\": {\"file\": \"c.vdb\", \"seed\": 3}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(strstr(atmos_context_error(ctx), "\"seed\"") != NULL);
    CHECK(parse("{\"volume\": {\"generate\": \"cumulus\", \"density_unit\": \"g_m3\"}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(parse("{\"volume\": {\"generate\": \"cumulus\", \"time_index\": 2}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK(parse("{\"volume\": {\"file\": \"c.vdb\", \"density_unit\": \"kg\"}}", &s) == ATMOS_E_INVALID_ARG);
    CHECK_OK(parse("{\"volume\": {\"file\": \"c.vdb\", \"density_unit\": \"g_m3\", \"scale\": 0.01, "
                   "\"voxel_size_m\": 25}}",
                   &s));
    CHECK(s.volume.density_unit == ATMOS_DENSITY_G_M3 && s.volume.scale == 0.01 && s.volume.voxel_size_m == 25);
    CHECK(!s.camera_given);
    CHECK_OK(parse("{\"camera\": {\"fov_deg\": 30}, \"volume\": {\"generate\": \"cumulus\", \"seed\": 2}}", &s));
    CHECK(s.camera_given);
}

/* The eight corners of the placed box project inside the image; the camera is above the
 * ground and looks at the box's centre. */
static void check_framed(const atmos_scene *s, const atmos_volume *v, const double off[3])
{
    const atmos_camera_desc *c = &s->camera;
    double f[3], n = 0;
    for (int a = 0; a < 3; a++) f[a] = c->look_at[a] - c->position[a], n += f[a] * f[a];
    n = sqrt(n);
    for (int a = 0; a < 3; a++) f[a] /= n;
    double r[3] = {-f[2], 0, f[0]}, rn = hypot(r[0], r[2]);
    for (int a = 0; a < 3; a++) r[a] /= rn;
    const double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    const double tv = tan(0.5 * c->fov_deg * 3.14159265358979 / 180), th = tv * s->width / s->height;
    double lo[3], hi[3];
    atmos_volume_bounds(v, lo, hi);
    int inside = 0;
    double widest = 0;
    for (int k = 0; k < 8; k++) {
        double q[3];
        for (int a = 0; a < 3; a++) q[a] = ((k >> a) & 1 ? hi[a] : lo[a]) + off[a] - c->position[a];
        const double z = q[0] * f[0] + q[1] * f[1] + q[2] * f[2];
        const double x = (q[0] * r[0] + q[1] * r[1] + q[2] * r[2]) / z / th,
                     y = (q[0] * u[0] + q[1] * u[1] + q[2] * u[2]) / z / tv;
        inside += z > 0 && fabs(x) <= 1 && fabs(y) <= 1;
        widest = fmax(widest, fmax(fabs(x), fabs(y)));
    }
    CHECK_MSG(inside == 8, "%d of 8 corners in view", inside);
    CHECK_MSG(widest > 0.5, "the box fills too little of the view (%.2f)", widest);
    CHECK(c->position[1] >= 2.0);
}

/* An artist's VDB (centred on its origin, half below it) goes to a cloud's base; the
 * framing camera sees the whole box. */
static void test_placement(void)
{
    char p[1024];
    const char *d = getenv("ATMOS_SOURCE_DIR");
    snprintf(p, sizeof p, "%s/../shared/data/real/wdas_cloud_sixteenth.vdb", d && *d ? d : ".");
    FILE *f = fopen(p, "rb");
    if (!f) {
        printf("test_volume_units: wdas_cloud_sixteenth.vdb not found: placement check skipped\n");
        return;
    }
    fclose(f);
    atmos_scene s;
    atmos_scene_defaults(&s);
    snprintf(s.volume.source, sizeof s.volume.source, "%s", p);
    s.renderer = ATMOS_RENDERER_SLICE;
    atmos_volume *v = NULL;
    double off[3], lo[3], hi[3];
    CHECK_OK(atmos_scene_load_volume(ctx, &s, &v, off));
    if (!v) return;
    CHECK(!strcmp(atmos_volume_source_format(v), "openvdb"));
    atmos_volume_bounds(v, lo, hi);
    CHECK_MSG(lo[1] < 0, "the file's box starts at %g m", lo[1]);
    CHECK_NEAR(lo[1] + off[1], ATMOS_SCENE_CLOUD_BASE_M, 1e-6);
    /* its 0..1 values became a cumulus's number densities */
    CHECK_MSG(field_max(v) > 0.5e8 && field_max(v) <= 1e8, "max %g m^-3", field_max(v));
    for (int e = 0; e < 3; e++) {
        const double el[3] = {0, -30, 20};
        atmos_scene_frame_volume(&s, v, off, el[e]);
        check_framed(&s, v, off);
    }
    atmos_volume_destroy(v);
}

#ifdef ATMOS_HAVE_NETCDF
#define NC_OK(x) CHECK((x) == NC_NOERR)
#define NX 12
#define NY 4
#define NZ 3

/* A WRF-like file: NX x NY columns of 1 km, three flat layers of 250 m, a cloud
 * mixing ratio varying smoothly from column to column along x, the same at every level
 * and row. */
static void write_wrf(const char *path)
{
    int nc, d[5];
    NC_OK(nc_create(path, NC_CLOBBER, &nc));
    NC_OK(nc_def_dim(nc, "Time", NC_UNLIMITED, &d[0]));
    NC_OK(nc_def_dim(nc, "bottom_top", NZ, &d[1]));
    NC_OK(nc_def_dim(nc, "south_north", NY, &d[2]));
    NC_OK(nc_def_dim(nc, "west_east", NX, &d[3]));
    NC_OK(nc_def_dim(nc, "bottom_top_stag", NZ + 1, &d[4]));
    double dx = 1000;
    NC_OK(nc_put_att_double(nc, NC_GLOBAL, "DX", NC_FLOAT, 1, &dx));
    NC_OK(nc_put_att_double(nc, NC_GLOBAL, "DY", NC_FLOAT, 1, &dx));
    const int mass[4] = {d[0], d[1], d[2], d[3]}, stag[4] = {d[0], d[4], d[2], d[3]};
    const char *names[6] = {"QCLOUD", "QVAPOR", "T", "P", "PB", "PH"};
    int id[7];
    for (int i = 0; i < 5; i++) NC_OK(nc_def_var(nc, names[i], NC_FLOAT, 4, mass, &id[i]));
    NC_OK(nc_def_var(nc, "PH", NC_FLOAT, 4, stag, &id[5]));
    NC_OK(nc_def_var(nc, "PHB", NC_FLOAT, 4, stag, &id[6]));
    NC_OK(nc_enddef(nc));
    static float m[NZ][NY][NX], w[NZ + 1][NY][NX];
    const size_t start[4] = {0, 0, 0, 0}, cm[4] = {1, NZ, NY, NX}, cs[4] = {1, NZ + 1, NY, NX};
    const float value[5] = {0, 0.01f, 0, 0, 80000.0f};
    for (int v = 0; v < 5; v++) {
        for (int k = 0; k < NZ; k++)
            for (int j = 0; j < NY; j++)
                for (int i = 0; i < NX; i++) m[k][j][i] = v ? value[v] : (float)(1e-3 * (1.2 + sin(0.9 * i)));
        NC_OK(nc_put_vara_float(nc, id[v], start, cm, &m[0][0][0]));
    }
    for (int v = 0; v < 2; v++) {
        for (int k = 0; k <= NZ; k++)
            for (int j = 0; j < NY; j++)
                for (int i = 0; i < NX; i++) w[k][j][i] = (float)(v ? 0.0 : 9.81 * 250.0 * k);
        NC_OK(nc_put_vara_float(nc, id[5 + v], start, cs, &w[0][0][0]));
    }
    NC_OK(nc_close(nc));
}

/* The sum and the largest relative change of field 0 between two volumes on one grid, at
 * every voxel centre. */
static void compare_fields(const atmos_volume *a, const atmos_volume *b, double *sum_a, double *sum_b, double *change,
                           int *negative)
{
    const atmos_volume_desc *d = atmos_volume_get_desc(a);
    *sum_a = *sum_b = *change = 0;
    *negative = 0;
    for (int k = 0; k < d->dims[2]; k++)
        for (int j = 0; j < d->dims[1]; j++)
            for (int i = 0; i < d->dims[0]; i++) {
                const double q[3] = {d->origin_m[0] + (i + 0.5) * d->voxel_size_m,
                                     d->origin_m[1] + (j + 0.5) * d->voxel_size_m,
                                     d->origin_m[2] + (k + 0.5) * d->voxel_size_m};
                const double x = atmos_volume_sample(a, 0, q), y = atmos_volume_sample(b, 0, q);
                *sum_a += x, *sum_b += y;
                *negative += y < 0;
                if (x > 0) *change = fmax(*change, fabs(y / x - 1));
            }
}

/* Artists' sub-grid detail: off by default; on, a texture that keeps the field's mean
 * (within the noise's sampling) and its sign, the same every time, refused for VDB/raw. */
static void test_wrf_detail(const char *path)
{
    atmos_volume_load_desc d;
    memset(&d, 0, sizeof d);
    d.voxel_size_m = 125;
    atmos_volume *plain = NULL, *art = NULL, *art2 = NULL;
    CHECK_OK(atmos_volume_load(ctx, path, &d, &plain));
    d.subgrid_detail = 0.6;
    CHECK_OK(atmos_volume_load(ctx, path, &d, &art));
    CHECK_OK(atmos_volume_load(ctx, path, &d, &art2));
    if (plain && art && art2) {
        double sa, sb, change, s2, c2;
        int neg, neg2;
        compare_fields(plain, art, &sa, &sb, &change, &neg);
        CHECK_MSG(change > 0.1 && change <= 0.6 + 1e-6, "detail changed voxels by up to %.3f", change);
        CHECK_MSG(fabs(sb / sa - 1) < 0.1, "detail moved the mean by %.3f", sb / sa - 1);
        CHECK(neg == 0);
        compare_fields(art, art2, &s2, &sb, &c2, &neg2);
        CHECK_MSG(c2 == 0, "detail differs between two loads (%g)", c2);
        printf("test_volume_units: sub-grid detail 0.6: voxels changed by up to %.2f, mean by %+.3f\n", change,
               sb / sa - 1);
    }
    atmos_volume_destroy(plain);
    atmos_volume_destroy(art);
    atmos_volume_destroy(art2);
}

/* Along a row, at 200 m voxels, column i's centre is voxel 5 i + 2. The second difference
 * of the resampled field there (its slope's change across the column) must be of the size
 * of those of its neighbours: bilinear interpolation is straight between columns (second
 * differences 0) and bends only at them, the pyramids of an egg crate. */
static void test_wrf_smooth(void)
{
    char p[1024];
    test_tmp_path(p, sizeof p, "wrf_smooth.nc");
    write_wrf(p);
    atmos_volume_load_desc d;
    memset(&d, 0, sizeof d);
    d.voxel_size_m = 200;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_load(ctx, p, &d, &v));
    if (!v) return;
    double row[NX * 5];
    for (int I = 0; I < NX * 5; I++) {
        const double q[3] = {(I + 0.5) * 200, 375, 0.5 * NY * 1000 + 100};
        row[I] = atmos_volume_sample(v, 0, q);
    }
    double worst = 0, peak = 0;
    for (int i = 2; i < NX - 2; i++) {
        const int I = 5 * i + 2;
        const double at = fabs(row[I + 1] - 2 * row[I] + row[I - 1]);
        double around = 0;
        for (int k = 1; k <= 2; k++) {
            around = fmax(around, fabs(row[I + k + 1] - 2 * row[I + k] + row[I + k - 1]));
            around = fmax(around, fabs(row[I - k + 1] - 2 * row[I - k] + row[I - k - 1]));
        }
        worst = fmax(worst, at / fmax(around, 1e-9 * row[I]));
        peak = fmax(peak, row[I]);
    }
    CHECK_MSG(worst < 2.5, "slope jump at a model column %.3g times its neighbours' bends", worst);
    /* the columns' own values are kept (an interpolation, not a smoothing) */
    const double rho = 80000.0 / (287.0 * 300.0 * pow(0.8, 287.0 / 1004.5) * (1 + 0.61 * 0.01));
    const double mp = atmos_particle_mean_mass("cloud");
    CHECK_REL(row[5 * 4 + 2], 1e-3 * (1.2 + sin(0.9 * 4)) * rho / mp, 2e-3);
    printf("test_volume_units: WRF resampling: worst bend at a column %.2f x its neighbours'\n", worst);
    atmos_volume_destroy(v);
    /* the default voxel follows the model's 250 m layers: 3 voxels over 750 m, not one of
     * the 1 km horizontal spacing */
    memset(&d, 0, sizeof d);
    v = NULL;
    CHECK_OK(atmos_volume_load(ctx, p, &d, &v));
    if (v) CHECK_MSG(atmos_volume_get_desc(v)->dims[1] >= 3, "%d voxels tall", atmos_volume_get_desc(v)->dims[1]);
    atmos_volume_destroy(v);
    test_wrf_detail(p);
    /* the units of other formats do not apply to a model's mixing ratios */
    d.density_unit = ATMOS_DENSITY_FRACTION;
    v = NULL;
    CHECK(atmos_volume_load(ctx, p, &d, &v) == ATMOS_E_INVALID_ARG && !v);
    /* nor a particle type for a single grid, nor a length scale */
    memset(&d, 0, sizeof d);
    d.field = "rain";
    CHECK(atmos_volume_load(ctx, p, &d, &v) == ATMOS_E_INVALID_ARG && !v);
    memset(&d, 0, sizeof d);
    d.length_scale = 0.01;
    CHECK(atmos_volume_load(ctx, p, &d, &v) == ATMOS_E_INVALID_ARG && !v);
}
#endif

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    char json[1024];
    write_raw(json, sizeof json);
    test_units(json);
    test_lengths(json);
    test_scene_keys();
    test_placement();
#ifdef ATMOS_HAVE_NETCDF
    test_wrf_smooth();
#endif
    atmos_context_destroy(ctx);
    return test_summary("test_volume_units");
}
