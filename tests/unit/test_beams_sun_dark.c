/* The surfaces' sunlight settled from the sun's shadow map (atmos__beams_sun_dark,
 * src/render/beams_sun.c, docs/beams.md "The sun"): a point whose finest tile of the map (8 x 8
 * texels and the ring a filtered look-up reads) holds only depths nearer the sun than the
 * point by more than two texels is in shadow, and the renderer casts no ray toward the sun
 * from it. Checked against exact shadow rays through the meshes: the points where camera rays
 * meet generated ridges 3 km high on a plane with a box floating over it (Fig. 10(a)'s kind of
 * scene), lit by the sun 8 and 30 degrees up: every point the map calls dark is dark by the
 * exact ray (none wrong), and the map settles at least half of the points in shadow (so the
 * shortcut spares rays). */
#include "atmos/atmos.h"
#include "render/beams_sun.h"
#include "test.h"
#include "test_mesh.h"

static atmos_context *ctx;

static atmos_mesh *placed(atmos_mesh *m, double x, double y, double z, double sx, double sy, double sz)
{
    return test_mesh_place(ctx, m, x, y, z, sx, sy, sz, 0);
}

static int blocked(atmos_mesh *const *mesh, int n, const double o[3], const double d[3])
{
    for (int i = 0; i < n; i++)
        if (atmos_mesh_intersect(mesh[i], o, d, 0, INFINITY, NULL)) return 1;
    return 0;
}

int main(void)
{
    CHECK_OK(atmos_context_create(NULL, &ctx));
    atmos_mesh *mesh[3] = {NULL, NULL, NULL};
    const atmos_terrain_desc td = {"generate:ridges", 16000, 3000, 0, 0, 0, 129, 11};
    CHECK_OK(atmos_mesh_terrain(ctx, &td, &mesh[0]));
    CHECK_OK(atmos_mesh_load(ctx, "builtin:plane", 0, &mesh[1]));
    CHECK_OK(atmos_mesh_load(ctx, "builtin:box", 0, &mesh[2]));
    if (!mesh[0] || !mesh[1] || !mesh[2]) return test_summary("test_beams_sun_dark");
    placed(mesh[0], -16000, 0, 0, 1, 1, 1), placed(mesh[1], 0, 0, 0, 30000, 30000, 30000);
    placed(mesh[2], -3000, 400, 500, 300, 100, 300);
    const double eye[3] = {0, 200, 0};
    for (int e = 0; e < 2; e++) {
        double sun[3];
        atmos_direction_from_angles(e ? 30 : 8, 266, sun);
        atmos__beams_sun s;
        memset(&s, 0, sizeof s);
        CHECK_OK(atmos__beams_sun_build(ctx, &s, sun, mesh, 3, 2048));
        int points = 0, shadow = 0, dark = 0, wrong = 0;
        for (int j = 0; j < 120; j++)
            for (int i = 0; i < 240; i++) { /* 120 degrees wide, from 2 up to 40 degrees down, toward the sun */
                double d[3];
                atmos_direction_from_angles(2 - 42.0 * (j + 0.5) / 120, 206 + 120.0 * (i + 0.5) / 240, d);
                atmos_mesh_hit best = {INFINITY, -1, {0, 0, 0}}, h;
                for (int m = 0; m < 3; m++)
                    if (atmos_mesh_intersect(mesh[m], eye, d, 0, best.t, &h)) best = h;
                if (!(best.t < INFINITY)) continue;
                const double c = best.normal[0] * sun[0] + best.normal[1] * sun[1] + best.normal[2] * sun[2];
                if (!(c > 0)) continue;
                const double off = 1e-4 * (1 + best.t); /* as the renderer offsets the point */
                double o[3];
                for (int a = 0; a < 3; a++) o[a] = eye[a] + best.t * d[a] + off * best.normal[a];
                const int b = blocked(mesh, 3, o, sun), k = atmos__beams_sun_dark(&s, o);
                points++, shadow += b, dark += k, wrong += k && !b;
            }
        printf("sun %g deg up: %d points facing the sun, %d in shadow by exact rays, %d settled dark by the map, "
               "%d of them wrongly\n", e ? 30.0 : 8.0, points, shadow, dark, wrong);
        CHECK_MSG(points > 5000 && shadow > 500, "too few points to test: %d, %d in shadow", points, shadow);
        CHECK_MSG(wrong == 0, "%d points called dark by the map are lit", wrong);
        CHECK_MSG(dark >= shadow / 2, "the map settled only %d of %d points in shadow", dark, shadow);
        atmos__beams_sun_free(&s);
    }
    for (int m = 0; m < 3; m++) atmos_mesh_destroy(mesh[m]);
    atmos_context_destroy(ctx);
    return test_summary("test_beams_sun_dark");
}
