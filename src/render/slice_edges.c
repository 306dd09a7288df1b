/* The slice renderer's edge pixels ("edge_aa"; docs/slice.md, "Antialiasing at the edges").
 *
 * The path tracer's samples spread over each pixel, the slice renderer's one eye ray goes
 * through its centre: where the volume's coverage changes within a pixel (its silhouette,
 * a thin fringe) the centre sample misses or overstates the pixel's share of the volume.
 * With eye_scale 2 every pixel takes four rays; edge_aa takes them only where they matter:
 * the pixels whose transmittance through the volume along the centre ray differs from one
 * of their eight neighbours' by more than edge_aa. The eye buffer is then twice the image per
 * axis, but the other pixels trace one ray through their centre, at eye pixel (2x, 2y), and
 * the three others are left out of the passes (their slice range empty). */
#include "atmosphere/atmosphere_ops.h"
#include "core/vec.h"
#include "render/slice_internal.h"

#include <math.h>
#include <stdlib.h>

int atmos__slice_edge_mode(const atmos__slice_plan *sp, const atmos__view *v)
{
    return sp->edge_aa > 0 && v->eye_scale == 1.0;
}

/* The volume's optical depth along the image ray dw (world) in front of the eye and of the
 * ground, with the cross-sections sig[] per field: the render grid's trilinear densities at
 * the midpoints of steps of at most a render voxel. */
static double ray_tau(const atmos__slice_plan *sp, const atmos_atmosphere *atm, const atmos_camera *cam,
                      const double eye[3], const double dw[3], const float *sig)
{
    const sgrid *g = &sp->g;
    double d[3], ta, tb;
    atmos__vol_dir_to_frame(&sp->x, dw, d);
    if (!atmos__ray_box(eye, d, g->box_lo, g->box_hi, &ta, &tb)) return 0;
    if (ta < 0) ta = 0;
    const double tg = atmos_atmosphere_ground_distance(atm, cam->position, dw);
    if (tb > tg) tb = tg;
    if (!(ta < tb)) return 0;
    const double len = (tb - ta) * g->sc; /* render voxels */
    const int ns = len > 4e6 ? 4000000 : (int)ceil(len) + 1;
    const double dt = (tb - ta) / ns;
    double tau = 0;
    float dens[ATMOS_VOLUME_MAX_FIELDS];
    for (int i = 0; i < ns; i++) {
        const double t = ta + (i + 0.5) * dt;
        float u[3];
        for (int a = 0; a < 3; a++) u[a] = (float)((eye[a] + t * d[a]) * g->sc + g->off[a]);
        if (!sgrid_sample_u(g, u[0], u[1], u[2], dens)) continue;
        for (int f = 0; f < g->nf; f++) tau += (dens[f] > 0.0f ? dens[f] : 0.0f) * (double)sig[f];
    }
    return tau * dt;
}

int atmos__slice_edges(atmos__slice_plan *sp, const atmos_atmosphere *atm, const atmos__view *v, sjob *j, int threads)
{
    const atmos_camera *cam = &v->cam;
    const int W = cam->width, H = cam->height;
    const size_t np = (size_t)W * H, need = np * (sizeof(float) + 1);
    if (need > sp->edge_cap) {
        unsigned char *b = realloc(sp->edge, need);
        if (!b) return 0;
        sp->edge = b, sp->edge_cap = need;
    }
    float *T = (float *)sp->edge; /* the transmittance per pixel, then the flags */
    unsigned char *flag = sp->edge + np * sizeof(float);
    float sig[ATMOS_VOLUME_MAX_FIELDS]; /* the plain cross-sections (not delta-M's): the coverage seen */
    for (int f = 0; f < sp->nf; f++) sig[f] = sp->tab.sig[f][sp->n / 2];
    /* only the pixels the eye spans reach (both eye rows of an image row; unclipped, so the
     * flags do not depend on the region rendered): the volume is zero along the others */
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int y = 0; y < H; y++) {
        const sspan a = j->erow[2 * y], b = j->erow[2 * y + 1];
        const int x0 = (a.x0 < b.x0 ? a.x0 : b.x0) / 2, x1 = (a.x1 > b.x1 ? a.x1 : b.x1) / 2;
        for (int x = 0; x < W; x++) {
            double dw[3], tau = 0;
            if (x >= x0 && x <= x1) {
                atmos_camera_ray(cam, x + 0.5, y + 0.5, dw);
                tau = ray_tau(sp, atm, cam, j->eye, dw, sig);
            }
            T[(size_t)y * W + x] = (float)exp(-tau);
        }
    }
    const float lim = (float)sp->edge_aa;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const float t = T[(size_t)y * W + x];
            int e = 0;
            for (int b = y > 0 ? y - 1 : 0; b <= y + 1 && b < H && !e; b++)
                for (int a = x > 0 ? x - 1 : 0; a <= x + 1 && a < W; a++)
                    if (fabsf(T[(size_t)b * W + a] - t) > lim) {
                        e = 1;
                        break;
                    }
            flag[(size_t)y * W + x] = (unsigned char)e;
        }
    j->edge = flag;
    return 1;
}
