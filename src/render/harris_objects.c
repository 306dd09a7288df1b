/* Objects inside Harris's particle clouds (harris_internal.h; Harris 2002 §3.2, Fig. 12): the
 * scene's meshes drawn per pixel, opaque and Lambertian, lit by the sun and the sky lights as
 * the particles are, through the clouds' light buffers (each vertex reads every cloud's light
 * pass as a particle would, pshade.c's probes), with the air between the eye and the surface.
 * The frame puts this layer between the far and the near parts of the clouds it lies in
 * (harris_frame.c: impostor splitting). */
#include "render/harris_internal.h"
#include "render/objects.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

atmos_status atmos__harris_objects_create(atmos_plan *p, atmos__harris_objects **out)
{
    *out = NULL;
    atmos__harris_objects *ob = calloc(1, sizeof *ob);
    if (!ob) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the objects");
    atmos__objects loaded;
    atmos_status st = atmos__objects_load(p->ctx, &p->scene, &p->wl, &loaded);
    ob->mesh = loaded.mesh, ob->albedo = loaded.albedo, ob->n = loaded.n; /* freed by the destroy below */
    for (int m = 0; m < ob->n && st == ATMOS_OK; m++) ob->nv += ob->mesh[m]->vertex_count;
    if (st == ATMOS_OK && !(ob->xyz = malloc(sizeof(float) * 3 * (size_t)ob->nv)))
        st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the objects");
    if (st == ATMOS_OK && !(ob->first = malloc(sizeof(int) * (size_t)(ob->n + 1))))
        st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the objects");
    for (int j = 0; j < ATMOS__HARRIS_MAX_LIGHTS && st == ATMOS_OK; j++)
        if (!(ob->light[j] = malloc(sizeof(float) * (size_t)ob->nv * p->wl.count)))
            st = atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the objects");
    if (st != ATMOS_OK) {
        atmos__harris_objects_destroy(ob);
        return st;
    }
    /* the probes: every vertex; the bounding sphere of all of them (the split's centre) */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int m = 0, v = 0; m < ob->n; m++) {
        const atmos_mesh *me = ob->mesh[m];
        ob->first[m] = v;
        memcpy(ob->xyz + 3 * (size_t)v, me->positions, sizeof(float) * 3 * (size_t)me->vertex_count);
        v += me->vertex_count;
        for (int a = 0; a < 3; a++) lo[a] = fmin(lo[a], me->lo[a]), hi[a] = fmax(hi[a], me->hi[a]);
    }
    ob->first[ob->n] = ob->nv;
    double r2 = 0;
    for (int a = 0; a < 3; a++) ob->centre[a] = 0.5 * (lo[a] + hi[a]), r2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    ob->radius = sqrt(r2);
    *out = ob;
    return ATMOS_OK;
}

void atmos__harris_objects_destroy(atmos__harris_objects *ob)
{
    if (!ob) return;
    for (int m = 0; m < ob->n; m++) atmos_mesh_destroy(ob->mesh[m]);
    free(ob->mesh), free(ob->albedo), free(ob->xyz), free(ob->first);
    for (int j = 0; j < ATMOS__HARRIS_MAX_LIGHTS; j++) free(ob->light[j]);
    free(ob->depth), free(ob->col);
    free(ob);
}

/* The radiance leaving the surface of mesh m at hit (from the ray o + t d): albedo / pi times
 * each light's irradiance on it (its irradiance outside the clouds, the cosine, the share the
 * clouds' light passes leave at the triangle's vertices, interpolated barycentrically). */
static void shade(const atmos__harris_plan *h, const atmos__harris_objects *ob, int m, const atmos_mesh_hit *hit,
                  const double o[3], const double d[3], double *L)
{
    const atmos_mesh *me = ob->mesh[m];
    const uint32_t *tri = me->indices + 3 * (size_t)hit->triangle;
    const float *A = me->positions + 3 * (size_t)tri[0], *B = me->positions + 3 * (size_t)tri[1],
                *C = me->positions + 3 * (size_t)tri[2];
    double e1[3], e2[3], w[3], d11 = 0, d12 = 0, d22 = 0, dw1 = 0, dw2 = 0;
    for (int a = 0; a < 3; a++) {
        e1[a] = B[a] - A[a], e2[a] = C[a] - A[a], w[a] = o[a] + hit->t * d[a] - A[a];
        d11 += e1[a] * e1[a], d12 += e1[a] * e2[a], d22 += e2[a] * e2[a], dw1 += w[a] * e1[a], dw2 += w[a] * e2[a];
    }
    const double den = d11 * d22 - d12 * d12;
    double b1 = den > 0 ? (d22 * dw1 - d12 * dw2) / den : 0, b2 = den > 0 ? (d11 * dw2 - d12 * dw1) / den : 0;
    b1 = fmin(fmax(b1, 0.0), 1.0), b2 = fmin(fmax(b2, 0.0), 1.0 - b1);
    const double bw[3] = {1.0 - b1 - b2, b1, b2};
    const int nw = h->o.nw;
    for (int k = 0; k < nw; k++) L[k] = 0;
    for (int j = 0; j < h->nlights; j++) {
        const double c = hit->normal[0] * h->dir[j][0] + hit->normal[1] * h->dir[j][1] + hit->normal[2] * h->dir[j][2];
        if (!(c > 0)) continue;
        for (int k = 0; k < nw; k++) {
            double s = 0;
            for (int i = 0; i < 3; i++) s += bw[i] * ob->light[j][((size_t)ob->first[m] + tri[i]) * nw + k];
            L[k] += h->e[j][k] * c * s;
        }
    }
    for (int k = 0; k < nw; k++) L[k] *= ob->albedo[m][k] / ATMOS_PI;
}

/* The ray of cam through image point (x, y) (pixel units; a pixel's centre at + 0.5), unit;
 * 0 where there is none (outside a fisheye's circle). */
static int pixel_ray(const atmos_camera *cam, double x, double y, double d[3])
{
    if (cam->type != ATMOS_CAMERA_PINHOLE) return atmos_camera_ray(cam, x, y, d);
    const double W = cam->width, H = cam->height, t = cam->tan_half_fov;
    const double u = (2.0 * x - W) / H * t, v = (H - 2.0 * y) / H * t;
    double l = 0;
    for (int i = 0; i < 3; i++) d[i] = cam->forward[i] + u * cam->right[i] + v * cam->up[i], l += d[i] * d[i];
    for (int i = 0; i < 3; i++) d[i] /= sqrt(l);
    return 1;
}

/* Pixel (x, y) of the layer: 2 x 2 rays (stratified), the nearest surface of each; the
 * coverage is the share of them that meet one, the colour their mean (premultiplied), the depth
 * the nearest. */
static void subpixels(const atmos_plan *p, const atmos__harris_plan *h, atmos__harris_objects *ob, const atmos__view *v,
                      const atmos__aerial *ap, int x, int y)
{
    const atmos_camera *cam = &v->cam;
    const int nw = h->o.nw;
    const size_t at = (size_t)y * cam->width + x;
    double sum[ATMOS_MAX_WAVELENGTHS] = {0}, nearest = INFINITY;
    int hits = 0;
    for (int s = 0; s < 4; s++) {
        double d[3], best = INFINITY, L[ATMOS_MAX_WAVELENGTHS], La[ATMOS_MAX_WAVELENGTHS], Ta[ATMOS_MAX_WAVELENGTHS];
        if (!pixel_ray(cam, x + 0.25 + 0.5 * (s & 1), y + 0.25 + 0.5 * (s >> 1), d)) continue;
        atmos_mesh_hit hit, first;
        int mb = -1;
        for (int m = 0; m < ob->n; m++)
            if (atmos_mesh_intersect(ob->mesh[m], cam->position, d, 0.0, best, &hit)) best = hit.t, first = hit, mb = m;
        if (mb < 0) continue;
        hits++, nearest = fmin(nearest, best);
        shade(h, ob, mb, &first, cam->position, d, L);
        if (!ap || !atmos__aerial_eval(ap, d, best, La, Ta)) {
            atmos_atmosphere_inscatter(p->atm, cam->position, d, best, v->sun, La);
            atmos_atmosphere_transmittance(p->atm, cam->position, d, best, Ta);
        }
        for (int k = 0; k < nw; k++) sum[k] += La[k] + Ta[k] * L[k];
    }
    ob->depth[at] = (float)nearest, ob->cover[at] = 0.25f * hits;
    for (int k = 0; k < nw; k++) ob->col[at * nw + k] = (float)(0.25 * sum[k]);
}

atmos_status atmos__harris_objects_frame(const atmos_plan *p, const atmos__harris_plan *h, atmos__harris_objects *ob,
                                         const atmos__view *v, const atmos__aerial *ap, const int rect[4])
{
    const atmos_camera *cam = &v->cam;
    const int nw = h->o.nw;
    const size_t npx = (size_t)cam->width * cam->height;
    if (npx > ob->cap) {
        free(ob->depth), free(ob->col);
        ob->depth = malloc(sizeof(float) * npx * 2), ob->col = malloc(sizeof(float) * npx * nw);
        ob->cover = ob->depth ? ob->depth + npx : NULL;
        ob->cap = ob->depth && ob->col ? npx : 0;
        if (!ob->cap) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render harris: out of memory for the objects' layer");
    }
    int bb[4];
    double Z;
    if (!atmos__pcloud_screen_box(cam, ob->centre, ob->radius, rect, bb, &Z)) {
        double d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (cam->position[a] - ob->centre[a]) * (cam->position[a] - ob->centre[a]);
        if (d2 > ob->radius * ob->radius) { /* out of view */
            memset(ob->box, 0, sizeof ob->box);
            return ATMOS_OK;
        }
        bb[0] = rect[0], bb[1] = rect[2], bb[2] = rect[1], bb[3] = rect[3]; /* the eye among the objects */
    }
    memcpy(ob->box, bb, sizeof ob->box);
#pragma omp parallel for schedule(dynamic, 4) num_threads(atmos__threads(p->ctx))
    for (int y = bb[2]; y < bb[3]; y++)
        for (int x = bb[0]; x < bb[1]; x++)
            subpixels(p, h, ob, v, ap, x, y);
    return ATMOS_OK;
}

void atmos__harris_objects_over(atmos_context *ctx, const atmos__harris_objects *ob, int nw, const atmos_camera *cam,
                                 atmos_image *img)
{
    const int C = img->channels;
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (int y = ob->box[2]; y < ob->box[3]; y++)
        for (int x = ob->box[0]; x < ob->box[1]; x++) {
            const size_t at = (size_t)y * cam->width + x;
            if (!(ob->cover[at] > 0)) continue;
            float *px = img->pixels + at * C;
            const float keep = 1.0f - ob->cover[at];
            for (int k = 0; k < nw; k++) px[k] = px[k] * keep + ob->col[at * nw + k];
            px[nw] = 1.0f - (1.0f - px[nw]) * keep;
        }
}
