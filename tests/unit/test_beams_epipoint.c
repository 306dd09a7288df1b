/* A point light's cube map along epipolar lines (src/render/beams_epipoint.c, docs/beams.md
 * *Shadow maps* and the nineteenth round under *Speed*): the lit stretches a ray gets from its
 * half-plane's 1-D trees against the shadow-map samples they replace (atmos__beams_visibility,
 * 2 x 2 filtered, at 20 000 midpoints along the ray), and against exact shadow rays through the
 * meshes. The scene: a floor with a box standing on it, a slab floating over it and a post, a
 * point light 3 m up among them (a cube map of 256 texels a side), seen from 6 m up and 9 m
 * away; each ray weighted by the unshadowed single scattering of the light without extinction,
 * 1 / |w(t)|^2 (w the offset from the light), whose integral over a stretch is closed form.
 * Bounds: every ray within 2 % of its unshadowed whole (the lines resample the map: an edge
 * moves by up to half a sample along a line, half the lines' spacing across them), the mean
 * within 0.15 %; the lines the same bytes for 1 and 2 threads. */
#include "atmos/atmos.h"
#include "render/beams_internal.h"
#include "test.h"
#include "test_mesh.h"

#include <math.h>
#include <string.h>

#define STEPS 20000

static atmos_context *ctx;

typedef struct acc {
    double tQ, v, sum;
} acc;

/* The unshadowed integral of 1 / |w(t)|^2 over [ta, tb]. */
static double weight(const acc *a, double ta, double tb)
{
    return (atan((tb - a->tQ) / a->v) - atan((ta - a->tQ) / a->v)) / a->v;
}

static void stretch(void *u, double ta, double tb, double w)
{
    acc *a = u;
    a->sum += w * weight(a, ta, tb);
}

static int blocked(atmos_mesh *const *mesh, int n, const double o[3], const double d[3], double t1)
{
    for (int i = 0; i < n; i++)
        if (atmos_mesh_intersect(mesh[i], o, d, 0, t1, NULL)) return 1;
    return 0;
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_mesh *mesh[4] = {NULL, NULL, NULL, NULL};
    const char *kind[4] = {"builtin:plane", "builtin:box", "builtin:box", "builtin:box"};
    for (int m = 0; m < 4; m++) CHECK_OK(atmos_mesh_load(ctx, kind[m], 0, &mesh[m]));
    if (!mesh[0] || !mesh[1] || !mesh[2] || !mesh[3]) return test_summary("test_beams_epipoint");
    test_mesh_place(ctx, mesh[0], 0, 0, 0, 40, 40, 40, 0);
    test_mesh_place(ctx, mesh[1], -1.5, 1, -1, 1, 1, 1, 0);
    test_mesh_place(ctx, mesh[2], 1.2, 1.5, -0.5, 1.2, 0.2, 0.8, 0);
    test_mesh_place(ctx, mesh[3], 0.3, 0.75, -3, 0.15, 0.75, 0.15, 0);
    atmos__beams_light l;
    memset(&l, 0, sizeof l);
    l.L.type = ATMOS_LIGHT_POINT;
    l.L.pos[0] = 0.4, l.L.pos[1] = 3, l.L.pos[2] = -0.8;
    l.L.range = INFINITY;
    atmos__beams_progress pr = {0, atmos__beams_shadow_faces(&l.L, 4), 0};
    CHECK_OK(atmos__beams_shadow_build(ctx, &l, mesh, 4, 256, &pr));
    const double eye[3] = {0, 6, 9};
    CHECK_MSG(atmos__beams_pl_build(&l.pl, &l, eye, (size_t)64 << 20, 1) == 0 && l.pl.lines > 0, "no lines");
    if (!l.pl.lines) return test_summary("test_beams_epipoint");
    /* the same lines with two threads */
    atmos__beams_light l2 = l;
    memset(&l2.pl, 0, sizeof l2.pl);
    CHECK(atmos__beams_pl_build(&l2.pl, &l2, eye, (size_t)64 << 20, 2) == 0 && l2.pl.lines == l.pl.lines);
    const size_t floats = (size_t)l.pl.lines * 3 * (l.pl.cnt + 2 * l.pl.cells);
    CHECK_MSG(l2.pl.m && !memcmp(l.pl.m, l2.pl.m, sizeof(float) * floats), "the lines differ with 2 threads");
    atmos__beams_pl_free(&l2.pl);
    int rays = 0, shadowed = 0, failed = 0;
    double worst = 0, mean = 0, worst_exact = 0;
    for (int j = 0; j < 45; j++)
        for (int i = 0; i < 60; i++) {
            double d[3] = {(i + 0.5 - 30) / 40.0, -0.45 - (j + 0.5 - 22.5) / 40.0, -1};
            const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int a = 0; a < 3; a++) d[a] /= n;
            atmos_mesh_hit best = {INFINITY, -1, {0, 0, 0}}, h;
            for (int m = 0; m < 4; m++)
                if (atmos_mesh_intersect(mesh[m], eye, d, 0, best.t, &h)) best = h;
            const double T = best.t < 30 ? best.t : 30;
            const double Lp[3] = {l.L.pos[0] - eye[0], l.L.pos[1] - eye[1], l.L.pos[2] - eye[2]};
            acc a = {Lp[0] * d[0] + Lp[1] * d[1] + Lp[2] * d[2], 0, 0};
            const double q[3] = {Lp[0] - a.tQ * d[0], Lp[1] - a.tQ * d[1], Lp[2] - a.tQ * d[2]};
            a.v = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
            if (atmos__beams_pl_walk(&l.pl, d, 0, T, stretch, &a)) {
                failed++;
                continue;
            }
            /* the shadow-map samples, and exact shadow rays, at the midpoints */
            double map = 0, exact = 0;
            const double dt = T / STEPS;
            for (int s = 0; s < STEPS; s++) {
                const double t = (s + 0.5) * dt;
                double P[3], w[3];
                for (int k = 0; k < 3; k++) P[k] = eye[k] + t * d[k], w[k] = l.L.pos[k] - P[k];
                const double r2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], r = sqrt(r2);
                for (int k = 0; k < 3; k++) w[k] /= r;
                map += atmos__beams_visibility(&l, P) / r2 * dt;
                if (s % 10 == 0) exact += (blocked(mesh, 4, P, w, r) ? 0 : 10) / r2 * dt;
            }
            const double whole = weight(&a, 0, T), e = fabs(a.sum - map) / whole;
            rays++, shadowed += map < 0.99 * whole, mean += e;
            worst = fmax(worst, e), worst_exact = fmax(worst_exact, fabs(a.sum - exact) / whole);
        }
    mean /= rays > 0 ? rays : 1;
    printf("%d lines of %d samples a piece; %d rays (%d shadowed, %d along the axis), against the map's samples: mean "
           "%.3g, worst %.3g of the unshadowed light; against exact rays worst %.3g\n",
           l.pl.lines, l.pl.cnt, rays, shadowed, failed, mean, worst, worst_exact);
    CHECK_MSG(rays > 2000 && shadowed > 300, "too few rays to test: %d, %d shadowed", rays, shadowed);
    CHECK_MSG(worst <= 0.02, "a ray off the map's samples by %.3g of its unshadowed light (bound 0.02)", worst);
    CHECK_MSG(mean <= 0.0015, "the rays off the map's samples by %.3g on average (bound 0.0015)", mean);
    atmos__beams_pl_free(&l.pl);
    atmos__beams_shadow_free(&l);
    for (int m = 0; m < 4; m++) atmos_mesh_destroy(mesh[m]);
    atmos_context_destroy(ctx);
    return test_summary("test_beams_epipoint");
}
