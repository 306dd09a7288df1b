/* The beam renderer's sky irradiance table kept between frames (src/render/beams_sky.c,
 * docs/beams.md "The sky's light"): atmos__beams_sky_keep builds the table for the ground under
 * the eye quantised to BEAMS_SKY_KEEP_M metres along the sun's azimuth and
 * BEAMS_SKY_KEEP_ACROSS_M across it, and keeps it while that point and the sun stay.
 *   - an eye moved within its quantum (400 m across the sun's azimuth among them: a grid of
 *     BEAMS_SKY_KEEP_M in x and z fails here) keeps the very table (not made again: a value
 *     written into it stays), and it equals, value
 *     for value, a fresh atmos__beams_sky_build at the quantised point;
 *   - an eye moved into another quantum, another sun, or a fog's layers asked or no longer
 *     asked, gets a new table equal to a fresh one;
 *   - the quantisation's cost: the table at the quantised point against the table at the true
 *     point half a quantum away along and across (the spherical model, the sun 8 and 30 degrees
 *     up and 3 below), within a relative 10^-3 at every node with light above 10^-3 of the
 *     brightest;
 *   - atmos__beams_sky_irradiance_memo gives the bits of the call it stands for. */
#include "atmos/atmos.h"
#include "render/beams_sky.h"
#include "test.h"

static atmos_context *ctx;

static int nodes(const atmos__beams_sky *s) { return BEAMS_SKY_NY * BEAMS_SKY_NA * s->nw; }

/* The worst relative difference of a against b over b's values above 1e-3 of its largest;
 * -1 when the sizes differ. */
static double worst(const atmos__beams_sky *a, const atmos__beams_sky *b)
{
    if (a->nw != b->nw || !a->E || !b->E) return -1;
    double top = 0, w = 0;
    for (int i = 0; i < nodes(b); i++) top = fmax(top, b->E[i]);
    for (int i = 0; i < nodes(b); i++)
        if (b->E[i] > 1e-3 * top) w = fmax(w, fabs(a->E[i] - b->E[i]) / b->E[i]);
    return w;
}

static int same(const atmos__beams_sky *a, const atmos__beams_sky *b)
{
    if (a->nw != b->nw || !a->E || !b->E) return 0;
    return !memcmp(a->E, b->E, sizeof(float) * (size_t)nodes(a));
}

/* atmos__beams_sky_irradiance_memo against the call it stands for, bit for bit, over a run of
 * normals and layers that repeat, differ in C alone (a memo keyed on the normal alone fails
 * here) or in a zero's sign alone; counts the mismatches. */
static int memo_mismatches(const atmos__beams_sky *s)
{
    const double C[] = {0.3, 0.3, 0.31, 0.31, 0.31, 2.0, 2.0, 0.0};
    const double n[][3] = {{0, 1, 0}, {0, 1, 0}, {0, 1, 0}, {-0.0, 1, 0}, {-0.0, 1, -0.0}, {0.6, 0, 0.8}, {0.6, 0, 0.8}, {0, -1, 0}};
    atmos__beams_sky_memo memo = {{0, 0, 0}, 0, 0, {0}};
    int bad = 0;
    for (int i = 0; i < 8; i++) {
        double a[ATMOS_MAX_WAVELENGTHS], b[ATMOS_MAX_WAVELENGTHS];
        atmos__beams_sky_irradiance(s, n[i], C[i], a);
        const double *e = atmos__beams_sky_irradiance_memo(s, n[i], C[i], b, &memo);
        bad += memcmp(a, e, sizeof(double) * (size_t)s->nw) != 0;
        bad += memcmp(a, atmos__beams_sky_irradiance_memo(s, n[i], C[i], b, NULL), sizeof(double) * (size_t)s->nw) != 0;
    }
    return bad;
}

/* The point a along the sun's azimuth and c across it, as atmos__beams_sky_keep makes it, at
 * height y. */
static void at(const double sun[3], double a, double c, double y, double p[3])
{
    double u[2];
    atmos__beams_sky_axes(sun, u);
    p[0] = a * u[0] - c * u[1] + 0.0, p[1] = y, p[2] = a * u[1] + c * u[0] + 0.0;
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_atmosphere_desc desc;
    atmos_atmosphere_defaults(&desc);
    desc.kind = ATMOS_ATMOSPHERE_SPHERICAL, desc.ground_albedo = 0.15;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *atm = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, &wl, &atm));
    const int nw = wl.count;
    const double Q = BEAMS_SKY_KEEP_M, Qc = BEAMS_SKY_KEEP_ACROSS_M, el[3] = {8, 30, -3};
    for (int e = 0; e < 3; e++) {
        double sun[3], eye1[3], eye2[3], eye3[3], q3[3], eye4[3], p4[3], q3b[3];
        atmos_direction_from_angles(el[e], 266, sun);
        atmos__beams_sky keep = {0}, fresh = {0}, exact = {0};
        const double q0[3] = {0, 0, 0};
        at(sun, 0.3 * Q, -0.2 * Qc, 200, eye1), at(sun, 0.1 * Q, 0.4 * Qc, 250, eye2);
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye1, sun, nw, 0, &keep));
        const float mark = keep.E[0];
        keep.E[0] = -1; /* a table made again would not keep this */
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye2, sun, nw, 0, &keep));
        CHECK_MSG(keep.E[0] == -1, "an eye moved within its quantum: the table was made again");
        keep.E[0] = mark;
        CHECK_OK(atmos__beams_sky_build(ctx, atm, q0, sun, nw, 0, &fresh));
        CHECK_MSG(same(&keep, &fresh), "the kept table differs from a fresh one at the quantised point");
        atmos__beams_sky_free(&fresh);
        /* another quantum */
        at(sun, 3.6 * Q, -1.7 * Qc, 200, eye3), at(sun, 4 * Q, -2 * Qc, 0, q3);
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye3, sun, nw, 0, &keep));
        CHECK_OK(atmos__beams_sky_build(ctx, atm, q3, sun, nw, 0, &fresh));
        CHECK_MSG(same(&keep, &fresh), "after the eye left its quantum: not the fresh table of the new one");
        atmos__beams_sky_free(&fresh);
        /* the quantisation's cost: half a quantum along and across away */
        at(sun, 4.5 * Q - 1e-6, -2.5 * Qc + 1e-6, 10, eye4), at(sun, 4.5 * Q - 1e-6, -2.5 * Qc + 1e-6, 0, p4);
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye4, sun, nw, 0, &keep));
        CHECK_OK(atmos__beams_sky_build(ctx, atm, p4, sun, nw, 0, &exact));
        const double w = worst(&keep, &exact);
        printf("sun %g deg up: the table half a quantum (%g m along the sun's azimuth, %g m across) from the true "
               "point: worst relative difference %.3g\n", el[e], 0.5 * Q, 0.5 * Qc, w);
        CHECK_MSG(w >= 0 && w < 1e-3, "quantisation error %.3g", w);
        atmos__beams_sky_free(&exact);
        /* another sun */
        double sun2[3];
        atmos_direction_from_angles(el[e] + 1, 266, sun2);
        at(sun2, 4 * Q, -2 * Qc, 0, q3b); /* eye4 lies in this quantum for sun2 too */
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye4, sun2, nw, 0, &keep));
        CHECK_OK(atmos__beams_sky_build(ctx, atm, q3b, sun2, nw, 0, &fresh));
        CHECK_MSG(same(&keep, &fresh), "after the sun moved: not the fresh table");
        atmos__beams_sky_free(&fresh);
        /* the same eye and sun with a height-dependent fog: the table made again with its layers */
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye4, sun2, nw, 1, &keep));
        CHECK_MSG(keep.nc == BEAMS_SKY_NC, "layered after unlayered: %d values of C kept", keep.nc);
        CHECK_OK(atmos__beams_sky_build(ctx, atm, q3b, sun2, nw, 1, &fresh));
        CHECK_MSG(keep.nc == fresh.nc && same(&keep, &fresh), "layered: not the fresh table");
        CHECK_MSG(memo_mismatches(&keep) == 0, "the memo's irradiance differs from the call's");
        atmos__beams_sky_free(&fresh);
        CHECK_OK(atmos__beams_sky_keep(ctx, atm, eye4, sun2, nw, 0, &keep));
        CHECK_MSG(keep.nc == 1, "unlayered after layered: %d values of C kept", keep.nc);
        atmos__beams_sky_free(&keep);
    }
    atmos_atmosphere_destroy(atm);
    atmos_context_destroy(ctx);
    return test_summary("test_beams_sky_keep");
}
