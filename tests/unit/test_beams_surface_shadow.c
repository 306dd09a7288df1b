/* The surfaces' shadows of the lights settled from their shadow maps (atmos__beams_surface_visible,
 * src/render/beams_shadow.c, docs/beams.md "Surfaces' shadows"): a point whose 3 x 3 texels round
 * its own hold no surface nearer the light than the point (less a slope-scaled bias) is lit, one
 * whose texels all do is in shadow, and the others are left to an exact shadow ray. Checked
 * against exact shadow rays through the meshes (independent: ray-triangle tests alone): the
 * points where camera rays meet a floor with boxes standing on it and floating over it, lit by
 * a point light (a cube of maps) and by a spot (one frustum), 512 texels a side as the renderer's
 * default: no point is settled wrongly, and the maps settle at least 90 % of the points. */
#include "atmos/atmos.h"
#include "render/beams_internal.h"
#include "test.h"
#include "test_mesh.h"

#include <math.h>
#include <string.h>

static atmos_context *ctx;

static atmos_mesh *placed(atmos_mesh *m, double x, double y, double z, double sx, double sy, double sz)
{
    return test_mesh_place(ctx, m, x, y, z, sx, sy, sz, 0);
}

static int blocked(atmos_mesh *const *mesh, int n, const double o[3], const double d[3], double t1)
{
    for (int i = 0; i < n; i++)
        if (atmos_mesh_intersect(mesh[i], o, d, 0, t1, NULL)) return 1;
    return 0;
}

/* The points a 160 x 120 camera at eye sees, looking down at the scene: counted against the
 * exact rays. */
static void check(atmos_mesh *const *mesh, int nmesh, const atmos__beams_light *l, const char *name)
{
    const double eye[3] = {0, 6, 9};
    int points = 0, shadow = 0, settled = 0, wrong = 0;
    for (int j = 0; j < 120; j++)
        for (int i = 0; i < 160; i++) {
            double d[3] = {(i + 0.5 - 80) / 100.0, -0.6 - (j + 0.5 - 60) / 100.0, -1};
            const double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (int a = 0; a < 3; a++) d[a] /= n;
            atmos_mesh_hit best = {INFINITY, -1, {0, 0, 0}}, h;
            for (int m = 0; m < nmesh; m++)
                if (atmos_mesh_intersect(mesh[m], eye, d, 0, best.t, &h)) best = h;
            if (!(best.t < INFINITY)) continue;
            double P[3], w[3];
            for (int a = 0; a < 3; a++) P[a] = eye[a] + best.t * d[a], w[a] = l->L.pos[a] - P[a];
            const double r = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
            for (int a = 0; a < 3; a++) w[a] /= r;
            const double c = best.normal[0] * w[0] + best.normal[1] * w[1] + best.normal[2] * w[2];
            if (!(c > 0) || atmos__lamp_falloff(&l->L, P) <= 0) continue;
            const double off = 1e-4 * (1 + best.t); /* as the renderer offsets the point */
            double o[3];
            for (int a = 0; a < 3; a++) o[a] = P[a] + off * best.normal[a];
            const int b = blocked(mesh, nmesh, o, w, r - off), v = atmos__beams_surface_visible(l, P, c);
            points++, shadow += b, settled += v >= 0, wrong += v >= 0 && v == b;
        }
    printf("%s: %d points facing the light, %d in shadow by exact rays, %d settled by the map, %d of them wrongly\n",
           name, points, shadow, settled, wrong);
    CHECK_MSG(points > 5000 && shadow > 500, "%s: too few points to test: %d, %d in shadow", name, points, shadow);
    CHECK_MSG(wrong == 0, "%s: %d points settled wrongly by the map", name, wrong);
    CHECK_MSG(settled >= 0.9 * points, "%s: the map settled only %d of %d points", name, settled, points);
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_mesh *mesh[4] = {NULL, NULL, NULL, NULL};
    CHECK_OK(atmos_mesh_load(ctx, "builtin:plane", 0, &mesh[0]));
    CHECK_OK(atmos_mesh_load(ctx, "builtin:box", 0, &mesh[1]));
    CHECK_OK(atmos_mesh_load(ctx, "builtin:box", 0, &mesh[2]));
    CHECK_OK(atmos_mesh_load(ctx, "builtin:box", 0, &mesh[3]));
    if (!mesh[0] || !mesh[1] || !mesh[2] || !mesh[3]) return test_summary("test_beams_surface_shadow");
    placed(mesh[0], 0, 0, 0, 40, 40, 40);
    placed(mesh[1], -1.5, 1, -1, 1, 1, 1);         /* standing on the floor */
    placed(mesh[2], 1.2, 1.5, -0.5, 1.2, 0.2, 0.8);     /* floating over it */
    placed(mesh[3], 0.3, 0.75, -3, 0.15, 0.75, 0.15);   /* a post */
    for (int k = 0; k < 2; k++) {
        atmos__beams_light l;
        memset(&l, 0, sizeof l);
        l.L.type = k ? ATMOS_LIGHT_SPOT : ATMOS_LIGHT_POINT;
        l.L.pos[0] = 0.4, l.L.pos[1] = 3, l.L.pos[2] = -0.8;
        l.L.axis[0] = 0, l.L.axis[1] = -1, l.L.axis[2] = 0;
        l.L.cos_inner = cos(50 * ATMOS_DEG2RAD), l.L.cos_outer = cos(58 * ATMOS_DEG2RAD);
        l.L.range = INFINITY;
        atmos__beams_progress pr = {0, atmos__beams_shadow_faces(&l.L, 4), 0};
        CHECK_OK(atmos__beams_shadow_build(ctx, &l, mesh, 4, 512, &pr));
        check(mesh, 4, &l, k ? "spot" : "point light");
        atmos__beams_shadow_free(&l);
    }
    for (int m = 0; m < 4; m++) atmos_mesh_destroy(mesh[m]);
    atmos_context_destroy(ctx);
    return test_summary("test_beams_surface_shadow");
}
