/* The volume's shadow on the air along the Nishita renderer's eye rays (nishita_air.c; the scene's
 * "air_shadows", as the slice renderer's slice_shadow.c). An opaque, black slab 2 km x 100 m x
 * 10 km (x from -1 to 1 km, y from 1500 to 1600 m, z from -10.5 to -0.5 km) under the sun at the
 * zenith in Riley's flat air (single scattering alone, in closed form); the eye at 1 km height
 * looks up into the slab's underside 8 km away, so its rays run in the slab's shadow from z =
 * -0.5 km on. The pixel is then the air's in-scatter from the eye to that point alone (the slab
 * sends nothing: black, opaque), S(t_a). Before the shadow was taken the Nishita renderer
 * added the air's in-scatter up to the slab unshadowed, about S(t_hit), 14 times as much here (with
 * the sun ahead of a cloud the air in front of it lies in its shadow: the rain case's deep pixels
 * +19 ... +36 % above the path tracer, docs/lightfield.md). With "air_shadows" off the pixel is
 * S(t_hit) again (the render grid's underside a little nearer). */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#define W 4
#define FOV 0.2

static void scene_for(atmos_scene *s, int air_shadows);

/* A ray that grazes the volume: the same slab 150 m above a level ray at 1550 m inside the
 * volume's box (its two lower layers of voxels empty), which never meets the slab (T = 1) but runs
 * in its shadow for 10 km. The renderer takes the air's shadow in proportion to the volume's
 * opacity along the ray, so that rays which miss the volume, whose air keeps the sky image's
 * unshadowed light, join those that graze it without a seam (4-6 % at the box's edge in Nishita's
 * Fig. 7(b) before): the pixel is the unshadowed one within 1 %. */
static void check_grazing(atmos_context *ctx, const test_optics *op)
{
    static float buf[20 * 3 * 100];
    for (int k = 0; k < 100; k++)
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 20; i++) buf[(k * 3 + j) * 20 + i] = j == 2 ? 1e10f : 0.0f;
    const int dims[3] = {20, 3, 100};
    const double org[3] = {-1000, 1500, -10500};
    atmos_volume *v = test_dense_volume(ctx, dims, 100, org, "cloud", "hg0", buf);
    atmos_image *img[2] = {NULL, NULL};
    for (int a = 0; a < 2 && v; a++) {
        atmos_scene s;
        scene_for(&s, a);
        s.camera.position[1] = 1550, s.camera.look_at[1] = 1550;
        img[a] = test_plan_frame_rows(ctx, &s, v, &op->o, 0, 0);
    }
    CHECK(img[0] && img[1]);
    for (int c = 0; c < 3 && img[0] && img[1]; c++) {
        double m[2] = {0, 0};
        for (int a = 0; a < 2; a++)
            for (int p = 0; p < W * W; p++) m[a] += img[a]->pixels[p * 4 + c] / (W * W);
        printf("channel %d, the grazing ray: air_shadows on %.5g, off %.5g\n", c, m[1], m[0]);
        CHECK_MSG(fabs(m[1] - m[0]) < 0.01 * m[0], "channel %d: a seam: %.5g against %.5g", c, m[1], m[0]);
    }
    atmos_image_destroy(img[0]), atmos_image_destroy(img[1]);
    atmos_volume_destroy(v);
}

static atmos_volume *slab(atmos_context *ctx)
{
    static float buf[20 * 100];
    for (int i = 0; i < 20 * 100; i++) buf[i] = 1e10f; /* sigma_t 10 per metre */
    const int dims[3] = {20, 1, 100};
    const double org[3] = {-1000, 1500, -10500};
    return test_dense_volume(ctx, dims, 100, org, "cloud", "hg0", buf);
}

static void scene_for(atmos_scene *s, int air_shadows)
{
    atmos_scene_defaults(s);
    s->atmosphere.kind = ATMOS_ATMOSPHERE_RILEY;
    s->atmosphere.thickness_m = 3000;
    s->atmosphere.ground_albedo = 0;
    s->width = s->height = W;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 90, s->sun.azimuth_deg = 0;
    const double pos[3] = {0, 1000, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = 1500, s->camera.look_at[2] = -8000;
    s->camera.fov_deg = FOV;
    s->renderer = ATMOS_RENDERER_NISHITA;
    s->nishita.orders = 1, s->nishita.sky = 0;
    test_nishita_paper(s);
    s->slice.air_shadows = air_shadows;
}

int main(void)
{
    atmos_context *ctx = test_context(2, NULL);
    test_optics op;
    test_hg_optics(ctx, "hg0", 0.0, 1e-4, 0, &op);
    atmos_volume *v = slab(ctx);
    atmos_scene s;
    scene_for(&s, 1);
    atmos_image *on = test_plan_frame_rows(ctx, &s, v, &op.o, 0, 0);
    scene_for(&s, 0);
    atmos_image *off = test_plan_frame_rows(ctx, &s, v, &op.o, 0, 0);
    atmos_wavelengths wl;
    atmos_atmosphere *atm = NULL;
    CHECK_OK(atmos_scene_wavelengths(ctx, &s, &wl));
    CHECK_OK(atmos_atmosphere_create(ctx, &s.atmosphere, &wl, &atm));
    if (!on || !off || !atm) {
        CHECK(0);
    } else {
        /* the central ray: up 500 m over 8 km; in the shadow from z = -500 m */
        const double pos[3] = {0, 1000, 0}, len = sqrt(500.0 * 500 + 8000.0 * 8000), up[3] = {0, 1, 0};
        const double d[3] = {0, 500 / len, -8000 / len}, ta = 500 / -d[2], thit = 8000 / -d[2];
        double Sa[ATMOS_MAX_WAVELENGTHS], Sh[ATMOS_MAX_WAVELENGTHS];
        atmos_atmosphere_inscatter(atm, pos, d, ta, up, Sa);
        atmos_atmosphere_inscatter(atm, pos, d, thit, up, Sh);
        for (int c = 0; c < 3; c++) {
            double m_on = 0, m_off = 0;
            for (int p = 0; p < W * W; p++) m_on += on->pixels[p * 4 + c] / (W * W), m_off += off->pixels[p * 4 + c] / (W * W);
            printf("channel %d: shadowed %.5g (the air to the shadow %.5g, %+.2f %% of the whole), unshadowed %.5g "
                   "(the air to the slab %.5g)\n",
                   c, m_on, Sa[c], 100 * (m_on - Sa[c]) / Sh[c], m_off, Sh[c]);
            CHECK_MSG(Sh[c] - Sa[c] > 0.5 * Sh[c], "the shadow is not most of the air's light: no test");
            CHECK_MSG(fabs(m_on - Sa[c]) < 0.06 * Sh[c], "channel %d: the shadowed air %.5g, expected %.5g", c, m_on,
                      Sa[c]);
            /* off: the air to where the ray meets the render grid's box-filtered underside, up to a
               render voxel (along the ray 16 times that) before the slab's: 9 % less here */
            CHECK_MSG(fabs(m_off - Sh[c]) < 0.15 * Sh[c], "channel %d: air_shadows off %.5g, expected %.5g", c, m_off,
                      Sh[c]);
        }
    }
    check_grazing(ctx, &op);
    atmos_atmosphere_destroy(atm);
    atmos_image_destroy(on), atmos_image_destroy(off);
    atmos_volume_destroy(v);
    test_optics_free(&op);
    atmos_context_destroy(ctx);
    return test_summary("test_nishita_air");
}
