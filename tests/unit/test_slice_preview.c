/* The slice renderer's preview frames (atmos_frame.light_size, .hold_field, with .slices,
 * .eye_scale and .no_air_shadows: docs/viewer.md, the viewer's preview while the sun moves).
 *
 * A generated cumulus, its field (the P1 field, then the do field) and its shadow on the air on,
 * 24 x 16 pixels. One plan
 * renders a full frame at sun A, previews at two suns between A and B (the light buffer at half
 * its side, the field held from A), then the full frame at B: its bytes must be those of a fresh
 * plan's frame at B (nothing of the previews stays in it). The last preview, at B, is compared
 * with that full frame (the preview's error, a stated bound); a preview at B with the plan's own
 * light buffer must differ from the one at half its side (the frame's light_size is used), and
 * light_size equal to the scene's must give the bytes of 0. The previews are the same bytes on
 * one thread and on two. A light_size out of range is refused. */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static char cache_dir[1024];

#define W 24
#define H 16

static void scene_for(atmos_scene *s)
{
    atmos_scene_defaults(s);
    s->renderer = ATMOS_RENDERER_SLICE;
    s->width = W, s->height = H;
    s->samples_per_pixel = 1;
    const double pos[3] = {0, 500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = 1500, s->camera.look_at[2] = -4000;
    s->camera.fov_deg = 50;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 30, s->sun.azimuth_deg = 150;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    s->slice.slices = 48;
    s->slice.light_size = 64;
    s->slice.air_shadows = 1;
    s->volume.placed = 1; /* the bottom face's centre 1.2 km up, 4 km ahead */
    s->volume.position_m[0] = 0, s->volume.position_m[1] = 1200, s->volume.position_m[2] = -4000;
}

static void sun_at(atmos_frame *f, double az)
{
    atmos_direction_from_angles(30, az, f->sun_dir);
}

/* A preview frame's settings (as tools/view/view_loop.c's slice_quality sets them). */
static void preview(atmos_frame *f, int light_size)
{
    f->eye_scale = 0.5, f->slices = 24, f->light_size = light_size, f->hold_field = 1, f->no_air_shadows = 1;
}

typedef struct {
    atmos_context *ctx;
    atmos_plan *plan;
    atmos_frame f0; /* the scene's frame */
} rig;

static void rig_open(rig *r, int threads, const atmos_scene *s, const atmos_volume *v, const test_optics *op)
{
    r->ctx = test_context(threads, cache_dir);
    atmos_plan_desc pd;
    memset(&pd, 0, sizeof pd);
    pd.optics = &op->o;
    r->plan = NULL;
    CHECK_OK(atmos_plan_create(r->ctx, s, v, &pd, &r->plan));
    CHECK_OK(atmos_frame_from_scene(r->ctx, s, &r->f0));
}

static void rig_close(rig *r)
{
    atmos_plan_destroy(r->plan);
    atmos_context_destroy(r->ctx);
}

/* A frame of the rig's plan at sun azimuth az, preview (light_size; 0: the full frame). */
static atmos_image *frame(rig *r, double az, int prev, int light_size)
{
    atmos_frame f = r->f0;
    sun_at(&f, az);
    if (prev) preview(&f, light_size);
    if (prev == 2) f.eye_scale = 1;
    atmos_image *img = NULL;
    CHECK_OK(atmos_plan_image_create(r->plan, &f, &img));
    atmos_status st = atmos_plan_render(r->plan, &f, NULL, img, NULL);
    CHECK_MSG(st == ATMOS_OK, "render: %s", atmos_context_error(r->ctx));
    return img;
}

static int same(const atmos_image *a, const atmos_image *b)
{
    return a && b && !memcmp(a->pixels, b->pixels, sizeof(float) * W * H * (size_t)a->channels);
}

/* The preview's error against the full frame: the mean and the largest |difference| of the
 * pixels' green radiance, relative to the full frame's mean green. */
static void error_of(const atmos_image *p, const atmos_image *full, double *mean, double *worst)
{
    const int C = full->channels;
    double sum = 0, d = 0, m = 0;
    for (int i = 0; i < W * H; i++) {
        const double e = fabs((double)p->pixels[i * C + 1] - full->pixels[i * C + 1]);
        sum += full->pixels[i * C + 1], d += e, m = fmax(m, e);
    }
    *mean = d / sum, *worst = m / (sum / (W * H));
}

/* The checks above for one field (its solve held in the previews, solved again for the full frame). */
static void check_field(const atmos_scene *scene, const atmos_volume *v, const test_optics *op, int field,
                        const char *name)
{
    atmos_scene sc = *scene, *s = &sc;
    s->slice.field = field;
    rig fresh, r1, r2;
    rig_open(&fresh, 2, s, v, op);
    atmos_image *ref = frame(&fresh, 170, 0, 0); /* a fresh plan's full frame at B */
    rig_close(&fresh);

    rig_open(&r2, 2, s, v, op);
    rig_open(&r1, 1, s, v, op);
    atmos_image *a2 = frame(&r2, 150, 0, 0), *a1 = frame(&r1, 150, 0, 0);
    atmos_image *p2 = frame(&r2, 160, 1, 32), *p1 = frame(&r1, 160, 1, 32);
    atmos_image *q2 = frame(&r2, 170, 1, 32), *q1 = frame(&r1, 170, 1, 32);
    atmos_image *big = frame(&r2, 170, 1, 64), *zero = frame(&r2, 170, 1, 0), *same_l = frame(&r2, 170, 1, 64);
    atmos_image *q2b = frame(&r2, 170, 1, 32);
    atmos_image *sharp = frame(&r2, 170, 2, 32); /* the preview at the image's resolution */
    atmos_image *full = frame(&r2, 170, 0, 0);
    CHECK_MSG(same(full, ref), "the full frame after previews differs from a fresh plan's");
    CHECK_MSG(same(a2, a1) && same(p2, p1) && same(q2, q1), "the frames differ between 1 and 2 threads");
    CHECK_MSG(!same(q2, big), "light_size 32 and 64 give the same preview: the frame's light_size is not used");
    CHECK_MSG(same(zero, same_l), "light_size equal to the scene's differs from 0");
    CHECK_MSG(same(q2, q2b), "the same preview rendered again differs");
    CHECK_MSG(!same(q2, full), "the preview equals the full frame: nothing was reduced");
    double mean, worst, mean1, worst1;
    error_of(q2, full, &mean, &worst);
    error_of(sharp, full, &mean1, &worst1);
    printf("%s field: preview at B against the full frame, relative to its mean green: mean |difference| %.4f, "
           "largest %.3f; at the image's resolution %.4f, %.3f\n", name, mean, worst, mean1, worst1);
    CHECK_MSG(mean < 0.15, "the preview's error: mean %.4f of the mean (bound 0.15)", mean);
    CHECK_MSG(mean1 < 0.05 && worst1 < 1.5,
              "the preview's error at the image's resolution: mean %.4f (bound 0.05), largest %.3f (bound 1.5)", mean1,
              worst1);

    atmos_frame f = r2.f0;
    f.light_size = -1;
    atmos_image *bad = NULL;
    CHECK_OK(atmos_plan_image_create(r2.plan, &f, &bad));
    CHECK_MSG(atmos_plan_render(r2.plan, &f, NULL, bad, NULL) == ATMOS_E_INVALID_ARG, "light_size -1 accepted");

    atmos_image *imgs[] = {ref, a2, a1, p2, p1, q2, q1, big, zero, same_l, q2b, sharp, full, bad};
    for (size_t i = 0; i < sizeof imgs / sizeof *imgs; i++) atmos_image_destroy(imgs[i]);
    rig_close(&r1), rig_close(&r2);
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache");
    atmos_scene s;
    scene_for(&s);
    atmos_context *gctx = test_context(2, cache_dir);
    atmos_volume *v = test_generate(gctx, "cumulus", 1, 150);
    test_optics op;
    test_hg_optics(gctx, "cloud", 0.85, 0.999, 1, &op);

    check_field(&s, v, &op, ATMOS_SLICE_FIELD_P1, "p1");
    check_field(&s, v, &op, ATMOS_SLICE_FIELD_DO, "do"); /* the default */
    test_optics_free(&op);
    atmos_volume_destroy(v);
    atmos_context_destroy(gctx);
    return test_summary("test_slice_preview");
}
