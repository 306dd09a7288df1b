/* atmos__lamp_clip (src/light/lamp.c), the span of a ray inside a spot's outer cone, against
 * the falloff sampled densely along the ray: every sample with a falloff above 0 must lie in
 * the clipped span. Spots of 30 + 10 deg, 85 + 4 deg and the hemispherical ones whose cone and
 * edge add up to 90 deg (85 + 5, 89 + 1, 90 + 0: a ceiling lamp lighting the half-space below
 * its plane, where cos 90 deg rounds to 6e-17 and the cone's quadric degenerates into the
 * plane counted twice) from rays that cross the light's plane at many angles. */
#include "test.h"
#include "light/lamp.h"

static void make_spot(double cone, double edge, atmos__lamp *l)
{
    atmos_scene_light s;
    memset(&s, 0, sizeof s);
    s.type = ATMOS_LIGHT_SPOT;
    s.position_m[1] = 12;
    s.direction[1] = -1;
    s.cone_deg = cone, s.edge_deg = edge;
    s.intensity_w_sr = 1;
    s.colour[0] = s.colour[1] = s.colour[2] = 1;
    s.range_m = 50;
    atmos_wavelengths wl;
    memset(&wl, 0, sizeof wl);
    wl.mode = ATMOS_WAVELENGTHS_RGB;
    wl.count = 3;
    wl.nm[0] = 600, wl.nm[1] = 550, wl.nm[2] = 450;
    atmos__lamp_make(&s, &wl, l);
}

/* the rays of a 40 x 30 pinhole image from (8, 2, 8) toward (0, 3, 0), 60 deg wide, over
 * [0, 60] m: the number whose lit samples fall outside the clipped span */
static int misses(const atmos__lamp *l, int *lit_rays)
{
    const double e[3] = {8, 2, 8};
    int bad = 0;
    *lit_rays = 0;
    for (int y = 0; y < 30; y++)
        for (int x = 0; x < 40; x++) {
            /* a fan of directions around -(1, 0, 1)/sqrt 2, rising with y */
            const double az = 0.25 * 3.14159265358979 + (x - 19.5) * 0.02, el = (14.5 - y) * 0.03 + 0.06;
            const double d[3] = {-cos(el) * cos(az), sin(el), -cos(el) * sin(az)};
            double t0 = 0, t1 = 60;
            const int in = atmos__lamp_clip(l, e, d, &t0, &t1);
            int lit = 0, out = 0;
            for (int i = 0; i <= 6000; i++) {
                const double t = i * 0.01, p[3] = {e[0] + t * d[0], e[1] + t * d[1], e[2] + t * d[2]};
                if (!(atmos__lamp_falloff(l, p) > 0)) continue;
                lit = 1;
                if (!in || t < t0 - 1e-9 || t > t1 + 1e-9) out = 1;
            }
            *lit_rays += lit;
            bad += out;
        }
    return bad;
}

int main(void)
{
    const double cases[][2] = {{30, 10}, {85, 4}, {85, 5}, {89, 1}, {90, 0}, {60, 30}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        atmos__lamp l;
        make_spot(cases[c][0], cases[c][1], &l);
        int lit = 0;
        const int bad = misses(&l, &lit);
        CHECK_MSG(bad == 0, "cone %g + edge %g: %d of %d lit rays clipped short", cases[c][0], cases[c][1], bad, lit);
        CHECK_MSG(lit > 100, "cone %g + edge %g: only %d lit rays", cases[c][0], cases[c][1], lit);
    }
    return test_summary("test_lamp_clip");
}
