/* The slice renderer's four eye rays at the volume's edges alone ("edge_aa", slice_edges.c)
 * on a hard-edged opaque sphere, whose pixels' coverage is known: the fraction of each
 * pixel's area inside the sphere's projected disk (from 32 x 32 rays a pixel). One ray
 * through the pixel's centre makes a silhouette pixel all covered or all clear; four rays
 * come within a quarter. Every pixel must be either the one-ray image's (eye_scale 1) or the
 * four-ray image's (eye_scale 2) bit for bit, the silhouette's the four-ray one; the
 * silhouette's coverage error within the bound below, which the one-ray image misses; the
 * same image on 1 and 2 threads and in a region of the frame (the edges found over the whole
 * image); and a thin sphere (no transmittance step) unchanged. */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#define N 128
#define VOX 5.0
#define R 300.0  /* the sphere's radius, m */
#define D 1000.0 /* its centre's distance from the eye, m */
#define W 32

static char cache_dir[1024];

/* A sphere of radius R of uniform density rho, centred D north of the eye at 1500 m (cube: the
 * whole box filled instead). */
static atmos_volume *sphere(atmos_context *ctx, float rho, int cube)
{
    atmos_volume_desc vd;
    memset(&vd, 0, sizeof vd);
    vd.dims[0] = vd.dims[1] = vd.dims[2] = N;
    vd.voxel_size_m = VOX;
    vd.origin_m[0] = -N * VOX / 2, vd.origin_m[1] = 1500 - N * VOX / 2, vd.origin_m[2] = -D - N * VOX / 2;
    atmos_volume *v = NULL;
    CHECK_OK(atmos_volume_create(ctx, &vd, &v));
    int f = -1;
    CHECK_OK(atmos_volume_add_field(ctx, v, "cloud", "cloud", &f));
    float *buf = malloc(sizeof(float) * N * N * N);
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const double x = (i + 0.5 - N / 2.0) * VOX, y = (j + 0.5 - N / 2.0) * VOX, z = (k + 0.5 - N / 2.0) * VOX;
                buf[((size_t)k * N + j) * N + i] = cube || x * x + y * y + z * z < R * R ? rho : 0.0f;
            }
    int off[3] = {0, 0, 0}, size[3] = {N, N, N};
    CHECK_OK(atmos_volume_set_dense(ctx, v, f, off, size, buf, 1.0f));
    free(buf);
    CHECK_OK(atmos_volume_finalize(ctx, v));
    return v;
}

static void scene_for(atmos_scene *s)
{
    atmos_scene_defaults(s);
    s->width = s->height = W;
    s->samples_per_pixel = 1;
    double pos[3] = {0, 1500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = 1500, s->camera.look_at[2] = -D;
    s->camera.fov_deg = 60;
    s->sun.from_time = 0;
    s->sun.elevation_deg = 30;
    s->sun.azimuth_deg = 120;
    s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    /* a near-black absorber: the image is the sky times the volume's transmittance (and the air in front) */
    s->slice.low_albedo = 1;
    s->slice.xi = 0;
    s->slice.field = ATMOS_SLICE_FIELD_NONE;
    s->slice.slices = 256;
}

static atmos_image *render(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *v,
                           const atmos_volume_optics *o, double eye_scale, double edge_aa)
{
    atmos_scene s = *scene;
    s.slice.eye_scale = eye_scale;
    s.slice.edge_aa = edge_aa;
    atmos_slice_settings ss;
    atmos_slice_defaults(&ss);
    ss.optics = o;
    atmos_image *img = NULL;
    CHECK_MSG(atmos_render_slice(ctx, &s, v, &ss, &img, NULL) == ATMOS_OK, "render slice: %s", atmos_context_error(ctx));
    return img;
}

/* The frame through a plan with edge_aa 0.05, rows [y0, y1) alone (region) or whole (the volume
 * where its own origin puts it, as atmos_render_slice does). */
static atmos_image *plan_frame(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *v,
                               const atmos_volume_optics *o, int y0, int y1)
{
    atmos_scene s = *scene;
    s.renderer = ATMOS_RENDERER_SLICE;
    s.slice.edge_aa = 0.05;
    return test_plan_frame_rows(ctx, &s, v, o, y0, y1);
}

/* Rows [y0, y1) rendered alone are the whole frame's bit for bit. */
static int region_same(atmos_context *ctx, const atmos_scene *s, const atmos_volume *v, const atmos_volume_optics *o,
                       int y0, int y1)
{
    atmos_image *whole = plan_frame(ctx, s, v, o, 0, W), *part = plan_frame(ctx, s, v, o, y0, y1);
    int same = whole && part;
    const size_t row = (size_t)W * (size_t)(whole ? whole->channels : 0);
    for (int y = y0; same && y < y1; y++)
        same = !memcmp(part->pixels + y * row, whole->pixels + y * row, sizeof(float) * row);
    atmos_image_destroy(whole), atmos_image_destroy(part);
    return same;
}

/* The fraction of pixel (x, y) inside the sphere's disk (the voxelised sphere's edge taken half
 * a voxel out). */
static double coverage(int x, int y) { return test_disk_coverage(x, y, W, 60, (R + 0.5 * VOX) / D); }

/* The volume's coverage of pixel p in img: (sky - img) / (sky - full), full the image of the
 * opaque box around the sphere (the air in front of the same halfway plane alone), the channels
 * summed. */
static double measured(const atmos_image *img, const atmos_image *sky, const atmos_image *full, size_t p)
{
    double a = 0, b = 0;
    for (int c = 0; c < 3; c++) {
        a += (double)sky->pixels[p * 4 + c] - img->pixels[p * 4 + c];
        b += (double)sky->pixels[p * 4 + c] - full->pixels[p * 4 + c];
    }
    return a / b;
}

int main(void)
{
    test_tmp_path(cache_dir, sizeof cache_dir, "cache");
    atmos_context *c1 = test_context(1, cache_dir), *c2 = test_context(2, cache_dir);
    test_optics op;
    test_hg_optics(c2, "hg0", 0.0, 1e-4, 1, &op);
    atmos_scene s;
    scene_for(&s);
    atmos_volume *v = sphere(c2, 1e10f, 1); /* 10 per metre: opaque within a metre */
    atmos_image *full = render(c2, &s, v, &op.o, 1, 0);
    atmos_volume_destroy(v);
    v = sphere(c2, 1e10f, 0);
    atmos_image *sky = NULL;
    CHECK_OK(atmos_render_sky(c2, &s, &sky, NULL));
    atmos_image *one = render(c2, &s, v, &op.o, 1, 0), *four = render(c2, &s, v, &op.o, 2, 0);
    atmos_image *edge = render(c2, &s, v, &op.o, 1, 0.05), *edge1 = render(c1, &s, v, &op.o, 1, 0.05);
    if (!sky || !full || !one || !four || !edge || !edge1) {
        CHECK(0);
    } else {
        const size_t bytes = sizeof(float) * 3;
        double e1 = 0, e4 = 0, ee = 0;
        int sil = 0, as_one = 0, as_four = 0, other = 0, sil_not_four = 0;
        for (int y = 0; y < W; y++)
            for (int x = 0; x < W; x++) {
                const size_t p = (size_t)y * W + x;
                const int is1 = !memcmp(edge->pixels + p * 4, one->pixels + p * 4, bytes);
                const int is4 = !memcmp(edge->pixels + p * 4, four->pixels + p * 4, bytes);
                as_one += is1 && !is4, as_four += is4 && !is1, other += !is1 && !is4;
                const double c = coverage(x, y);
                if (c <= 0.01 || c >= 0.99) continue;
                sil++;
                sil_not_four += !is4;
                const double d1 = measured(one, sky, full, p) - c, d4 = measured(four, sky, full, p) - c,
                             de = measured(edge, sky, full, p) - c;
                e1 += d1 * d1, e4 += d4 * d4, ee += de * de;
            }
        e1 = sqrt(e1 / sil), e4 = sqrt(e4 / sil), ee = sqrt(ee / sil);
        printf("slice edge_aa on an opaque sphere: %d silhouette pixels, coverage RMS error one ray %.3f, four rays "
               "%.3f, four at the edges %.3f; pixels as one ray alone %d, as four rays alone %d, neither %d\n",
               sil, e1, e4, ee, as_one, as_four, other);
        CHECK_MSG(other == 0, "edge_aa: %d pixels are neither the one-ray nor the four-ray image's", other);
        CHECK_MSG(sil_not_four == 0, "edge_aa: %d silhouette pixels are not the four-ray image's", sil_not_four);
        CHECK_MSG(ee <= 0.15, "edge_aa: the silhouette's coverage RMS error %.3f > 0.15", ee);
        CHECK_MSG(e1 > 0.15, "the one-ray image's silhouette coverage error %.3f: the bound above tells nothing", e1);
        CHECK_MSG(!memcmp(edge->pixels, edge1->pixels, sizeof(float) * 4 * W * W), "edge_aa: 1 and 2 threads differ");
    }
    atmos_image_destroy(one), atmos_image_destroy(four), atmos_image_destroy(edge), atmos_image_destroy(edge1);
    atmos_volume_destroy(v);
    /* a translucent sphere (optical depth 1.8 through its centre): rows rendered alone, whose
     * neighbours' transmittance the edges must still see */
    v = sphere(c2, 3e6f, 0);
    CHECK_MSG(region_same(c2, &s, v, &op.o, 9, 14), "edge_aa: rows 9-13 rendered alone differ");
    atmos_volume_destroy(v);
    /* a thin sphere (optical depth through it 6e-4): no step between neighbours, the one-ray image */
    v = sphere(c2, 1e3f, 0);
    one = render(c2, &s, v, &op.o, 1, 0), edge = render(c2, &s, v, &op.o, 1, 0.05);
    CHECK(one && edge && !memcmp(one->pixels, edge->pixels, sizeof(float) * 4 * W * W));
    atmos_image_destroy(one), atmos_image_destroy(edge), atmos_image_destroy(sky), atmos_image_destroy(full);
    atmos_volume_destroy(v);
    test_optics_free(&op);
    atmos_context_destroy(c1), atmos_context_destroy(c2);
    return test_summary("test_slice_edges");
}
