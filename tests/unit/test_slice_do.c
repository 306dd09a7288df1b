/* The slice renderer with the discrete-ordinates field ("slice": {"do": true}; render/slice_do.c,
 * docs/lightfield.md "The discrete-ordinates field in the slice renderer"): the first order in the
 * delta-M scaled medium (low albedo's passes with sigma_t*) plus the Nishita renderer's
 * discrete-ordinates field of the orders >= 2 toward the eye.
 *  - A wide uniform slab (HG 0.85, albedo 1, a vacuum, the sun at the zenith) of optical depth
 *    1, 4 and 16, its reflected radiance at view cosines 0.9 and 0.6 against the independent
 *    adding-doubling solver (path_ad.h); the first order alone (low albedo) is far off at 4 and
 *    16, so the check can fail. Beside it the same slab as the field's own approximation would
 *    give it solved exactly (adding-doubling with delta-M of degree 3 and the full phase's first
 *    order, test_ad_tms): at depths 1 and 4 the field within 5 points of that, so that what the
 *    bounds allow is its degree's truncation (-5.5 / -13.3 % at depth 1) and not its sweeps'.
 *  - The forward lobe: the slab of depth 4 seen from below 10-25 degrees from the sun, within 15 %
 *    of adding-doubling (TMS's first order, the renderer's before 2026-12-06, +94 % at 10 degrees),
 *    and the same by the Nishita renderer with its do field (the same first order of two populations).
 *  - Optically thick cells (a slab of depth 64, the field's cells of 2 and 6 voxels) against
 *    adding-doubling: the sweeps' step scheme alone was 10-29 % dark there.
 *  - Lit from behind: the slab of depth 4, 16 and 64 seen from below, its transmitted radiance
 *    against adding-doubling (two known excesses bounded: near the sun's direction and depth 64).
 *  - Nothing counted twice in thin media: a slab of optical depth 0.02, mostly the first order,
 *    within 3 % of adding-doubling.
 *  - The reference (scalar) eye pass reads the same field: its image within 0.1 % of the fast one's.
 *  - The same bytes with 1 and 2 threads.
 *  - The viewer's preview (hold_field) while the sun moves keeps the last sun's field: no solve,
 *    the image that of the last sun's field; the next frame without it solves for its sun. */
#include "test.h"
#include "test_optics.h"
#include "test_slab.h"

#define G 0.85

/* The slab (test_slab.h) seen at mu, the slice renderer with "do" (or, do 0, low albedo without
 * xi: the first order alone), the field's cells of cell voxels. */
static void scene(atmos_scene *s, double mu, int do_field, int cell)
{
    test_slab_scene(s, mu);
    s->renderer = ATMOS_RENDERER_SLICE;
    s->slice.do_field = do_field, s->slice.low_albedo = !do_field;
    s->slice.xi = 0; /* Riley's xi is not single scattering (and "do" does not use it) */
    s->nishita.mc_cell = cell;
}

/* The image of the slab of optical depth tau seen at mu, with "do" (cells of cell voxels) or the
 * first order alone. */
static double mean_cell(atmos_context *ctx, const test_optics *op, const atmos_volume *v, double mu, int do_field,
                        int cell)
{
    atmos_scene s;
    scene(&s, mu, do_field, cell);
    atmos_image *img = test_plan_frame(ctx, &s, v, &op->o);
    CHECK(img != NULL);
    const double m = img ? test_image_mean(img) : 0;
    atmos_image_destroy(img);
    return m;
}

static double mean_of(atmos_context *ctx, const test_optics *op, const atmos_volume *v, double mu, int do_field)
{
    return mean_cell(ctx, op, v, mu, do_field, 2);
}

static void check_slabs(atmos_context *ctx, const test_optics *op)
{
    const double taus[3] = {1, 4, 16}, mus[2] = {0.9, 0.6};
    for (int t = TEST_SANITIZED; t < 3 - TEST_SANITIZED; t++) { /* the sanitizer copy: depth 4 alone */
        atmos_volume *v = test_slab(ctx, taus[t]);
        ad_result r;
        CHECK(ad_slab(taus[t], 1.0, G, 1.0, 32, &r));
        for (int a = 0; a < 2 && v; a++) {
            const double ref = test_ad_up(&r, mus[a]), m = mean_of(ctx, op, v, mus[a], 1),
                         m1 = mean_of(ctx, op, v, mus[a], 0), m3 = test_ad_tms(taus[t], G, 3, mus[a], 0);
            printf("  slab tau %g, view mu %.2f: adding-doubling %.4f; first order (low albedo) %.4f (%+.1f %%); "
                   "slice with do %.4f (%+.1f %%); degree 3 solved exactly %.4f (%+.1f %%)\n",
                   taus[t], mus[a], ref, m1, 100 * (m1 / ref - 1), m, 100 * (m / ref - 1), m3, 100 * (m3 / ref - 1));
            CHECK(fabs(m / ref - 1) < (t == 1 ? 0.05 : t == 0 ? 0.15 : 0.1));
            if (t > 0) CHECK(fabs(m1 / ref - 1) > 0.5);
            /* the field's own error (its sweeps, quadrature and grid) beside its degree's at depths
               1 and 4: within 5 points (measured +3.6 / +1.6 and -0.5 / -0.4; the diamond in every
               cell -3.5 / -4.3 and -5.6 / -4.9, the field of degree 2 -6.2 / -1.2 at depth 1); not
               checked at 16 and 64, where the thick cells' sweeps themselves differ from it by more
               (-6.5 / -3.1 points at 16): there only the bound against adding-doubling above holds */
            if (t < 2) CHECK(fabs(m / m3 - 1) < 0.05);
        }
        atmos_volume_destroy(v);
    }
}

/* A thin slab: nothing counted twice, the first order's full phase: within 3 % of adding-doubling
 * (measured -2.1 %), nearer than the first order alone (-5.5 %: the second order's share at this
 * view, HG 0.85 seen at 127 degrees from the sun's light). */
static void check_thin(atmos_context *ctx, const test_optics *op)
{
    atmos_volume *v = test_slab(ctx, 0.02);
    ad_result r;
    CHECK(ad_slab(0.02, 1.0, G, 1.0, 32, &r));
    const double ref = test_ad_up(&r, 0.6), m = mean_of(ctx, op, v, 0.6, 1), m1 = mean_of(ctx, op, v, 0.6, 0);
    printf("  slab tau 0.02, view mu 0.60: adding-doubling %.6f; first order (low albedo) %.6f (%+.2f %%); slice with "
           "do %.6f (%+.2f %%)\n",
           ref, m1, 100 * (m1 / ref - 1), m, 100 * (m / ref - 1));
    CHECK(ref > 0 && fabs(m / ref - 1) < 0.03 && fabs(m / ref - 1) < fabs(m1 / ref - 1));
    atmos_volume_destroy(v);
}

/* Seen through the slab toward the sun: the camera dist m (900) below the slab's bottom centre, its view
 * at angle acos(mu) from the zenith (the scattering angle), the slab's diffusely transmitted
 * radiance; by the slice renderer with "do" or (nishita 1) the Nishita renderer with its do field
 * (the accuracy bench's nishita_do: the first order and the field, delta-M of degree 3). */
static double mean_below(atmos_context *ctx, const test_optics *op, const atmos_volume *v, double mu, int nishita,
                         double dist)
{
    atmos_scene s;
    scene(&s, mu, 1, 2);
    if (nishita) {
        s.renderer = ATMOS_RENDERER_NISHITA;
        s.nishita.orders = 1, s.nishita.sky = 0, s.nishita.mc_kphotons = 0, s.nishita.do_field = 1;
        s.nishita.mc_delta_m = 1, s.nishita.mc_lmax = 3;
    }
    const double bottom = 1000 + 0.5 * (NY - NS) * VS, st = sqrt(1 - mu * mu);
    const double pos[3] = {0, bottom - dist * mu, dist * st};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    s.camera.look_at[0] = 0, s.camera.look_at[1] = bottom, s.camera.look_at[2] = 0;
    s.camera.fov_deg = 1.5;
    atmos_image *img = test_plan_frame(ctx, &s, v, &op->o);
    CHECK(img != NULL);
    const double m = img ? test_image_mean(img) : 0;
    atmos_image_destroy(img);
    return m;
}

/* The forward lobe, toward the sun (the accuracy bench's cumulus with the sun in front: its
 * silver lining): the slab of optical depth 4 seen from below at 10, 15 and 25 degrees from the
 * sun, against adding-doubling, within 15 % (measured +6.4, -10.1, -13.7 %). The field's own
 * approximation solved exactly (delta-M of degree 3 and TMS's first order: test_ad_tms), which
 * the renderer drew before 2026-12-06 to 0.2 point, is +94, +37, -4 %: the full phase times the
 * whole delta-M beam counted the peak's light twice; now the light the peak has turned scatters
 * with delta-M's scaled phase (slice_do.c, sjob.two_pop). The Nishita renderer with its do field
 * (nishita_render.c, the same populations from dm_two_pop.c): +5.8, -10.5, -13.8 %; before, as TMS
 * solved exactly, +94.0, +37.3, -4.5 %. */
static void check_forward(atmos_context *ctx, const test_optics *op)
{
    const double mus[3] = {0.985, 0.966, 0.906}, tau = 4;
    atmos_volume *v = test_slab(ctx, tau);
    ad_result r;
    CHECK(ad_slab(tau, 1.0, G, 1.0, 32, &r));
    for (int a = TEST_SANITIZED; a < 3 && v; a++) { /* the sanitizer copy: 15 and 25 degrees */
        const double ref = test_ad_down(&r, mus[a]), m = mean_below(ctx, op, v, mus[a], 0, 900),
                     mn = mean_below(ctx, op, v, mus[a], 1, 900), m3 = test_ad_tms(tau, G, 3, mus[a], 1);
        printf("  slab tau 4 seen from below at %.0f deg from the sun: adding-doubling %.5f; slice with do %.5f "
               "(%+.1f %%); Nishita with do %.5f (%+.1f %%); degree 3 solved exactly %.5f (%+.1f %%)\n",
               acos(mus[a]) * 57.29577951308232, ref, m, 100 * (m / ref - 1), mn, 100 * (mn / ref - 1), m3,
               100 * (m3 / ref - 1));
        CHECK(fabs(m / ref - 1) < 0.15);
        CHECK(fabs(mn / ref - 1) < 0.15);
    }
    atmos_volume_destroy(v);
}

/* Optically thick cells: a slab of optical depth 64 across its 12 voxels, the field's cells of 2
 * and 6 voxels (6 and 2 cells across it, 10.7 and 32 optical depths a cell, 5.1 and 15 after
 * delta-M), its reflected radiance at view cosines 0.9 and 0.6 against adding-doubling. The
 * sweeps' step scheme alone, whose numerical diffusion grows with a cell's optical depth, was
 * 19 and 10 % dark with cells of 2 voxels and 29 and 21 % with 6 (the rain's cumulus on the
 * bench: its deepest pixels 16 % dark with the sun behind); the weighted diamond in thick cells
 * -0.5 and +3.0 %, and +8.8 and +14.9 % with 6 (diamond difference overshoots in cells that
 * thick: within 16 % there, where the step scheme is not). */
static void check_thick_cells(atmos_context *ctx, const test_optics *op)
{
    const double mus[2] = {0.9, 0.6};
    const int cells[2] = {2, 6};
    atmos_volume *v = test_slab(ctx, 64);
    ad_result r;
    CHECK(ad_slab(64, 1.0, G, 1.0, 32, &r));
    for (int c = 0; c < 2 - TEST_SANITIZED && v; c++)
        for (int a = 0; a < 2; a++) {
            const double ref = test_ad_up(&r, mus[a]), m = mean_cell(ctx, op, v, mus[a], 1, cells[c]);
            printf("  slab tau 64, cells of %d voxels, view mu %.2f: adding-doubling %.4f; slice with do %.4f "
                   "(%+.1f %%)\n",
                   cells[c], mus[a], ref, m, 100 * (m / ref - 1));
            CHECK(fabs(m / ref - 1) < (c == 0 ? 0.05 : 0.16));
        }
    atmos_volume_destroy(v);
}

/* Lit from behind (the clouds and the rain with the sun in front): the slab of optical depth 4,
 * 16 and 64 seen from below, the sun at the zenith above it, at view cosines 0.98 (11.5 degrees
 * from the sun), 0.9 and 0.6 looking up, its diffusely transmitted radiance against
 * adding-doubling (cells of 2 voxels). Measured 2026-12-06 with the first order's two
 * populations (check_forward): depths 4 and 16 within -12.8 ... +3.2 % (depth 4 at 0.9, 26 degrees
 * from the sun, -12.8 %: the turned light's lost forward lobe, as check_forward's -10 ... -14 %;
 * before the two populations, depth 4 at 0.98 was +73 %), bounded at 15 % as check_forward is;
 * depth 64 +23 ... +31 %, a known excess bounded here so that it cannot grow unseen (cells of
 * 10.7 optical depths; cells of 1 voxel +9 / +11 %, of 4 +120 / +145 %): most of it the field's
 * half-empty cell at the slab's face, its mean over the slab's half read as the face's
 * (docs/accuracy.md, "The rain in front: the thick voxels' exit skin": that cell moved to its
 * centre along the field's gradient +7.2 % at all three, but the rain's deep bins unmoved and the
 * reflected checks darker, so not kept). */
static void check_transmitted(atmos_context *ctx, const test_optics *op)
{
    const double taus[3] = {4, 16, 64}, mus[3] = {0.98, 0.9, 0.6};
    for (int t = 0; t < 3 - 2 * TEST_SANITIZED; t++) {
        atmos_volume *v = test_slab(ctx, taus[t]);
        ad_result r;
        CHECK(ad_slab(taus[t], 1.0, G, 1.0, 32, &r));
        for (int a = 0; a < 3 && v; a++) {
            const double m = mean_below(ctx, op, v, mus[a], 0, 1000), ref = test_ad_down(&r, mus[a]), e = m / ref - 1;
            printf("  slab tau %g seen from below, view mu %.2f: adding-doubling %.5f; slice with do %.5f (%+.1f %%)\n",
                   taus[t], mus[a], ref, m, 100 * e);
            CHECK(t == 2 ? e > 0 && e < 0.35 : fabs(e) < 0.15);
        }
        atmos_volume_destroy(v);
    }
}

/* A thick layer at a low sun: a layer of optical depth 64 (400 m, voxels 8 to 15 of 24 rows),
 * the sun at 22 degrees elevation, seen from near the zenith (mu 0.995, where the reflected
 * radiance hardly depends on the azimuth: adding-doubling's azimuthal mean is the reference),
 * the render grid at full resolution (8 voxels of 8 optical depths across the layer, cells of 2)
 * and at grid_max_dim 14 (one voxel of 64 optical depths, cells of 1). The field's first order
 * taken along the chord through each voxel's centre along the sun's dominant axis, here a
 * horizontal one, lit the layer's voxels through the layer, not through their top faces: -87 %
 * and -94 % against adding-doubling; through the sunward faces -26 % and -89 % (measured; the
 * rest: a thick voxel's one radiance, its source spread over its depth and its top skin not
 * resolved: 4 voxels across it -51 %, 2 -77 %; docs/slice.md, "Why the deck is dark"). */
static void check_low_sun(atmos_context *ctx, const test_optics *op)
{
    enum { NYL = 24 };
    const double tau = 64, mu = 0.995, el = 22, top = 1000 + 16 * VS, D = 20000, st = sqrt(1 - mu * mu);
    float *buf = calloc((size_t)NX * NYL * NX, sizeof(float));
    for (int k = 0; buf && k < NX; k++)
        for (int j = 8; j < 16; j++)
            for (int i = 0; i < NX; i++) buf[((size_t)k * NYL + j) * NX + i] = (float)(tau / (SIGMA * VS * 8));
    const int dims[3] = {NX, NYL, NX};
    atmos_volume *v = buf ? test_cloud_volume(ctx, dims, VS, buf) : NULL;
    free(buf);
    ad_result r;
    CHECK(ad_slab(tau, 1.0, G, sin(el * 3.14159265358979323846 / 180), 32, &r));
    const double ref = test_ad_up(&r, mu);
    double m[2] = {0, 0};
    for (int c = 0; c < 2 && v; c++) {
        atmos_scene s;
        scene(&s, mu, 1, c == 0 ? 2 : 1);
        s.sun.elevation_deg = el;
        s.slice.grid_max_dim = c == 0 ? 256 : 14;
        const double pos[3] = {0, top + D * mu, D * st};
        atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
        s.camera.look_at[0] = 0, s.camera.look_at[1] = top, s.camera.look_at[2] = 0;
        s.camera.fov_deg = 1.5;
        atmos_image *img = test_plan_frame(ctx, &s, v, &op->o);
        CHECK(img != NULL);
        m[c] = img ? test_image_mean(img) : 0;
        atmos_image_destroy(img);
    }
    printf("  layer tau 64 at a 22 degree sun, view mu %.3f: adding-doubling %.4f; slice with do, 8 voxels across "
           "it %.4f (%+.1f %%), one voxel %.4f (%+.1f %%)\n",
           mu, ref, m[0], 100 * (m[0] / ref - 1), m[1], 100 * (m[1] / ref - 1));
    CHECK(ref > 0 && m[0] / ref > 0.6 && m[1] / ref > 0.08);
    atmos_volume_destroy(v);
}

/* The reference passes (atmos_plan_desc.reference) against the fast ones, the slab of depth 4. */
static void check_reference(atmos_context *ctx, const test_optics *op)
{
    atmos_volume *v = test_slab(ctx, 4);
    atmos_scene s;
    scene(&s, 0.6, 1, 2);
    atmos_image *img[2] = {NULL, NULL};
    for (int r = 0; r < 2 && v; r++) {
        atmos_plan_desc d;
        memset(&d, 0, sizeof d);
        d.optics = &op->o, d.offset_given = 1, d.reference = r;
        atmos_plan *p = NULL;
        atmos_frame f;
        CHECK_OK(atmos_plan_create(ctx, &s, v, &d, &p));
        if (p && atmos_frame_from_scene(ctx, &s, &f) == ATMOS_OK && atmos_plan_image_create(p, &f, &img[r]) == ATMOS_OK)
            CHECK_OK(atmos_plan_render(p, &f, NULL, img[r], NULL));
        atmos_plan_destroy(p);
    }
    CHECK(img[0] && img[1]);
    if (img[0] && img[1]) {
        const double a = test_image_mean(img[0]), b = test_image_mean(img[1]);
        printf("  slab tau 4, view mu 0.60: fast passes %.5f, reference passes %.5f (%+.3f %%)\n", a, b,
               100 * (b / a - 1));
        CHECK(a > 0 && fabs(b / a - 1) < 1e-3);
    }
    atmos_image_destroy(img[0]), atmos_image_destroy(img[1]);
    atmos_volume_destroy(v);
}

/* The same image, byte for byte, with 1 and 2 threads. */
static void check_threads(const test_optics *op)
{
    atmos_image *img[2] = {NULL, NULL};
    for (int t = 0; t < 2; t++) {
        atmos_context *ctx = NULL;
        atmos_context_desc d;
        atmos_context_defaults(&d);
        d.threads = t + 1;
        CHECK_OK(atmos_context_create(&d, &ctx));
        atmos_volume *v = test_slab(ctx, 4);
        atmos_scene s;
        scene(&s, 0.6, 1, 2);
        img[t] = test_plan_frame(ctx, &s, v, &op->o);
        atmos_volume_destroy(v);
        atmos_context_destroy(ctx);
    }
    CHECK(img[0] && img[1]);
    if (img[0] && img[1]) {
        const size_t bytes = sizeof(float) * img[0]->width * img[0]->height * img[0]->channels;
        CHECK(test_image_mean(img[0]) > 0);
        CHECK(!memcmp(img[0]->pixels, img[1]->pixels, bytes));
    }
    atmos_image_destroy(img[0]), atmos_image_destroy(img[1]);
}

/* Renders the frame of sun elevation el (hold: hold_field) with plan p; its field's sweeps into
 * *sweeps, its mean into *mean. */
static void held_frame(atmos_context *ctx, atmos_plan *p, const atmos_scene *s, double el, int hold, int *sweeps,
                       double *mean)
{
    atmos_scene t = *s;
    t.sun.elevation_deg = el;
    atmos_frame f;
    atmos_image *img = NULL;
    atmos_plan_stats ps;
    CHECK_OK(atmos_frame_from_scene(ctx, &t, &f));
    f.hold_field = hold;
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    if (img) CHECK_OK(atmos_plan_render(p, &f, NULL, img, NULL));
    atmos_plan_get_stats(p, &ps);
    *sweeps = ps.slice.field_sweeps, *mean = img ? test_image_mean(img) : 0;
    atmos_image_destroy(img);
}

/* hold_field: the sun at the zenith, then held previews at 60 degrees, then the frame at 60 without
 * it: the held frames solve nothing, the last one does; the held image (the zenith's field) is
 * the same twice and differs from the solved one's at 60 degrees. */
static void check_hold(atmos_context *ctx, const test_optics *op)
{
    atmos_volume *v = test_slab(ctx, 4);
    atmos_scene s;
    scene(&s, 0.6, 1, 2);
    atmos_plan_desc d;
    memset(&d, 0, sizeof d);
    d.optics = &op->o, d.offset_given = 1;
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, &d, &p));
    if (p) {
        int s0, s1, s2, s3;
        double m0, m1, m2, m3;
        held_frame(ctx, p, &s, 90, 0, &s0, &m0);
        held_frame(ctx, p, &s, 60, 1, &s1, &m1);
        held_frame(ctx, p, &s, 60, 1, &s2, &m2);
        held_frame(ctx, p, &s, 60, 0, &s3, &m3);
        printf("  hold_field: sweeps %d at 90 degrees, %d and %d held at 60, %d at 60 after; means %.5f %.5f %.5f "
               "%.5f\n",
               s0, s1, s2, s3, m0, m1, m2, m3);
        CHECK(s0 > 0 && s1 == 0 && s2 == 0 && s3 > 0);
        CHECK(m1 == m2 && m1 != m3);
    }
    atmos_plan_destroy(p);
    atmos_volume_destroy(v);
}

int main(void)
{
    atmos_context *ctx = NULL;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 2;
    CHECK_OK(atmos_context_create(&d, &ctx));
    test_optics op;
    test_hg_optics(ctx, "hg", G, 1.0, 1, &op);
    check_slabs(ctx, &op);
    check_thin(ctx, &op);
    check_forward(ctx, &op);
    check_thick_cells(ctx, &op);
    check_transmitted(ctx, &op);
    if (!TEST_SANITIZED) check_low_sun(ctx, &op);
    check_reference(ctx, &op);
    check_threads(&op);
    check_hold(ctx, &op);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
    return test_summary("test_slice_do");
}
