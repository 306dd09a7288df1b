/* The aerial-perspective volume (src/atmosphere/atmosphere_aerial.c, spherical_aerial.c)
 * against the atmosphere's own direct answers (atmos_atmosphere_inscatter and
 * atmos_atmosphere_transmittance of the same segment) at random (direction, distance) pairs:
 * the production sky's fast path (a high sun, a low sun in view near the horizon, the grid
 * the slice renderer makes), the generic path on Riley's closed form and on the homogeneous
 * layer (whose optical depth is linear in distance, so the interpolated transmittance is
 * exact), the answers outside the grid, thread independence; and the slice renderer's frame
 * under the spherical sky with the volume against the frame asking the atmosphere per pixel
 * (the reference passes). */
#include "atmos/atmos.h"
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "test.h"
#include "test_optics.h"

#include <stdint.h>

static uint64_t rng_state = 0x243F6A8885A308D3ull;
static double rnd(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (double)((z ^ (z >> 31)) >> 11) * (1.0 / 9007199254740992.0);
}

static atmos_atmosphere *make(atmos_atmosphere_kind kind)
{
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    ad.kind = kind;
    ad.ground_albedo = 0.3;
    ad.hide_sun_disk = 1;
    if (kind == ATMOS_ATMOSPHERE_HOMOGENEOUS) ad.thickness_m = 3000;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *a = NULL;
    CHECK_OK(atmos_atmosphere_create(NULL, &ad, &wl, &a));
    return a;
}

static double lum(const double *c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/* A frustum from eye (altitude y) centred on (el, az) degrees, +-tu across, +-tv up. */
static void frustum(atmos__aerial_grid *g, double y, double el, double az, double tu, double tv, double sun_el,
                    double sun_az, int nu, int nv, int nd, double tmax)
{
    memset(g, 0, sizeof *g);
    g->eye[1] = y;
    atmos_direction_from_angles(el, az, g->fwd);
    atmos_direction_from_angles(sun_el, sun_az, g->sun);
    const double wup[3] = {0, 1, 0};
    atmos__cross3(g->fwd, wup, g->right);
    atmos__normalize3(g->right);
    atmos__cross3(g->right, g->fwd, g->up);
    g->u0 = -tu, g->u1 = tu, g->v0 = -tv, g->v1 = tv;
    g->nu = nu, g->nv = nv, g->nd = nd, g->tmax = tmax;
}

/* Worst and RMS relative errors of count random pairs (the distance cut at the ground, as the
 * renderer does; in-scatter relative to max(direct, floor x the largest direct luminance));
 * the worst transmittance error relative to the direct transmittance. */
typedef struct {
    double s_worst, s_rms, t_worst, answered;
} errs;

static errs compare(const char *name, const atmos_atmosphere *a, const atmos__aerial_grid *g, int count)
{
    atmos__aerial ap;
    memset(&ap, 0, sizeof ap);
    CHECK(atmos__aerial_build(&ap, a, g, 2));
    enum { MAXN = 512 };
    static double S[MAXN][3], D[MAXN][3], T[MAXN][3], E[MAXN][3];
    double smax = 0;
    int got = 0;
    for (int i = 0; i < count && i < MAXN; i++) {
        const double u = g->u0 + (g->u1 - g->u0) * rnd(), v = g->v0 + (g->v1 - g->v0) * rnd(), x = rnd();
        double d[3];
        for (int c = 0; c < 3; c++) d[c] = g->fwd[c] + u * g->right[c] + v * g->up[c];
        atmos__normalize3(d);
        double t = g->tmax * (i % 4 == 0 ? x * x : x); /* a quarter crowded near the eye */
        const double tg = atmos_atmosphere_ground_distance(a, g->eye, d);
        if (t > tg) t = tg;
        atmos_atmosphere_inscatter(a, g->eye, d, t, g->sun, D[i]);
        atmos_atmosphere_transmittance(a, g->eye, d, t, E[i]);
        if (atmos__aerial_eval(&ap, d, t, S[i], T[i])) got++;
        else memcpy(S[i], D[i], sizeof S[i]), memcpy(T[i], E[i], sizeof T[i]); /* as the renderer */
        smax = fmax(smax, lum(D[i]));
    }
    errs e = {0, 0, 0, (double)got / count};
    for (int i = 0; i < count; i++) {
        for (int c = 0; c < 3; c++) {
            const double r = fabs(S[i][c] - D[i][c]) / fmax(D[i][c], 1e-3 * smax);
            e.s_worst = fmax(e.s_worst, r);
            e.s_rms += r * r / (3.0 * count);
            e.t_worst = fmax(e.t_worst, fabs(T[i][c] - E[i][c]) / fmax(E[i][c], 1e-6));
        }
    }
    e.s_rms = sqrt(e.s_rms);
    printf("%s: %d pairs (%.0f %% from the volume), in-scatter worst %.3f %% rms %.3f %%, transmittance worst "
           "%.3f %%\n", name, count, 100 * e.answered, 100 * e.s_worst, 100 * e.s_rms, 100 * e.t_worst);
    atmos__aerial_free(&ap);
    return e;
}

/* The production sky's fast path, the grid's nodes by atmos__aerial_nodes (as the slice
 * renderer makes them): within 1 % at worst, in-scatter and transmittance. */
static void spherical_case(const atmos_atmosphere *a, const char *name, double y, double el, double az, double tu,
                           double tv, double sun_el, double sun_az, double tmax, int count)
{
    atmos__aerial_grid g;
    frustum(&g, y, el, az, tu, tv, sun_el, sun_az, atmos__aerial_nodes(2 * tu, tmax), atmos__aerial_nodes(2 * tv, tmax),
            32, tmax);
    const errs e = compare(name, a, &g, count);
    CHECK(e.s_worst < 0.01 && e.t_worst < 0.01);
    CHECK(e.s_rms < 0.002);
    CHECK(e.answered > 0.5);
}

static void spherical_cases(const atmos_atmosphere *a)
{
    /* 1500 m up, a 30-degree sun in the frame's corner, the ground in its lower part */
    spherical_case(a, "spherical, sun 30 deg, 62-degree view, 20 km", 1500, 10, 150, 0.6, 0.6, 30, 180, 20e3, 400);
    /* 2 m up, a 3-degree sun in view, the horizon across the frame */
    spherical_case(a, "spherical, sun 3 deg in view, horizon, 30 km", 2, 2, 200, 0.3, 0.15, 3, 200, 30e3, 400);
    /* the sun just below the horizon (the air in front lit from below the frame) */
    spherical_case(a, "spherical, sun -2 deg, 15 km", 300, 5, 100, 0.4, 0.3, -2, 90, 15e3, 300);
    /* a cloud 1-3 km away in a 45-degree view */
    spherical_case(a, "spherical, 45-degree view, 3 km", 1500, 8, 0, 0.41, 0.41, 35, 200, 3000, 400);
}

/* The generic path: Riley's closed form and the homogeneous layer. */
static void generic_cases(void)
{
    atmos_atmosphere *r = make(ATMOS_ATMOSPHERE_RILEY);
    atmos__aerial_grid g;
    frustum(&g, 1500, 10, 150, 0.6, 0.6, 30, 180, 24, 24, 32, 20e3);
    errs e = compare("riley (generic), 20 km", r, &g, 300);
    CHECK(e.s_worst < 0.01 && e.t_worst < 0.01);
    atmos_atmosphere_destroy(r);
    atmos_atmosphere *h = make(ATMOS_ATMOSPHERE_HOMOGENEOUS);
    frustum(&g, 1000, 0, 30, 0.5, 0.3, 20, 60, 12, 8, 16, 1500); /* inside the layer throughout */
    e = compare("homogeneous (generic), 1.5 km", h, &g, 300);
    CHECK(e.s_worst < 0.01);
    CHECK(e.t_worst < 1e-5); /* optical depth linear in distance: exact but for float storage */
    atmos_atmosphere_destroy(h);
}

/* Outside the grid: no answer. The same table on 1 and 2 threads. */
static void edges_and_threads(const atmos_atmosphere *a)
{
    atmos__aerial_grid g;
    frustum(&g, 1500, 10, 150, 0.3, 0.3, 30, 180, 9, 7, 12, 5000);
    atmos__aerial p1, p2;
    memset(&p1, 0, sizeof p1), memset(&p2, 0, sizeof p2);
    CHECK(atmos__aerial_build(&p1, a, &g, 1));
    CHECK(atmos__aerial_build(&p2, a, &g, 2));
    const size_t nf = (size_t)g.nu * g.nv * g.nd * 3 * 4;
    CHECK(memcmp(p1.tab, p2.tab, sizeof(float) * nf) == 0);
    double S[3], T[3], back[3], side[3];
    for (int c = 0; c < 3; c++) back[c] = -g.fwd[c], side[c] = g.fwd[c] + 0.5 * g.right[c];
    atmos__normalize3(side);
    CHECK(!atmos__aerial_eval(&p1, g.fwd, 5001, S, T));
    CHECK(!atmos__aerial_eval(&p1, back, 100, S, T));
    CHECK(!atmos__aerial_eval(&p1, side, 100, S, T));
    CHECK(atmos__aerial_eval(&p1, g.fwd, 0, S, T));
    CHECK(S[0] == 0 && S[1] == 0 && S[2] == 0 && T[0] == 1 && T[1] == 1 && T[2] == 1);
    atmos__aerial_free(&p1), atmos__aerial_free(&p2);
}

int main(void)
{
    atmos_atmosphere *a = make(ATMOS_ATMOSPHERE_SPHERICAL);
    spherical_cases(a);
    edges_and_threads(a);
    generic_cases();
    atmos_atmosphere_destroy(a);
    return test_summary("test_aerial");
}
