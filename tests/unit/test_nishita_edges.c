/* The Nishita renderer's four eye rays at the volume's edges ("nishita.edge_aa"; the slice
 * renderer's edge pixels, edge_aa.c) on a hard-edged near-black sphere before a uniform
 * background in a vacuum, whose pixels' coverage is known: the fraction of each pixel's area
 * inside the sphere's projected disk (from 32 x 32 rays a pixel); the image is the background
 * times one minus it. One ray through the pixel's centre makes a silhouette pixel all covered
 * or all clear; four rays come within a quarter. Checked: the silhouette's coverage error
 * within the bound below, which the one-ray image (edge_aa 0) misses; the pixels away from the
 * silhouette the one-ray image's bit for bit; the same image on 1 and 2 threads and in a region
 * of the frame rendered alone (the edges found around it). */
#include "atmos/atmos.h"
#include "test.h"
#include "test_optics.h"

#define N 128
#define VOX 5.0
#define R 300.0  /* the sphere's radius, m */
#define D 1000.0 /* its centre's distance from the eye, m */
#define W 32

/* A sphere of radius R of uniform density rho (10 per metre: opaque within a metre), centred D
 * north of the eye at 1500 m. */
static atmos_volume *sphere(atmos_context *ctx)
{
    float *buf = malloc(sizeof(float) * N * N * N);
    for (int k = 0; k < N; k++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                const double x = (i + 0.5 - N / 2.0) * VOX, y = (j + 0.5 - N / 2.0) * VOX, z = (k + 0.5 - N / 2.0) * VOX;
                buf[((size_t)k * N + j) * N + i] = x * x + y * y + z * z < R * R ? 1e10f : 0.0f;
            }
    const int dims[3] = {N, N, N};
    const double org[3] = {-N * VOX / 2, 1500 - N * VOX / 2, -D - N * VOX / 2};
    atmos_volume *v = test_dense_volume(ctx, dims, VOX, org, "cloud", "hg0", buf);
    free(buf);
    return v;
}

static void scene_for(atmos_scene *s, double edge_aa)
{
    test_vacuum_scene(s, 30, 180); /* the sun behind the eye */
    s->width = s->height = W;
    s->atmosphere.background_radiance = 1.0;
    const double pos[3] = {0, 1500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = 1500, s->camera.look_at[2] = -D;
    s->camera.fov_deg = 60;
    s->renderer = ATMOS_RENDERER_NISHITA;
    s->nishita.orders = 1, s->nishita.sky = 0;
    test_nishita_paper(s);
    s->nishita.edge_aa = edge_aa;
}

/* Rows [y0, y1) of the frame (the volume where its own coordinates put it). */
static atmos_image *frame(atmos_context *ctx, double edge_aa, const atmos_volume *v, const atmos_volume_optics *o,
                          int y0, int y1)
{
    atmos_scene s;
    scene_for(&s, edge_aa);
    return test_plan_frame_rows(ctx, &s, v, o, y0, y1);
}

/* The fraction of pixel (x, y) inside the sphere's disk (the voxelised sphere's edge taken half
 * a voxel out). */
static double coverage(int x, int y) { return test_disk_coverage(x, y, W, 60, (R + 0.5 * VOX) / D); }

/* 1 when pixel (x, y) and its eight neighbours are all clear or all covered. */
static int away(const double *cov, int x, int y)
{
    int clear = 0, full = 0, n = 0;
    for (int b = y - 1; b <= y + 1; b++)
        for (int a = x - 1; a <= x + 1; a++) {
            if (a < 0 || b < 0 || a >= W || b >= W) continue;
            n++, clear += cov[b * W + a] <= 0.0, full += cov[b * W + a] >= 1.0;
        }
    return clear == n || full == n;
}

int main(void)
{
    atmos_context *c1 = test_context(1, NULL), *c2 = test_context(2, NULL);
    test_optics op;
    test_hg_optics(c2, "hg0", 0.0, 1e-4, 0, &op);
    atmos_volume *v = sphere(c2);
    atmos_image *one = frame(c2, 0, v, &op.o, 0, W), *edge = frame(c2, 0.05, v, &op.o, 0, W),
                *edge1 = frame(c1, 0.05, v, &op.o, 0, W), *part = frame(c2, 0.05, v, &op.o, 9, 14);
    if (!one || !edge || !edge1 || !part) {
        CHECK(0);
    } else {
        double cov[W * W], e1 = 0, ee = 0;
        int sil = 0, moved_away = 0;
        for (int p = 0; p < W * W; p++) cov[p] = coverage(p % W, p / W);
        for (int y = 0; y < W; y++)
            for (int x = 0; x < W; x++) {
                const size_t p = (size_t)y * W + x;
                const int same = !memcmp(edge->pixels + p * 4, one->pixels + p * 4, sizeof(float) * 3);
                moved_away += away(cov, x, y) && !same;
                if (cov[p] <= 0.01 || cov[p] >= 0.99) continue;
                sil++;
                double m1 = 0, me = 0; /* the measured coverage: 1 - the image over the background 1 */
                for (int c = 0; c < 3; c++) m1 += (1.0 - one->pixels[p * 4 + c]) / 3, me += (1.0 - edge->pixels[p * 4 + c]) / 3;
                e1 += (m1 - cov[p]) * (m1 - cov[p]), ee += (me - cov[p]) * (me - cov[p]);
            }
        e1 = sqrt(e1 / sil), ee = sqrt(ee / sil);
        printf("nishita edge_aa on an opaque sphere: %d silhouette pixels, coverage RMS error one ray %.3f, four at "
               "the edges %.3f; pixels away from the silhouette changed %d\n",
               sil, e1, ee, moved_away);
        CHECK_MSG(ee <= 0.15, "edge_aa: the silhouette's coverage RMS error %.3f > 0.15", ee);
        CHECK_MSG(e1 > 0.15, "the one-ray image's silhouette coverage error %.3f: the bound above tells nothing", e1);
        CHECK_MSG(moved_away == 0, "edge_aa: %d pixels away from the silhouette differ from the one-ray image",
                  moved_away);
        CHECK_MSG(!memcmp(edge->pixels, edge1->pixels, sizeof(float) * 4 * W * W), "edge_aa: 1 and 2 threads differ");
        const size_t row = (size_t)W * 4;
        CHECK_MSG(!memcmp(part->pixels + 9 * row, edge->pixels + 9 * row, sizeof(float) * 5 * row),
                  "edge_aa: rows 9-13 rendered alone differ");
    }
    atmos_image_destroy(one), atmos_image_destroy(edge), atmos_image_destroy(edge1), atmos_image_destroy(part);
    atmos_volume_destroy(v);
    test_optics_free(&op);
    atmos_context_destroy(c1), atmos_context_destroy(c2);
    return test_summary("test_nishita_edges");
}
