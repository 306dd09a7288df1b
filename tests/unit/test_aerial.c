/* The aerial-perspective volume (src/atmosphere/atmosphere_aerial.c, spherical_aerial.c)
 * against the atmosphere's own direct answers (atmos_atmosphere_inscatter and
 * atmos_atmosphere_transmittance of the same segment) at random (direction, distance) pairs:
 * the production sky's fast path (a high sun, a low sun in view near the horizon, the grid
 * the slice renderer makes), the generic path on Riley's closed form and on the homogeneous
 * layer (whose optical depth is linear in distance, so the interpolated transmittance is
 * exact), the answers outside the grid, thread independence; and the slice renderer's frame
 * under the spherical sky with the volume against the frame asking the atmosphere per pixel
 * (the reference passes). */
#include "atmos/atmos.h"
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "test.h"
#include "test_optics.h"

#include <stdint.h>

static uint64_t rng_state = 0x243F6A8885A308D3ull;
static double rnd(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (double)((z ^ (z >> 31)) >> 11) * (1.0 / 9007199254740992.0);
}

static atmos_atmosphere *make(atmos_atmosphere_kind kind)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = kind;
    ad.ground_albedo = 0.3;
    ad.hide_sun_disk = 1;
    if (kind == ATMOS_ATMOSPHERE_HOMOGENEOUS) ad.thickness_m = 3000;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &a));
    return a;
}

static double lum(const double *c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* A frustum from eye (altitude y) centred on (el, az) degrees, +-tu across, +-tv up. */
static void frustum(atmos__aerial_grid *g, double y, double el, double az, double tu, double tv, double sun_el,
                    double sun_az, int nu, int nv, int nd, double tmax, double roll_deg)
{
    memset(g, 0, sizeof *g);
    g->eye[1] = y;
    atmos_direction_from_angles(el, az, g->fwd);
    atmos_direction_from_angles(sun_el, sun_az, g->sun);
    const double wup[3] = {0, 1, 0};
    atmos__cross3(g->fwd, wup, g->right);
    atmos__normalize3(g->right);
    atmos__cross3(g->right, g->fwd, g->up);
    const double cr = cos(roll_deg * 0.017453292519943295), sr = sin(roll_deg * 0.017453292519943295);
    for (int c = 0; c < 3; c++) {
        const double r = g->right[c], u = g->up[c];
        g->right[c] = cr * r + sr * u, g->up[c] = cr * u - sr * r;
    }
    g->u0 = -tu, g->u1 = tu, g->v0 = -tv, g->v1 = tv;
    g->nu = nu, g->nv = nv, g->nd = nd, g->tmin = 0, g->tmax = tmax;
}

/* Worst and RMS relative errors of count random pairs that the volume answers (the distance
 * cut at the ground, as the renderer does; in-scatter relative to max(direct, 1e-3 x the
 * largest direct luminance)), the worst transmittance error relative to the direct
 * transmittance, and the share of the pairs answered (the rest: the renderer asks the
 * atmosphere). near_sun: a quarter of the directions within ~3 degrees of the sun. */
typedef struct {
    double s_worst, s_rms, t_worst, answered;
} errs;

static errs compare(const char *name, const atmos_atmosphere *a, const atmos__aerial_grid *g, int count, int near_sun)
{
    atmos__aerial ap;
    memset(&ap, 0, sizeof ap);
    CHECK(atmos__aerial_build(&ap, a, g, 2));
    enum { MAXN = 512 };
    static double S[MAXN][3], D[MAXN][3], T[MAXN][3], E[MAXN][3];
    static int ok[MAXN];
    double smax = 0;
    int got = 0;
    for (int i = 0; i < count && i < MAXN; i++) {
        const double u = g->u0 + (g->u1 - g->u0) * rnd(), v = g->v0 + (g->v1 - g->v0) * rnd(), x = rnd();
        double d[3];
        for (int c = 0; c < 3; c++) d[c] = g->fwd[c] + u * g->right[c] + v * g->up[c];
        if (i % 4 == 1 && near_sun) /* a quarter within ~3 degrees of the sun: its aureole */
            for (int c = 0; c < 3; c++)
                d[c] = g->sun[c] + 0.05 * (2 * rnd() - 1) * g->right[c] + 0.05 * (2 * rnd() - 1) * g->up[c];
        atmos__normalize3(d);
        double t = g->tmin + (g->tmax - g->tmin) * (i % 4 == 0 ? x * x : x); /* a quarter crowded near tmin */
        const double tg = atmos_atmosphere_ground_distance(a, g->eye, d);
        if (t > tg) t = tg;
        atmos_atmosphere_inscatter(a, g->eye, d, t, g->sun, D[i]);
        atmos_atmosphere_transmittance(a, g->eye, d, t, E[i]);
        ok[i] = atmos__aerial_eval(&ap, d, t, S[i], T[i]); /* 0: the renderer asks the atmosphere */
        got += ok[i];
        smax = fmax(smax, lum(D[i]));
    }
    errs e = {0, 0, 0, (double)got / count};
    for (int i = 0; i < count; i++) {
        for (int c = 0; c < 3 && ok[i]; c++) {
            const double r = fabs(S[i][c] - D[i][c]) / fmax(D[i][c], 1e-3 * smax);
            e.s_worst = fmax(e.s_worst, r);
            e.s_rms += r * r / (3.0 * got);
            e.t_worst = fmax(e.t_worst, fabs(T[i][c] - E[i][c]) / fmax(E[i][c], 1e-6));
        }
    }
    e.s_rms = sqrt(e.s_rms);
    printf("%s (%dx%d nodes): %d pairs (%.0f %% from the volume), in-scatter worst %.3f %% rms %.3f %%, transmittance worst "
           "%.3f %%\n", name, g->nu, g->nv, count, 100 * e.answered, 100 * e.s_worst, 100 * e.s_rms, 100 * e.t_worst);
    atmos__aerial_free(&ap);
    return e;
}

/* The production sky's fast path, the grid's nodes by atmos__aerial_nodes (as the slice
 * renderer makes them): within 1 % at worst, in-scatter and transmittance. */
static void spherical_case(const atmos_atmosphere *a, const char *name, double y, double el, double az, double tu,
                           double tv, double sun_el, double sun_az, double tmax, int count, int near_sun,
                           double roll)
{
    atmos__aerial_grid g;
    frustum(&g, y, el, az, tu, tv, sun_el, sun_az, 2, 2, ATMOS__AERIAL_SLICES, tmax, roll);
    atmos__aerial_nodes(a, &g);
    const errs e = compare(name, a, &g, count, near_sun);
    CHECK(e.s_worst < 0.01 && e.t_worst < 0.01);
    CHECK(e.s_rms < 0.002);
    CHECK(e.answered > 0.5);
}

/* From 36 000 km at a 40 km patch of the ground (looking 14 degrees off the vertical), the
 * slices from 30 km in front of the patch to 1 km behind it, crowded at the far end (what the
 * slice renderer does for a volume there, a box from the ground up): the air in front marched
 * as one segment. */
static void from_space(const atmos_atmosphere *a)
{
    atmos__aerial_grid g;
    memset(&g, 0, sizeof g);
    g.eye[1] = 36000e3, g.eye[2] = 9000e3;
    const double target[3] = {0, 0, 0};
    for (int c = 0; c < 3; c++) g.fwd[c] = target[c] - g.eye[c];
    const double dist = sqrt(atmos__dot3(g.fwd, g.fwd));
    atmos__normalize3(g.fwd);
    const double wup[3] = {0, 1, 0};
    atmos__cross3(g.fwd, wup, g.right);
    atmos__normalize3(g.right);
    atmos__cross3(g.right, g.fwd, g.up);
    atmos_direction_from_angles(20, 180, g.sun);
    g.u0 = g.v0 = -20e3 / dist, g.u1 = g.v1 = 20e3 / dist;
    g.nd = ATMOS__AERIAL_SLICES, g.tmin = dist - 30e3, g.tmax = dist + 1e3, g.crowd_far = 1;
    atmos__aerial_nodes(a, &g);
    const errs e = compare("spherical, from 36 000 km, slices from 30 km above the ground", a, &g, 300, 0);
    CHECK(e.s_worst < 0.01 && e.t_worst < 0.01);
    CHECK(e.answered > 0.5);
}

static void spherical_cases(const atmos_atmosphere *a)
{
    /* 1500 m up, a 30-degree sun in the frame's corner, the ground in its lower part */
    spherical_case(a, "spherical, sun 30 deg, 62-degree view, 20 km", 1500, 10, 150, 0.6, 0.6, 30, 180, 20e3, 400, 0, 0);
    /* the same with the camera rolled 30 degrees (the image's axes no longer level) */
    spherical_case(a, "spherical, sun 30 deg, rolled 30 deg, 20 km", 1500, 10, 150, 0.6, 0.6, 30, 180, 20e3, 400, 0, 30);
    /* 2 m up, a 3-degree sun in view, the horizon across the frame */
    spherical_case(a, "spherical, sun 3 deg in view, horizon, 30 km", 2, 2, 200, 0.3, 0.15, 3, 200, 30e3, 400, 1, 0);
    /* the sun just below the horizon (the air in front lit from below the frame) */
    spherical_case(a, "spherical, sun -2 deg, 15 km", 300, 5, 100, 0.4, 0.3, -2, 90, 15e3, 300, 0, 0);
    /* a cloud 1-3 km away in a 45-degree view */
    spherical_case(a, "spherical, 45-degree view, 3 km", 1500, 8, 0, 0.41, 0.41, 35, 200, 3000, 400, 0, 0);
    /* a storm's distance, looking down 20 degrees from 6 km */
    spherical_case(a, "spherical, 45-degree view 20 deg down from 6 km, 40 km", 6000, -20, 300, 0.41, 0.41, 15, 30, 40e3,
                   400, 0, 0);
}

/* Many wavelengths: the node count keeps the table within its budget. */
static void budget(void)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = ATMOS_ATMOSPHERE_RILEY;
    atmos_wavelengths wl;
    atmos_wavelengths_spectral(ATMOS_MAX_WAVELENGTHS, &wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &a));
    atmos__aerial_grid g;
    frustum(&g, 1500, 10, 150, 0.6, 0.6, 30, 180, 2, 2, ATMOS__AERIAL_SLICES, 40e3, 30);
    atmos__aerial_nodes(a, &g);
    const double bytes = (double)g.nu * g.nv * g.nd * wl.count * 4 * sizeof(float);
    printf("%d wavelengths: %dx%d nodes, %.1f MB\n", wl.count, g.nu, g.nv, bytes / 1048576);
    CHECK(bytes <= ATMOS__AERIAL_MAX_BYTES && g.nu >= 2 && g.nv >= 2);
    atmos_atmosphere_destroy(a);
}

/* The generic path: Riley's closed form and the homogeneous layer. */
static void generic_cases(void)
{
    atmos_atmosphere *r = make(ATMOS_ATMOSPHERE_RILEY);
    atmos__aerial_grid g;
    frustum(&g, 1500, 10, 150, 0.6, 0.6, 30, 180, 2, 2, ATMOS__AERIAL_SLICES, 20e3, 0);
    atmos__aerial_nodes(r, &g);
    errs e = compare("riley (generic), 20 km", r, &g, 300, 0);
    CHECK(e.s_worst < 0.01 && e.t_worst < 0.01);
    atmos_atmosphere_destroy(r);
    atmos_atmosphere *h = make(ATMOS_ATMOSPHERE_HOMOGENEOUS);
    frustum(&g, 1000, 0, 30, 0.5, 0.3, 20, 60, 12, 8, 16, 1500, 0); /* inside the layer throughout */
    e = compare("homogeneous (generic), 1.5 km", h, &g, 300, 0);
    CHECK(e.s_worst < 0.01);
    CHECK(e.t_worst < 1e-5); /* optical depth linear in distance: exact but for float storage */
    atmos_atmosphere_destroy(h);
}

/* Outside the grid: no answer. The same table on 1 and 2 threads. */
static void edges_and_threads(const atmos_atmosphere *a)
{
    atmos__aerial_grid g;
    frustum(&g, 1500, 10, 150, 0.3, 0.3, 30, 180, 9, 7, 12, 5000, 0);
    atmos__aerial p1, p2;
    memset(&p1, 0, sizeof p1), memset(&p2, 0, sizeof p2);
    CHECK(atmos__aerial_build(&p1, a, &g, 1));
    CHECK(atmos__aerial_build(&p2, a, &g, 2));
    const size_t nf = (size_t)g.nu * g.nv * g.nd * 3 * 4;
    CHECK(memcmp(p1.tab, p2.tab, sizeof(float) * nf) == 0);
    double S[3], T[3], back[3], side[3];
    for (int c = 0; c < 3; c++) back[c] = -g.fwd[c], side[c] = g.fwd[c] + 0.5 * g.right[c];
    atmos__normalize3(side);
    CHECK(!atmos__aerial_eval(&p1, g.fwd, 5001, S, T));
    CHECK(!atmos__aerial_eval(&p1, back, 100, S, T));
    CHECK(!atmos__aerial_eval(&p1, side, 100, S, T));
    CHECK(atmos__aerial_eval(&p1, g.fwd, 0, S, T));
    CHECK(S[0] == 0 && S[1] == 0 && S[2] == 0 && T[0] == 1 && T[1] == 1 && T[2] == 1);
    atmos__aerial_free(&p1), atmos__aerial_free(&p2);
}

/* A Gaussian blob of peak density 3e6 m^-3 (optical depth ~1 across with the test particle),
 * 640 m wide, centred at 1500 m, dist metres north of the origin. */
static atmos_volume *blob(double dist)
{
    enum { N = 32 };
    const double vox = 20.0;
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[1] = vd.dims[2] = N;
    vd.voxel_size_m = vox;
    vd.origin_m[0] = -N * vox / 2, vd.origin_m[1] = 1500 - N * vox / 2, vd.origin_m[2] = -dist - N * vox / 2;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(NULL, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(NULL, v, "cloud", "cloud", &f));
    static float buf[N * N * N];
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const double x = (i + 0.5 - N / 2.0) / (N / 2.0), y = (j + 0.5 - N / 2.0) / (N / 2.0),
                             z = (k + 0.5 - N / 2.0) / (N / 2.0), r2 = x * x + y * y + z * z;
                buf[(k * N + j) * N + i] = r2 < 0.8 ? (float)(3e6 * exp(-4 * r2) * (0.8 - r2) / 0.8) : 0.0f;
            }
    int off[3] = {0, 0, 0}, size[3] = {N, N, N};
    CHECK_OK(atmos_volume_set_dense(NULL, v, f, off, size, buf, 1.0f));
    CHECK_OK(atmos_volume_finalize(NULL, v));
    return v;
}

/* The volume's grid does not depend on the region rendered nor on the thread count: a
 * region of the frame (at eye_scale, and at full resolution) has the whole frame's values
 * (whole: the full-resolution frame, 2 threads), and one thread gives the same bytes. */
static void region_and_threads(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v,
                               const atmos_volume_optics *o, const atmos_image *whole, double eye_scale)
{
    atmos_plan_desc d;
    memset(&d, 0, sizeof d);
    d.optics = o;
    d.offset_given = 1; /* where atmos_render_slice leaves it */
    for (int pass = 0; pass < 3; pass++) {
        atmos_context_desc cd;
        atmos_context_defaults(&cd);
        cd.threads = pass == 2 ? 1 : 2;
        cd.log = NULL;
        atmos_context *c1 = NULL;
        CHECK_OK(atmos_context_create(&cd, &c1));
        atmos_plan *p = NULL;
        atmos_frame f;
        atmos_image *a = NULL, *b = NULL;
        CHECK_OK(atmos_plan_create(pass == 2 ? c1 : ctx, s, v, &d, &p));
        CHECK_OK(atmos_frame_from_scene(ctx, s, &f));
        if (pass == 1) f.eye_scale = eye_scale;
        CHECK_OK(atmos_plan_image_create(p, &f, &a));
        CHECK_OK(atmos_plan_image_create(p, &f, &b));
        const atmos_region reg = {21, 17, 45, 40};
        CHECK_OK(atmos_plan_render(p, &f, NULL, a, NULL));
        CHECK_OK(atmos_plan_render(p, &f, &reg, b, NULL)); /* kept image: render a fresh plan's region */
        atmos_plan_destroy(p);
        p = NULL;
        CHECK_OK(atmos_plan_create(ctx, s, v, &d, &p));
        for (size_t i = 0; i < (size_t)f.width * f.height * b->channels; i++) b->pixels[i] = -7.0f;
        CHECK_OK(atmos_plan_render(p, &f, &reg, b, NULL));
        int diff = 0;
        for (int y = reg.y0; y < reg.y1; y++)
            for (int x = reg.x0; x < reg.x1; x++)
                for (int c = 0; c < 4; c++) {
                    const size_t i = ((size_t)y * f.width + x) * 4 + c;
                    diff += a->pixels[i] != b->pixels[i];
                }
        CHECK_MSG(!diff, "pass %d: %d region values differ from the whole frame's", pass, diff);
        if (pass != 1)
            CHECK_MSG(!memcmp(a->pixels, whole->pixels, sizeof(float) * (size_t)f.width * f.height * 4),
                      "pass %d (%d threads): the frame differs from the 2-thread one", pass, cd.threads);
        atmos_image_destroy(a), atmos_image_destroy(b);
        atmos_plan_destroy(p);
        atmos_context_destroy(c1);
    }
}

/* The slice renderer's frame of the blob dist metres away under the spherical sky (sun
 * sun_el degrees high, 30 degrees left of the view): with the aerial-perspective volume
 * against the reference passes, which ask the atmosphere per pixel (and differ from the fast
 * passes by < 1e-5). Over the pixels the volume changes (the sky image differs), the RMS and
 * the largest relative difference per channel. */
static void frame_case(atmos_context *ctx, const test_optics *op, double dist, double sun_el)
{
    atmos_volume *v = blob(dist);
    atmos_scene s;
    atmos_scene_defaults(&s);
    s.width = s.height = 64;
    s.samples_per_pixel = 1;
    const double pos[3] = {0, 1500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    s.camera.look_at[0] = 0, s.camera.look_at[1] = 1500, s.camera.look_at[2] = -dist;
    s.camera.fov_deg = 2 * atan(600 / dist) * 57.29578;
    s.sun.from_time = 0;
    s.sun.elevation_deg = sun_el;
    s.sun.azimuth_deg = 330;
    s.wavelengths = ATMOS_WAVELENGTHS_RGB;
    s.atmosphere.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    s.atmosphere.ground_albedo = 0.3;
    s.slice.light_size = 96;
    s.slice.slices = 64;
    atmos_image *img[2] = {NULL, NULL}, *sky = NULL;
    for (int r = 0; r < 2; r++) {
        atmos_slice_settings ss;
        atmos_slice_defaults(&ss);
        ss.optics = &op->o;
        ss.reference = r;
        atmos_status st = atmos_render_slice(ctx, &s, v, &ss, &img[r], NULL);
        CHECK_MSG(st == ATMOS_OK, "render slice: %s", atmos_context_error(ctx));
    }
    s.renderer = ATMOS_RENDERER_SKY;
    CHECK_OK(atmos_render_sky(ctx, &s, &sky, NULL));
    double sum2 = 0, worst = 0;
    long cnt = 0;
    for (int p = 0; img[0] && img[1] && sky && p < s.width * s.height; p++)
        for (int c = 0; c < 3; c++) {
            const double a = img[0]->pixels[p * 4 + c], b = img[1]->pixels[p * 4 + c], k = sky->pixels[p * 4 + c];
            if (!(fabs(b - k) > 1e-6 * k)) continue; /* the volume leaves it alone */
            const double e = fabs(a - b) / b;
            sum2 += e * e, cnt++;
            worst = fmax(worst, e);
        }
    const double rms = cnt ? sqrt(sum2 / cnt) : 0;
    printf("frame, blob at %.0f m, sun %.0f deg: %ld pixel values changed by the volume, vs per-pixel air: rms %.4f %%, "
           "worst %.4f %%\n", dist, sun_el, cnt, 100 * rms, 100 * worst);
    CHECK(cnt > 300);
    CHECK(rms < 0.002 && worst < 0.01);
    s.renderer = ATMOS_RENDERER_SLICE;
    region_and_threads(ctx, &s, v, &op->o, img[0], 0.5);
    atmos_image_destroy(img[0]), atmos_image_destroy(img[1]), atmos_image_destroy(sky);
    atmos_volume_destroy(v);
}

int main(void)
{
    atmos_atmosphere *a = make(ATMOS_ATMOSPHERE_SPHERICAL);
    spherical_cases(a);
    from_space(a);
    edges_and_threads(a);
    generic_cases();
    budget();
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.threads = 2;
    cd.log = NULL;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    test_optics op;
    test_hg_optics(ctx, "hg07", 0.7, 0.95, 1, &op);
    frame_case(ctx, &op, 1000, 30);
    frame_case(ctx, &op, 12000, 4);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
    atmos_atmosphere_destroy(a);
    return test_summary("test_aerial");
}
