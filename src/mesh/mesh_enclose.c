/* A point shut inside a mesh, by the parity of a ray's crossings (mesh_enclose.h). */
#include "mesh/mesh_enclose.h"

#include <math.h>

#define MAX_CROSSINGS 100000 /* a bound on the walk along one ray */

/* How many times the ray p + t d, t > 0, crosses the mesh's surface. */
static long crossings(const atmos_mesh *m, const double p[3], const double d[3])
{
    long n = 0;
    double t0 = 0;
    atmos_mesh_hit h;
    while (n < MAX_CROSSINGS && atmos_mesh_intersect(m, p, d, t0, INFINITY, &h)) {
        n++;
        t0 = h.t + 1e-9 * (1 + h.t); /* past this hit (the positions are floats) */
    }
    return n;
}

int atmos__mesh_encloses(const atmos_mesh *m, const double p[3])
{
    if (!m || m->triangle_count <= 0) return 0;
    for (int k = 0; k < 3; k++)
        if (!(p[k] >= m->lo[k] && p[k] <= m->hi[k])) return 0;
    /* the axes, each tilted by small irrational amounts so that no ray runs along a face or
     * through a grid's rows of vertices */
    static const double tilt[3][3] = {{1, 0.1234567, 0.0765432}, {0.0876543, 1, 0.1345679}, {0.1123457, 0.0654321, 1}};
    for (int k = 0; k < 3; k++)
        for (int s = -1; s <= 1; s += 2) {
            const double d[3] = {s * tilt[k][0], s * tilt[k][1], s * tilt[k][2]};
            if (crossings(m, p, d) % 2 == 0) return 0;
        }
    return 1;
}
