/* The slice renderer's shadow of the volume on the air (light shafts, crepuscular rays;
 * src/render/slice_shadow.c, docs/slice.md "Light shafts") against a closed form.
 *
 * A slab of optical depth tau (100 m thick, 2 km x 10 km) 500 m above a horizontal ray at
 * 1000 m that runs under it from 0.5 to 10.5 km, the sun at the zenith. Single scattering of
 * the sun by the air along the ray at altitude y is P(90 deg) E(y) beta(y) T(t) dt; with the
 * air's albedo 1 the slab's shadow takes away P E (T(a) - T(b)) (1 - e^-tau), T the air's
 * transmittance from the eye to a = 0.5 km and b = 10.5 km, E the sunlight at the ray, all
 * from the atmosphere interface's own functions (as test_path.c's light shaft). The pixel
 * looks past the volume (its ray never enters the box), so before the shadow existed it was
 * the sky image exactly, the same as with the slab removed. A pixel looking the other way
 * (away from the shadow) must be unchanged bit for bit, the option off must give the
 * unshadowed sky, and 1 and 2 threads the same bytes. Riley's air and a homogeneous layer.
 * And the ground in the slab's shadow loses the sunlight the slab takes (check_ground), the
 * flat ground's and a planet's. */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static char cache_dir[1024];

static atmos_context *make_ctx(int threads)
{
    return test_context(threads, cache_dir);
}

#define SLAB_Y 1500.0 /* the slab's bottom; the ray runs 500 m below it */
#define RAY_Y 1000.0

/* The slab: 20 x 1 x 100 voxels of 100 m, x in [-1, 1] km, z in [-10.5, -0.5] km; tau across
 * its thickness (0: an empty volume). */
static atmos_volume *slab(atmos_context *ctx, double tau)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = 20, vd.dims[1] = 1, vd.dims[2] = 100;
    vd.voxel_size_m = 100;
    vd.origin_m[0] = -1000, vd.origin_m[1] = SLAB_Y, vd.origin_m[2] = -10500;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "hg", &f));
    static float buf[20 * 100];
    for (int i = 0; i < 20 * 100; i++) buf[i] = (float)(tau / (1e-9 * 100));
    if (tau > 0) {
        int off[3] = {0, 0, 0}, size[3] = {20, 1, 100};
        CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    }
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

/* 5 x 5 pixels (the centre pixel's ray is the camera's axis), 2 degrees, from (0, RAY_Y, 0)
 * toward -z (under the slab) or +z (away from it). */
static void scene_for(atmos_scene *s, int kind, int away)
{
    atmos_scene_defaults(s);
    s->atmosphere.kind = kind;
    s->atmosphere.thickness_m = 3000;
    if (kind == ATMOS_ATMOSPHERE_HOMOGENEOUS) s->atmosphere.beta_sl_550 = 1e-4; /* haze */
    s->atmosphere.ground_albedo = 0;
    s->width = s->height = 5;
    s->samples_per_pixel = 1;
    const double pos[3] = {0, RAY_Y, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = RAY_Y, s->camera.look_at[2] = away ? 1000 : -1000;
    s->camera.fov_deg = 2;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 90;
    s->sun.azimuth_deg = 0;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    s->slice.light_size = 64;
    s->slice.slices = 64; /* the slab itself is not looked at */
}

static atmos_image *render(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const test_optics *op)
{
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    ss.optics = &op->o;
    atmos_image *img = NULL;
    atmos_status st = atmos_render_slice(ctx, s, v, &ss, &img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render slice: %s", atmos_context_error(ctx));
    return img;
}

/* One frame of a fresh plan of s with its "air_shadows" set to air (5 x 5 pixels). */
static atmos_image *plan_frame(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v,
                               const atmos_plan_desc *pd, int air)
{
    atmos_scene sc = *s;
    sc.renderer = ATMOS_RENDERER_SLICE;
    sc.slice.air_shadows = air;
    atmos_plan *plan = NULL;
    atmos_frame f;
    atmos_image *img = NULL;
    if (atmos_plan_create(ctx, &sc, v, pd, &plan) == ATMOS_OK && atmos_frame_from_scene(ctx, &sc, &f) == ATMOS_OK &&
        atmos_plan_image_create(plan, &f, &img) == ATMOS_OK && atmos_plan_render(plan, &f, NULL, img, NULL) != ATMOS_OK)
        atmos_image_destroy(img), img = NULL;
    atmos_plan_destroy(plan);
    return img;
}

/* Two frames of one plan: without the shadows (atmos_frame.no_air_shadows) the bytes of a plan
 * with "air_shadows" false, then with them those of a fresh plan with it true, and the two
 * different (the shadow takes something). */
static int frames_without_then_with(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v,
                                    const test_optics *op)
{
    atmos_plan_desc pd;
    memset(&pd, 0, sizeof pd);
    pd.optics = &op->o;
    atmos_image *off = plan_frame(ctx, s, v, &pd, 0), *on = plan_frame(ctx, s, v, &pd, 1), *a = NULL, *b = NULL;
    atmos_scene sc = *s;
    sc.renderer = ATMOS_RENDERER_SLICE;
    s = &sc;
    atmos_plan *plan = NULL;
    atmos_frame f;
    int ok = off && on && atmos_plan_create(ctx, s, v, &pd, &plan) == ATMOS_OK &&
             atmos_frame_from_scene(ctx, s, &f) == ATMOS_OK && atmos_plan_image_create(plan, &f, &a) == ATMOS_OK &&
             atmos_plan_image_create(plan, &f, &b) == ATMOS_OK;
    f.no_air_shadows = 1;
    ok = ok && atmos_plan_render(plan, &f, NULL, a, NULL) == ATMOS_OK;
    f.no_air_shadows = 0;
    ok = ok && atmos_plan_render(plan, &f, NULL, b, NULL) == ATMOS_OK;
    const size_t bytes = ok ? sizeof(float) * 25 * (size_t)a->channels : 0;
    const int same = ok && !memcmp(a->pixels, off->pixels, bytes) && !memcmp(b->pixels, on->pixels, bytes) &&
                     memcmp(a->pixels, b->pixels, bytes) != 0;
    if (!same && ok)
        printf("plan frames: A=off %d, B=on %d, A!=B %d; centre green A %g B %g off %g on %g\n",
               !memcmp(a->pixels, off->pixels, bytes), !memcmp(b->pixels, on->pixels, bytes),
               memcmp(a->pixels, b->pixels, bytes) != 0, a->pixels[12 * a->channels + 1], b->pixels[12 * a->channels + 1],
               off->pixels[12 * a->channels + 1], on->pixels[12 * a->channels + 1]);
    atmos_image_destroy(a), atmos_image_destroy(b), atmos_image_destroy(off), atmos_image_destroy(on);
    atmos_plan_destroy(plan);
    return same;
}

/* The closed form of what the shadow takes from the centre pixel, per channel. */
static void closed_form(atmos_context *ctx, const atmos_scene *s, double tau, double *D)
{
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, s, &wl));
    atmos_atmosphere *sky = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &s->atmosphere, &wl, &sky));
    const double pos[3] = {0, RAY_Y, 0}, up[3] = {0, 1, 0}, dir[3] = {0, 0, -1};
    double E[ATMOS_MAX_WAVELENGTHS], Ta[ATMOS_MAX_WAVELENGTHS], Tb[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_sunlight(sky, pos, up, E);
    atmos_atmosphere_transmittance(sky, pos, dir, 500, Ta);
    atmos_atmosphere_transmittance(sky, pos, dir, 10500, Tb);
    const double P = atmos_atmosphere_phase(sky, pos, 0.0);
    for (int c = 0; c < 3; c++) D[c] = P * E[c] * (Ta[c] - Tb[c]) * (1 - exp(-tau));
    atmos_atmosphere_destroy(sky);
}

static void check_kind(int kind, const char *name)
{
    atmos_context *ctx = make_ctx(2);
    test_optics op;
    test_hg_optics(ctx, "hg", 0.0, 1e-6, 1, &op);
    atmos_volume *none = slab(ctx, 0);
    atmos_scene s;
    scene_for(&s, kind, 0);
    atmos_image *open = render(ctx, &s, none, &op);
    const int C = open->channels, mid = (2 * 5 + 2) * C;
    static const double taus[2] = {50, 0.5};
    for (int i = 0; i < 2; i++) {
        atmos_volume *v = slab(ctx, taus[i]);
        atmos_image *img = render(ctx, &s, v, &op);
        double D[3];
        closed_form(ctx, &s, taus[i], D);
        for (int c = 0; c < 3; c++) {
            const double got = open->pixels[mid + c] - img->pixels[mid + c];
            printf("%s, tau %g, channel %d: unshadowed %.6g, the shadow takes %.6g, closed form %.6g (%+.2f %%)\n", name,
                   taus[i], c, open->pixels[mid + c], got, D[c], 100 * (got / D[c] - 1));
            /* opaque: the shadow's two ends are each widened by about half a render voxel (the
             * render grid's padding: its interpolant falls to zero over one voxel outside the
             * box), where the optical depth ramps from 50 to 0 and 1 - e^-tau stays near 1:
             * +1.0 % to +1.5 % measured; at tau 0.5 the ramps cancel to first order (+0.2 %) */
            const double tol = taus[i] > 5 ? 0.02 : 0.005;
            CHECK_MSG(fabs(got - D[c]) < tol * D[c], "%s tau %g channel %d: %.6g vs %.6g", name, taus[i], c, got, D[c]);
        }
        if (i == 0) {
            /* the option off: the air unshadowed, the sky image as without the slab */
            atmos_scene so = s;
            so.slice.air_shadows = 0;
            atmos_image *off = render(ctx, &so, v, &op);
            CHECK(memcmp(off->pixels, open->pixels, sizeof(float) * 25 * C) == 0);
            atmos_image_destroy(off);
            /* a frame that leaves them out (the viewer's moving preview), then one with them */
            CHECK(frames_without_then_with(ctx, &s, v, &op));
            /* one thread: the same bytes */
            atmos_context *c1 = make_ctx(1);
            atmos_image *one = render(c1, &s, v, &op);
            CHECK(memcmp(one->pixels, img->pixels, sizeof(float) * 25 * C) == 0);
            atmos_image_destroy(one);
            atmos_context_destroy(c1);
            /* looking away from the shadow: unchanged bit for bit */
            atmos_scene sa;
            scene_for(&sa, kind, 1);
            atmos_image *a0 = render(ctx, &sa, none, &op), *a1 = render(ctx, &sa, v, &op);
            CHECK(memcmp(a0->pixels, a1->pixels, sizeof(float) * 25 * C) == 0);
            atmos_image_destroy(a0), atmos_image_destroy(a1);
        }
        atmos_image_destroy(img);
        atmos_volume_destroy(v);
    }
    atmos_image_destroy(open);
    atmos_volume_destroy(none);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
}

/* The ground in the slab's shadow: a ray 45 degrees down from (0, RAY_Y, 0) toward -z meets
 * the ground at z = -RAY_Y, under the slab. The sunlight the slab takes from the ground there
 * is albedo / pi E(ground) T(eye -> ground) (1 - e^-tau) (the sun at the zenith); the air's
 * share is the same with and without the ground's albedo, so the difference between what the
 * shadow takes at albedo 0.3 and at albedo 0 is the ground's alone. */
static void check_ground(int kind, const char *name)
{
    atmos_context *ctx = make_ctx(2);
    test_optics op;
    test_hg_optics(ctx, "hg", 0.0, 1e-6, 1, &op);
    atmos_volume *none = slab(ctx, 0), *v = slab(ctx, 50);
    double took[2][3];
    atmos_scene s;
    for (int a = 0; a < 2; a++) {
        scene_for(&s, kind, 0);
        s.camera.look_at[1] = 0, s.camera.look_at[2] = -RAY_Y;
        s.atmosphere.ground_albedo = a ? 0.3 : 0.0;
        atmos_image *open = render(ctx, &s, none, &op), *img = render(ctx, &s, v, &op);
        const int C = open->channels, mid = (2 * 5 + 2) * C;
        for (int c = 0; c < 3; c++) took[a][c] = open->pixels[mid + c] - img->pixels[mid + c];
        atmos_image_destroy(open), atmos_image_destroy(img);
    }
    atmos_wavelengths wl;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    atmos_atmosphere *sky = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &s.atmosphere, &wl, &sky));
    const double eye[3] = {0, RAY_Y, 0}, g[3] = {0, 0, -RAY_Y}, up[3] = {0, 1, 0};
    const double dir[3] = {0, -sqrt(0.5), -sqrt(0.5)};
    double E[ATMOS_MAX_WAVELENGTHS], T[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_sunlight(sky, g, up, E);
    atmos_atmosphere_transmittance(sky, eye, dir, RAY_Y * sqrt(2.0), T);
    for (int c = 0; c < 3; c++) {
        const double want = 0.3 / 3.14159265358979323846 * E[c] * T[c] * (1 - exp(-50.0)), got = took[1][c] - took[0][c];
        printf("%s, the ground in the shadow, channel %d: the shadow takes %.6g from it, closed form %.6g (%+.2f %%)\n",
               name, c, got, want, 100 * (got / want - 1));
        CHECK_MSG(fabs(got - want) < 0.01 * want, "%s ground channel %d: %.6g vs %.6g", name, c, got, want);
    }
    atmos_atmosphere_destroy(sky);
    atmos_volume_destroy(none), atmos_volume_destroy(v);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache");
    check_kind(ATMOS_ATMOSPHERE_RILEY, "Riley");
    check_kind(ATMOS_ATMOSPHERE_HOMOGENEOUS, "homogeneous layer");
    check_ground(ATMOS_ATMOSPHERE_RILEY, "Riley");
    check_ground(ATMOS_ATMOSPHERE_HOMOGENEOUS, "homogeneous layer");
    check_ground(ATMOS_ATMOSPHERE_SPHERICAL, "spherical");
    check_ground(ATMOS_ATMOSPHERE_DOBASHI, "Dobashi");
    return test_summary("test_slice_shafts");
}
