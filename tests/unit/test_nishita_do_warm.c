/* The Nishita renderer's discrete-ordinates field warm-started after a sun move (render/nishita_do.c,
 * the frame's warm_field; docs/lightfield.md "A discrete-ordinates field"): a dense ball lit by a
 * sun at 40 degrees, then the sun moved 2 degrees in azimuth in the same plan. Started from the
 * last sun's moments the solve takes fewer GMRES iterations than a fresh plan's for the same sun
 * and gives its image within the solver's tolerance, much closer than the first sun's image is
 * (so that the check can fail). With the atmosphere, the sun at 10 degrees then at -10 (no sunlight
 * reaches the ball): the warm-started field is 0 as the fresh one, not the last sun's moments swept
 * once more (a ghost of the last sun). Solved afresh after more moves (each plan's cells' medium
 * kept from its first sun) the image does not depend on the frames before it, to the bit. An optically thin ball
 * under the sky: 2 sweeps a wavelength (thin()); one 1000 times thinner: one source iteration a
 * wavelength instead of GMRES, afresh and warm-started (thinner()), always from 0 (the thinner ball
 * at sunset leaves no ghost either). The grey ball in a vacuum with the sky off takes the
 * fill's copy of the last wavelength's moments (nishita_do.c): its index phi[i - NK] wrapped round
 * as an unsigned for every i until 2026-12-06, which Clang's -fsanitize=pointer-overflow reports on
 * this test ("addition of unsigned offset ... overflowed") and GCC's sanitizer, the asan twin's, does
 * not. */
#include "test.h"
#include "test_optics.h"

#define N 24       /* voxels per axis */
#define VS 50.0    /* m */
#define SIGMA 1e-9 /* m^2 */

/* A ball of radius 10 voxels, tau optical depth per voxel (20 tau across), in a grid of N^3. */
static atmos_volume *ball(atmos_context *ctx, double tau)
{
    float *buf = calloc(N * N * N, sizeof(float));
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const double x = i + 0.5 - 0.5 * N, y = j + 0.5 - 0.5 * N, z = k + 0.5 - 0.5 * N;
                if (x * x + y * y + z * z < 100) buf[((size_t)k * N + j) * N + i] = (float)(tau / (SIGMA * VS));
            }
    const int dims[3] = {N, N, N};
    atmos_volume *v = test_cloud_volume(ctx, dims, VS, buf);
    free(buf);
    return v;
}

static double mean(const atmos_image *img)
{
    double s = 0;
    for (int i = 0; i < img->width * img->height * img->channels; i++) s += img->pixels[i];
    return s / (img->width * img->height * img->channels);
}

/* The mean absolute difference of a and b over b's mean. */
static double rel_diff(const atmos_image *a, const atmos_image *b)
{
    double s = 0;
    for (int i = 0; i < a->width * a->height * a->channels; i++) s += fabs(a->pixels[i] - b->pixels[i]);
    return s / (a->width * a->height * a->channels) / mean(b);
}

/* The GMRES iterations of the frame's field (the image's atmos:nishita metadata), -1 if none. */
static int iterations(const atmos_image *img)
{
    const char *m = atmos_image_get_meta(img, "atmos:nishita"), *at = m ? strstr(m, "directions, ") : NULL;
    int it = -1;
    if (!at || sscanf(at, "directions, %d GMRES", &it) != 1) return -1;
    return it;
}

/* The sweeps of the frame's field (the image's atmos:nishita metadata), -1 if none. */
static int sweeps(const atmos_image *img)
{
    const char *m = atmos_image_get_meta(img, "atmos:nishita"), *at = m ? strstr(m, "GMRES iterations, ") : NULL;
    int n = -1;
    if (!at || sscanf(at, "GMRES iterations, %d sweeps", &n) != 1) return -1;
    return n;
}

/* The bound on the error that the frame's field gives with source iterations (the image's
 * atmos:nishita metadata: "(k source iterations, relative error at most B)"), -1 if none. */
static double source_bound(const atmos_image *img)
{
    const char *m = atmos_image_get_meta(img, "atmos:nishita"), *at = m ? strstr(m, "sweeps (") : NULL;
    int k = 0;
    double b = -1;
    if (!at || sscanf(at, "sweeps (%d source iterations, relative error at most %lf", &k, &b) != 2) return -1;
    return k == 1 ? b : -1;
}

/* The largest absolute difference of a and b. */
static double max_diff(const atmos_image *a, const atmos_image *b)
{
    double m = 0;
    for (int i = 0; i < a->width * a->height * a->channels; i++) m = fmax(m, fabs(a->pixels[i] - b->pixels[i]));
    return m;
}

/* Renders frame f (its sun sun_el degrees high, sun_az in azimuth) with plan p into a new image. */
static atmos_image *frame(atmos_context *ctx, atmos_plan *p, const atmos_scene *s, double sun_el, double sun_az,
                          int warm)
{
    atmos_scene t = *s;
    t.sun.elevation_deg = sun_el, t.sun.azimuth_deg = sun_az;
    atmos_frame f;
    atmos_image *img = NULL;
    CHECK_OK(atmos_frame_from_scene(ctx, &t, &f));
    f.warm_field = warm;
    CHECK_OK(atmos_plan_image_create(p, &f, &img));
    if (img) CHECK_MSG(atmos_plan_render(p, &f, NULL, img, NULL) == ATMOS_OK, "render: %s", atmos_context_error(ctx));
    return img;
}

/* With the atmosphere (scene s's, else s): the sun at 10 degrees, then at -10 warm-started and
 * afresh; the two images of the sun below the horizon must be the same, within rel times the
 * day's mean (0: to the bit). */
static void sunset(atmos_context *ctx, const atmos_scene *s, atmos_volume *v, const atmos_plan_desc *pd, double rel)
{
    atmos_scene t = *s, d0;
    atmos_scene_defaults(&d0);
    t.atmosphere = d0.atmosphere;
    atmos_plan *p = NULL, *q = NULL;
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &p));
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &q));
    if (p && q) {
        atmos_image *day = frame(ctx, p, &t, 10, 0, 1), *warm = frame(ctx, p, &t, -10, 0, 1),
                    *fresh = frame(ctx, q, &t, -10, 0, 0);
        if (day && warm && fresh) {
            const double dw = max_diff(warm, fresh);
            printf("  sun at 10 then -10 degrees with the atmosphere: mean %.3e at 10 degrees; at -10, warm %.3e, "
                   "fresh %.3e, largest difference %.1e\n",
                   mean(day), mean(warm), mean(fresh), dw);
            CHECK(mean(day) > 0);
            CHECK(dw <= rel * mean(day));
        } else
            CHECK(0);
        atmos_image_destroy(day), atmos_image_destroy(warm), atmos_image_destroy(fresh);
    }
    atmos_plan_destroy(p), atmos_plan_destroy(q);
}

/* An optically thin ball (1e-4 a voxel) under the atmosphere's sky (its light differs per
 * wavelength: the three wavelengths solved): the first wavelength, started from 0, converges in one
 * GMRES iteration, so the others start from 0 too, 2 sweeps a wavelength (the source's and one
 * iteration's; from the first one's solution times the ratio of the light they took 3: its
 * residual's sweep, then still one iteration). */
static void thin(atmos_context *ctx, const atmos_scene *s, const atmos_plan_desc *pd)
{
    atmos_scene t = *s, d0;
    atmos_scene_defaults(&d0);
    t.atmosphere = d0.atmosphere, t.nishita.sky = 1;
    atmos_volume *v = ball(ctx, 1e-4);
    atmos_plan *p = NULL;
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &p));
    atmos_image *img = p ? frame(ctx, p, &t, 40, 0, 0) : NULL;
    if (img) {
        const int it = iterations(img), sw = sweeps(img);
        printf("  thin ball under the sky: %d GMRES iterations, %d sweeps (3 wavelengths), mean %.3e\n", it, sw,
               mean(img));
        CHECK(mean(img) > 0);
        CHECK(it == 3);
        CHECK(sw == 6); /* 8 when the second and third started from the first one's solution */
    } else
        CHECK(0);
    atmos_image_destroy(img);
    atmos_plan_destroy(p);
    atmos_volume_destroy(v);
}

/* A ball a thousand times thinner (1e-7 a voxel) under the same sky: its scattering operator's
 * bound rho below the solver's tolerance, so one source iteration a wavelength replaces GMRES
 * (nishita_do.c, thin_sweeps): 3 sweeps afresh and 3 after the sun moved 2 degrees warm-started,
 * the warm frame's image within 1e-5 of a fresh plan's for the same sun (where the first sun's is
 * further off: the check can fail). */
static void thinner(atmos_context *ctx, const atmos_scene *s, const atmos_plan_desc *pd)
{
    atmos_scene t = *s, d0;
    atmos_scene_defaults(&d0);
    t.atmosphere = d0.atmosphere, t.nishita.sky = 1;
    atmos_volume *v = ball(ctx, 1e-7);
    atmos_plan *p = NULL, *q = NULL;
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &p));
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &q));
    atmos_image *first = p ? frame(ctx, p, &t, 40, 0, 0) : NULL, *warm = p ? frame(ctx, p, &t, 40, 2, 1) : NULL,
                *fresh = q ? frame(ctx, q, &t, 40, 2, 0) : NULL;
    if (first && warm && fresh) {
        const double dw = rel_diff(warm, fresh), df = rel_diff(first, fresh);
        printf("  a ball of 1e-7 a voxel under the sky: %d sweeps afresh, %d warm-started after the sun moved 2 "
               "degrees, that image %.1e from a fresh plan's (the first sun's %.1e)\n",
               sweeps(first), sweeps(warm), dw, df);
        CHECK(sweeps(first) == 3 && sweeps(warm) == 3 && sweeps(fresh) == 3);
        /* no residual is computed: the metadata gives the bound rho on the error, not a residual of 0 */
        const double b = source_bound(fresh);
        printf("  its field's metadata: one source iteration, relative error at most %.1e\n", b);
        CHECK(b > 0 && b <= 1e-3);
        CHECK(mean(fresh) > 0 && dw < 1e-5 && df > 10 * dw);
    } else
        CHECK(0);
    atmos_image_destroy(first), atmos_image_destroy(warm), atmos_image_destroy(fresh);
    atmos_plan_destroy(p), atmos_plan_destroy(q);
    atmos_volume_destroy(v);
}

/* The dense ball under the sky (the three wavelengths solved, none a copy of another), the sun moved
 * 2 degrees: warm-started, the second and third wavelengths start from their own last fields plus
 * the ratio of the light times the first one's change, and take one GMRES iteration each (from the
 * first one's new field times the ratio, as before 2026-12-07, they took as many as afresh: the
 * clouds are nearly but not quite grey, and that start carries the whole difference). The image
 * within the solver's tolerance of a fresh plan's. Warm, each wavelength's source is not swept on its
 * own (its norm estimated from the last solve's ratio, atmos__do_problem's kappa): a sweep an
 * iteration and one a wavelength for the first residual (the build before, one more a wavelength:
 * 12 sweeps for 6 iterations); afresh the source's sweep is the first residual. */
static void dense_sky(atmos_context *ctx, const atmos_scene *s, atmos_volume *v, const atmos_plan_desc *pd)
{
    atmos_scene t = *s, d0;
    atmos_scene_defaults(&d0);
    t.atmosphere = d0.atmosphere, t.nishita.sky = 1;
    atmos_plan *p = NULL, *q = NULL;
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &p));
    CHECK_OK(atmos_plan_create(ctx, &t, v, pd, &q));
    atmos_image *first = p ? frame(ctx, p, &t, 40, 0, 0) : NULL, *warm = p ? frame(ctx, p, &t, 40, 2, 1) : NULL,
                *fresh = q ? frame(ctx, q, &t, 40, 2, 0) : NULL;
    if (first && warm && fresh) {
        const int iw = iterations(warm), ifr = iterations(fresh);
        const double dw = rel_diff(warm, fresh), d0f = rel_diff(first, fresh);
        printf("  the dense ball under the sky, the sun moved 2 degrees: %d GMRES iterations (%d sweeps) "
               "warm-started, %d (%d) afresh; the image %.1e from the fresh one's, the first sun's %.1e\n",
               iw, sweeps(warm), ifr, sweeps(fresh), dw, d0f);
        CHECK(ifr >= 9 && iw >= 1 && iw <= ifr / 2);
        /* afresh the second and third wavelengths start from the first's field times the ratio: their
           sources swept, and their first residuals */
        CHECK(sweeps(warm) == iw + 3 && sweeps(fresh) == ifr + 3 + 2);
        CHECK(mean(fresh) > 0 && dw < 2e-4 && d0f > 5 * dw);
    } else
        CHECK(0);
    atmos_image_destroy(first), atmos_image_destroy(warm), atmos_image_destroy(fresh);
    atmos_plan_destroy(p), atmos_plan_destroy(q);
}

int main(void)
{
    atmos_context *ctx = NULL;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = 2;
    CHECK_OK(atmos_context_create(&d, &ctx));
    test_optics op;
    test_hg_optics(ctx, "hg", 0.85, 1.0, 0, &op);
    const atmos_volume_optics o = op.o;
    atmos_volume *v = ball(ctx, 1);
    atmos_scene s;
    test_vacuum_scene(&s, 40, 0);
    s.sun.irradiance_count = 1, s.sun.irradiance[0] = 1.0;
    s.width = s.height = 32;
    const double pos[3] = {0, 1000 + 0.5 * N * VS, 6000}, look[3] = {0, 1000 + 0.5 * N * VS, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s.camera);
    for (int a = 0; a < 3; a++) s.camera.look_at[a] = look[a];
    s.camera.fov_deg = 15;
    s.renderer = ATMOS_RENDERER_NISHITA;
    s.nishita.orders = 1, s.nishita.sky = 0;
    s.nishita.mc_kphotons = 0, s.nishita.do_field = 1, s.nishita.mc_delta_m = 1, s.nishita.mc_cell = 2;
    s.nishita.mc_lmax = 3;
    atmos_plan_desc pd;
    memset(&pd, 0, sizeof pd);
    pd.optics = &o, pd.offset_given = 1;
    atmos_plan *p = NULL, *q = NULL;
    CHECK_OK(atmos_plan_create(ctx, &s, v, &pd, &p));
    CHECK_OK(atmos_plan_create(ctx, &s, v, &pd, &q));
    if (p && q) {
        atmos_image *first = frame(ctx, p, &s, 40, 0, 1), *warm = frame(ctx, p, &s, 40, 2, 1),
                    *fresh = frame(ctx, q, &s, 40, 2, 0);
        /* the sun moved again, solved afresh in both plans (each keeping its cells' medium from its
           first sun, p's after warm-started frames): the same image to the bit */
        atmos_image *cold_p = frame(ctx, p, &s, 40, 4, 0), *cold_q = frame(ctx, q, &s, 40, 4, 0);
        if (first && warm && fresh && cold_p && cold_q) {
            printf("  sun moved again, solved afresh: largest difference between the two plans' %.1e\n",
                   max_diff(cold_p, cold_q));
            CHECK(max_diff(cold_p, cold_q) == 0);
            const int i0 = iterations(first), iw = iterations(warm), ifr = iterations(fresh);
            const double dw = rel_diff(warm, fresh), d0 = rel_diff(first, fresh);
            printf("  sun moved 2 degrees: GMRES iterations %d warm-started, %d afresh (the first sun %d); the "
                   "image %.1e from the fresh one's (mean absolute difference over its mean), the first sun's "
                   "%.1e\n",
                   iw, ifr, i0, dw, d0);
            CHECK(ifr > 0 && iw >= 0 && iw < ifr);
            CHECK(mean(fresh) > 0);
            CHECK(dw < 2e-4); /* measured 1.2e-5 */
            CHECK(d0 > 5 * dw);
        } else
            CHECK(0);
        atmos_image_destroy(first), atmos_image_destroy(warm), atmos_image_destroy(fresh);
        atmos_image_destroy(cold_p), atmos_image_destroy(cold_q);
    }
    atmos_plan_destroy(p), atmos_plan_destroy(q);
    sunset(ctx, &s, v, &pd, 1e-6);
    dense_sky(ctx, &s, v, &pd);
    /* the same with the thinner ball: its source iterations start from 0, not from the last sun's
       moments, so no ghost of the day is left at night: the fresh plan's bytes (from the last
       sun's moments 2e-20 off) */
    atmos_volume *vt = ball(ctx, 1e-7);
    sunset(ctx, &s, vt, &pd, 0);
    atmos_volume_destroy(vt);
    thin(ctx, &s, &pd);
    thinner(ctx, &s, &pd);
    atmos_volume_destroy(v);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
    return test_summary("test_nishita_do_warm");
}
