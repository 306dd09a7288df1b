/* A spot's projected image along an eye ray's sub-planes (src/render/beams_tint.c), against the
 * samples read one by one (the light times atmos__lamp_tint at each, the beam renderer's way
 * before issue 17's thirty-first round): the stained glass's window (scenes/, 64 x 64, panes
 * between black lead, black round the lancet) on a spot of 12 + 1 deg, rays in a fan across
 * its beam, runs of 1 to 64 samples. Each sum within 1e-10 of the reference (rounding); every sample
 * outside the span atmos__beams_ray_tint_span keeps is untinted; a box that
 * atmos__lamp_tint_same calls one colour is that colour at every point sampled in it. */
#include "test.h"
#include "light/lamp.h"
#include "render/beams_internal.h"

#include <stdlib.h>

static atmos_context *ctx;

static void make_window(atmos__beams_light *bl)
{
    atmos_scene s;
    memset(&s, 0, sizeof s);
    atmos_scene_light *l = &s.lights[0];
    l->type = ATMOS_LIGHT_SPOT;
    l->position_m[0] = -22, l->position_m[1] = 22;
    l->direction[0] = 16, l->direction[1] = -14.5;
    l->cone_deg = 12, l->edge_deg = 1;
    l->intensity_w_sr = 1;
    l->colour[0] = l->colour[1] = l->colour[2] = 1;
    l->range_m = 80;
    const char *src = getenv("ATMOS_SOURCE_DIR");
    snprintf(l->image, sizeof l->image, "%s/scenes/dobashi_fig09b_window.png", src && *src ? src : ".");
    s.light_count = 1;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    memset(bl, 0, sizeof *bl);
    atmos__lamp_make(l, &wl, &bl->L);
    CHECK_OK(atmos__lamp_load_image(ctx, &s, 0, &bl->L));
}

/* The rays of a fan from (5, 1.8, 11) across the beam; returns the worst relative difference
 * of the run sums and counts the tinted samples outside the kept span in *stray. */
static double compare_runs(const atmos__beams_light *bl, int *stray, int *lit)
{
    const double e[3] = {5, 1.8, 11};
    double worst = 0;
    *stray = *lit = 0;
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 32; x++) {
            const double az = -2.4 + x * 0.03, el = 0.05 + y * 0.03;
            const double d[3] = {cos(el) * cos(az), sin(el), cos(el) * sin(az)};
            atmos__beams_ray ray;
            atmos__beams_ray_init(bl, e, d, &ray);
            double p0 = 0, p1 = 40;
            const int some = atmos__beams_ray_tint_span(&ray, &p0, &p1);
            for (int m = 1; m <= 64; m *= 2) {
                const double ta = 0, step = 40.0 / m, o = 0.5;
                double h[3] = {0, 0, 0}, ref[3] = {0, 0, 0};
                atmos__beams_ray_tinted_sum(&ray, ta, step, o, 0, m, h);
                for (int s = 0; s < m; s++) {
                    const double t = ta + (s + o) * step, v = atmos__beams_ray_light(&ray, t);
                    const double P[3] = {e[0] + t * d[0], e[1] + t * d[1], e[2] + t * d[2]};
                    double tint[3];
                    atmos__lamp_tint(&bl->L, P, tint);
                    const int tinted = tint[0] > 0 || tint[1] > 0 || tint[2] > 0;
                    *stray += tinted && (!some || t < p0 || t > p1);
                    *lit += tinted && v > 0;
                    for (int c = 0; c < 3; c++) ref[c] += v * tint[c];
                }
                for (int c = 0; c < 3; c++) {
                    const double diff = fabs(h[c] - ref[c]) / (ref[c] > 1e-300 ? ref[c] : 1);
                    worst = diff > worst ? diff : worst;
                }
            }
        }
    return worst;
}

/* Boxes of texel coordinates over the image: where atmos__lamp_tint_same says one colour,
 * the bilinear tint at points of the box (its corners and a grid inside) is that colour. */
static void check_boxes(const atmos__lamp *L, int *same, int *wrong)
{
    *same = *wrong = 0;
    for (int i = 0; i < 4000; i++) {
        const double x0 = -2 + 68.0 * (i % 97) / 97, y0 = -2 + 68.0 * (i / 97 % 41) / 41;
        const double w = 0.05 + 3.0 * (i % 7) / 7, h = 0.05 + 3.0 * (i % 5) / 5;
        double rgb[3];
        if (!atmos__lamp_tint_same(L, x0, x0 + w, y0, y0 + h, rgb)) continue;
        (*same)++;
        for (int a = 0; a <= 8; a++)
            for (int b = 0; b <= 8; b++) {
                double t[3];
                atmos__lamp_tint_at(L, x0 + w * a / 8, y0 + h * b / 8, t);
                int off = 0;
                for (int c = 0; c < 3; c++) off |= fabs(t[c] - rgb[c]) > 1e-6 * (1 + rgb[c]);
                *wrong += off;
            }
    }
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos__beams_light bl;
    make_window(&bl);
    int stray, lit, same, wrong;
    const double worst = compare_runs(&bl, &stray, &lit);
    printf("run sums against the samples read one by one: worst relative difference %.3g over %d lit samples; "
           "%d tinted samples outside the kept span\n",
           worst, lit, stray);
    CHECK_MSG(worst <= 1e-10, "tinted run sums differ from the samples by %.3g", worst);
    CHECK_MSG(stray == 0, "%d tinted samples outside the span", stray);
    CHECK_MSG(lit > 1000, "only %d lit samples: the fan misses the beam", lit);
    check_boxes(&bl.L, &same, &wrong);
    printf("boxes of one colour: %d, points off their colour: %d\n", same, wrong);
    CHECK_MSG(wrong == 0, "%d points in boxes of one colour differ from it", wrong);
    CHECK_MSG(same > 200, "only %d boxes of one colour", same);
    atmos__lamp_free(&bl.L);
    atmos_context_destroy(ctx);
    return test_summary("test_beams_tint");
}
