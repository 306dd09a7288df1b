/* The eye pass's rows (src/particles/psplat.c: each row's span within the cut, the spans'
 * columns and transmittances in vector loops, three wavelengths and coverage composited in
 * one loop over the span's values):
 * a field of three-wavelength splats against a direct composite of the same particles computed
 * here pixel by pixel from each pixel's ray (double precision, erf from the C library: the
 * column's closed form, not the renderer's polynomial). */
#include "atmos/atmos.h"
#include "particles/pcloud.h"
#include "test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.141592653589793

/* tau(b) / tc of a particle cut at 3 s: exp(-u / 2) erf(sqrt((9 - u) / 2)), u = b^2 / s^2. */
static double column(double u) { return u >= 9 ? 0.0 : exp(-0.5 * u) * erf(sqrt(0.5 * (9 - u))); }

typedef struct keyed { double z; int p; } keyed;
static int far_first(const void *a, const void *b)
{
    const double za = ((const keyed *)a)->z, zb = ((const keyed *)b)->z;
    return za > zb ? -1 : za < zb;
}

/* 400 particles of three wavelengths splatted over 160 x 90 pixels against the direct
 * composite: within 2e-5 of the brightest pixel (the column's polynomial, single precision). */
static void field(void)
{
    enum { W = 160, H = 90, NW = 3, NP = 400 };
    atmos__pcloud pc;
    memset(&pc, 0, sizeof pc);
    pc.nfields = 1;
    for (int i = 0; i < NP; i++)
        CHECK_OK(atmos__pcloud_add(&pc, 80 * sin(i * 1.3), 40 * cos(i * 0.7), -900 - 0.7 * i, 3 + i % 11, 2e8, 0));
    atmos__poptics o;
    memset(&o, 0, sizeof o);
    o.nw = NW;
    const double sig[NW] = {1.0e-12, 1.3e-12, 0.7e-12}, alb[NW] = {0.9, 0.95, 0.8}, e[NW] = {1.5, 1.2, 0.9};
    double sun_e[1][ATMOS_MAX_WAVELENGTHS] = {{0}};
    for (int k = 0; k < NW; k++) o.sigma_ext[0][k] = sig[k], o.albedo[0][k] = alb[k], sun_e[0][k] = e[k];
    float *light = malloc(sizeof(float) * NP * NW), *order = calloc(NP, sizeof(float));
    for (int i = 0; i < NP * NW; i++) light[i] = 0.3f + 0.6f * (float)((i * 37) % 101) / 101.0f;
    const float *lp[1] = {light}, *op[1] = {order};
    const double sun[1][3] = {{0, 1, 0}};
    const atmos__plights L = {1, lp, op, sun, (const double(*)[ATMOS_MAX_WAVELENGTHS])sun_e, NULL, NULL, NULL};
    atmos_camera_desc cd;
    const double pos[3] = {3, 2, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &cd);
    cd.fov_deg = 12;
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(NULL, &cd, W, H, &cam));
    atmos_image *img = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, NW + 1, &img));
    const int rect[4] = {0, 0, W, H};
    CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L, NULL, 0, &cam, rect, img, NULL));
    keyed *ord = malloc(sizeof *ord * NP);
    for (int p = 0; p < NP; p++) {
        const double rel[3] = {pc.x[p] - pos[0], pc.y[p] - pos[1], pc.z[p] - pos[2]};
        ord[p].z = rel[0] * cam.forward[0] + rel[1] * cam.forward[1] + rel[2] * cam.forward[2], ord[p].p = p;
    }
    qsort(ord, NP, sizeof *ord, far_first);
    double worst = 0, top = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double d[3], px[NW + 1] = {0};
            CHECK(atmos_camera_ray(&cam, x + 0.5, y + 0.5, d));
            for (int q = 0; q < NP; q++) {
                const int p = ord[q].p;
                const double rel[3] = {pc.x[p] - pos[0], pc.y[p] - pos[1], pc.z[p] - pos[2]};
                const double t = rel[0] * d[0] + rel[1] * d[1] + rel[2] * d[2];
                const double b2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2] - t * t, s = pc.s[p];
                if (b2 > 9 * s * s) continue;
                double tm = 0; /* no phase tables: isotropic */
                for (int k = 0; k < NW; k++) {
                    const double T = exp(-sig[k] * pc.n0[p] * s * sqrt(2 * PI) * column(b2 / (s * s)));
                    const double col = alb[k] * e[k] * light[p * NW + k] / (4 * PI);
                    px[k] = px[k] * T + col * (1 - T), tm += T;
                }
                px[NW] = 1 - (1 - px[NW]) * tm / NW;
            }
            for (int c = 0; c <= NW; c++) {
                const double got = img->pixels[((size_t)y * W + x) * (NW + 1) + c];
                worst = fmax(worst, fabs(got - px[c])), top = fmax(top, fabs(px[c]));
            }
        }
    printf("splat field: worst difference %.3g of the brightest %.4g\n", worst, top);
    CHECK(top > 0.01);
    CHECK(worst <= 2e-5 * top);
    free(ord), free(light), free(order);
    atmos_image_destroy(img);
    atmos__pcloud_free(&pc);
}

/* Which pixels a splat touches (draw visits only each row's columns within the cut): single
 * dense particles (tc about 1e4, so that T < 1 in single precision to within 1e-4 of the cut's
 * u = b^2 / s^2 = 9) 0.2 to 6.2 pixels wide at the image's centre (more near its edges), at
 * scattered sub-pixel places, near the image's edges and beyond them, and close to the eye in
 * a 100-degree camera (elliptical splats), each splatted alone over a frame of constant values within a part of it (rect):
 * every pixel of the part whose ray passes within the cut (u < 9 - 1e-4, u from the ray here,
 * double precision) changed, every other pixel left as it was, bit for bit (a particle whose
 * splat reaches the eye's plane is not drawn at all). */
static void spans(void)
{
    enum { W = 150, H = 96, NW = 3 };
    atmos__poptics o;
    memset(&o, 0, sizeof o);
    o.nw = NW, o.sigma_ext[0][0] = o.sigma_ext[0][1] = o.sigma_ext[0][2] = 1.0;
    o.albedo[0][0] = 0.9, o.albedo[0][1] = 0.8, o.albedo[0][2] = 0.7;
    double sun_e[1][ATMOS_MAX_WAVELENGTHS] = {{2, 2, 2}};
    const float light[NW] = {1, 1, 1}, order[1] = {0}, *lp[1] = {light}, *op[1] = {order};
    const double sun[1][3] = {{0, 1, 0}};
    const atmos__plights L = {1, lp, op, sun, (const double(*)[ATMOS_MAX_WAVELENGTHS])sun_e, NULL, NULL, NULL};
    atmos_camera_desc cd;
    const double pos[3] = {0, 0, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &cd);
    cd.fov_deg = 100;
    cd.look_at[0] = 0.3, cd.look_at[1] = 0.2, cd.look_at[2] = -1; /* not along an axis */
    atmos_camera cam;
    CHECK_OK(atmos_camera_init(NULL, &cd, W, H, &cam));
    atmos_image *img = NULL;
    CHECK_OK(atmos_image_create(NULL, W, H, NW + 1, &img));
    const int rect[4] = {5, 3, W - 7, H - 2}; /* tiles not on the image's grid */
    long inside = 0, missed = 0, stray = 0, splats = 0;
    for (int i = 0; i < 400; i++) {
        /* a direction on the screen (x, y in pixels, some beyond the edges), a distance, a width */
        const double x = -10 + (W + 20) * fmod(i * 0.6180339887, 1.0), y = -10 + (H + 20) * fmod(i * 0.7548776662, 1.0);
        double d[3];
        if (!atmos_camera_ray(&cam, x, y, d)) continue;
        const double dist = i % 5 == 0 ? 0.5 + 0.05 * (i % 7) : 20.0 + 3.0 * (i % 13);
        const double spx = 0.2 + 6.0 * fmod(i * 0.3819660113, 1.0); /* the width in pixels (at the centre) */
        const double s = spx * dist * 2.0 * cam.tan_half_fov / H;
        atmos__pcloud pc;
        memset(&pc, 0, sizeof pc);
        pc.nfields = 1;
        CHECK_OK(atmos__pcloud_add(&pc, dist * d[0], dist * d[1], dist * d[2], s, 1e4 / (s * sqrt(2 * PI)), 0));
        for (size_t k = 0; k < (size_t)W * H * (NW + 1); k++) img->pixels[k] = 0.25f;
        int drawn = 0;
        CHECK_OK(atmos__pcloud_splat(NULL, &pc, &o, &L, NULL, 0, &cam, rect, img, &drawn));
        splats += drawn;
        for (int py = 0; py < H; py++)
            for (int px = 0; px < W; px++) {
                double r[3];
                CHECK(atmos_camera_ray(&cam, px + 0.5, py + 0.5, r));
                const double rel[3] = {pc.x[0], pc.y[0], pc.z[0]}, tt = rel[0] * r[0] + rel[1] * r[1] + rel[2] * r[2];
                const double u = (rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2] - tt * tt) / (s * s);
                const int in_rect = px >= rect[0] && px < rect[2] && py >= rect[1] && py < rect[3];
                const float *v = img->pixels + ((size_t)py * W + px) * (NW + 1);
                const int changed = v[0] != 0.25f || v[1] != 0.25f || v[2] != 0.25f || v[3] != 0.25f;
                if (drawn && in_rect && tt > 0 && u < 9 - 1e-4) inside++, missed += !changed;
                else if (!(drawn && in_rect && tt > 0 && u < 9 + 1e-6)) stray += changed;
            }
        atmos__pcloud_free(&pc);
    }
    printf("splat spans: %ld splats drawn, %ld pixels within the cut, %ld of them missed, %ld changed outside\n",
           splats, inside, missed, stray);
    CHECK(splats > 300);
    CHECK(inside > 20000);
    CHECK(missed == 0);
    CHECK(stray == 0);
    atmos_image_destroy(img);
}

int main(void)
{
    field();
    spans();
    return test_summary("test_psplat_field");
}
