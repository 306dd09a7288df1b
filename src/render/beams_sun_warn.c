/* A warning for a sun's shadow map stretched by one far object (beams_sun.h): the orthographic
 * map spans every object's bounds, so one vertex far away makes its texels so large that the
 * shadows (and the shafts in the fog) of everything else are lost without a word. */
#include "render/beams_sun.h"
#include "core/vec.h"

#include <math.h>

/* The map's texels are "too large" when they exceed this many times the median size of the
 * objects' triangles (their bounding boxes' largest side): most triangles then fall within
 * a texel, and shadows of things that size cannot show. */
#define TEXEL_PER_TRIANGLE 16.0

void atmos__beams_sun_warn_texel(atmos_context *ctx, const atmos__beams_sun *s, atmos_mesh *const *mesh, int nmesh)
{
    if (s->n == 0) return;
    long small = 0, all = 0;
    int widest = -1;
    double wide = -1;
    for (int m = 0; m < nmesh; m++) {
        const atmos_mesh *M = mesh[m];
        long ms = 0; /* the mesh's small triangles: a count, the same with any number of threads */
#pragma omp parallel for schedule(static) reduction(+ : ms) num_threads(atmos__threads(ctx))
        for (int t = 0; t < M->triangle_count; t++) {
            double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 3; a++) {
                    const double x = M->positions[3 * M->indices[3 * t + k] + a];
                    lo[a] = fmin(lo[a], x), hi[a] = fmax(hi[a], x);
                }
            const double size = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
            ms += size * TEXEL_PER_TRIANGLE < s->texel;
        }
        small += ms, all += M->triangle_count;
        /* the object whose bounds across the sun's rays are the widest sets the map's extent */
        double u0 = INFINITY, u1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
        for (int i = 0; i < M->vertex_count; i++) {
            const double q[3] = {M->positions[3 * i], M->positions[3 * i + 1], M->positions[3 * i + 2]};
            const double u = atmos__dot3(q, s->right), v = atmos__dot3(q, s->up);
            u0 = fmin(u0, u), u1 = fmax(u1, u), v0 = fmin(v0, v), v1 = fmax(v1, v);
        }
        if (fmax(u1 - u0, v1 - v0) > wide) wide = fmax(u1 - u0, v1 - v0), widest = m;
    }
    if (2 * small <= all) return;
    atmos__log(ctx, ATMOS_LOG_WARN,
               "the sun's %dx%d shadow map has texels of %.3g m, larger than %g times most of the objects' "
               "triangles: its extent (%.3g m) is set by the bounds of /objects/%d; shadows and shafts smaller "
               "than a few texels are lost (docs/beams.md, \"The sun\")",
               s->n, s->n, s->texel, TEXEL_PER_TRIANGLE, wide, widest);
}
