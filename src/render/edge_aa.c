/* The volume's edges in an image (edge_aa.h; docs/slice.md, "Antialiasing at the edges").
 *
 * A renderer's one eye ray through a pixel's centre misses or overstates the pixel's share of
 * the volume where its coverage changes within the pixel (its silhouette, a thin fringe); the
 * path tracer's samples spread over the pixel. The edges are found from the volume's
 * transmittance along the centre rays alone, before the renderer's own rays: the pixels whose
 * transmittance differs from one of their eight neighbours' by more than a step. */
#include "render/edge_aa.h"

#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>

/* beyond this optical depth the transmittance (< 1e-17) differs from any other such by nothing */
#define EDGE_TAU_MAX 40.0

/* The volume's optical depth along the image ray dw (world) in front of the eye and of the
 * ground: the render grid's trilinear densities at the midpoints of steps of at most a render
 * voxel, the cross-sections d->sig per field. */
static double ray_tau(const atmos__edge_desc *e, const double dw[3])
{
    const sgrid *g = e->g;
    double d[3], ta, tb;
    atmos__vol_dir_to_frame(e->x, dw, d);
    if (!atmos__ray_box(e->eye, d, g->box_lo, g->box_hi, &ta, &tb)) return 0;
    if (ta < 0) ta = 0;
    const double tg = atmos_atmosphere_ground_distance(e->atm, e->cam->position, dw);
    if (tb > tg) tb = tg;
    if (!(ta < tb)) return 0;
    const double len = (tb - ta) * g->sc; /* render voxels */
    const int ns = len > 4e6 ? 4000000 : (int)ceil(len) + 1;
    const double dt = (tb - ta) / ns, stop = EDGE_TAU_MAX / dt;
    double tau = 0;
    float dens[ATMOS_VOLUME_MAX_FIELDS];
    for (int i = 0; i < ns && tau < stop; i++) {
        const double t = ta + (i + 0.5) * dt;
        float u[3];
        for (int a = 0; a < 3; a++) u[a] = (float)((e->eye[a] + t * d[a]) * g->sc + g->off[a]);
        if (!sgrid_sample_u(g, u[0], u[1], u[2], dens)) continue;
        for (int f = 0; f < g->nf; f++) tau += (dens[f] > 0.0f ? dens[f] : 0.0f) * (double)e->sig[f];
    }
    return tau * dt;
}

const unsigned char *atmos__edge_flags(const atmos__edge_desc *e, const atmos__rect *r, unsigned char **buf,
                                       size_t *cap, int threads)
{
    const int W = e->cam->width, H = e->cam->height;
    const size_t np = (size_t)W * H, need = np * (sizeof(float) + 1);
    if (need > *cap) {
        unsigned char *b = realloc(*buf, need);
        if (!b) return NULL;
        *buf = b, *cap = need;
    }
    float *T = (float *)*buf; /* the transmittance per pixel, then the flags */
    unsigned char *flag = *buf + np * sizeof(float);
    /* the region and a pixel around it, clipped to the image */
    const int ya = r->y0 > 0 ? r->y0 - 1 : 0, yb = r->y1 < H ? r->y1 + 1 : H;
    const int xa = r->x0 > 0 ? r->x0 - 1 : 0, xb = r->x1 < W ? r->x1 + 1 : W;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int y = ya; y < yb; y++) {
        int x0 = 0, x1 = W - 1;
        if (e->row) e->row(e->row_ctx, y, &x0, &x1);
        for (int x = xa; x < xb; x++) {
            double dw[3], tau = 0;
            if (x >= x0 && x <= x1 && atmos_camera_ray(e->cam, x + 0.5, y + 0.5, dw)) tau = ray_tau(e, dw);
            T[(size_t)y * W + x] = (float)exp(-tau);
        }
    }
    const float lim = (float)e->lim;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) {
            const float t = T[(size_t)y * W + x];
            int ed = 0;
            for (int b = y > ya ? y - 1 : ya; b < yb && b <= y + 1 && !ed; b++)
                for (int a = x > xa ? x - 1 : xa; a < xb && a <= x + 1; a++)
                    if (fabsf(T[(size_t)b * W + a] - t) > lim) {
                        ed = 1;
                        break;
                    }
            flag[(size_t)y * W + x] = (unsigned char)ed;
        }
    return flag;
}
