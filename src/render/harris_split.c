/* Impostor splitting (Harris 2002 §3.2; harris_internal.h): with objects in view, the frame is
 * split at the distance from the eye to the objects' centre, as Harris splits a cloud's
 * impostor at the object inside it: the particles farther from the eye than that (their
 * centres) make a far layer drawn before the objects, the others a near layer drawn after. A
 * cloud the split's sphere crosses, whose image meets the objects', is split into its far and
 * near particles, each with its own impostor; every other cloud goes whole to the side of its
 * centre. */
#include "render/harris_internal.h"

#include <math.h>
#include <string.h>

static double dist(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* Cloud k's particles into h->part: the far ones first (ascending), then the near ones; 1 when
 * both sides have some. */
static int partition(atmos__harris_plan *h, const double eye[3], int k)
{
    const atmos__pclusters *c = &h->clouds;
    const int s = c->start[k], n = c->start[k + 1] - s;
    int nf = 0, nn = 0;
    for (int q = 0; q < n; q++) {
        const int i = c->idx[s + q];
        const double pc[3] = {h->pc.x[i], h->pc.y[i], h->pc.z[i]};
        if (dist(pc, eye) > h->split_m) h->part[s + nf++] = i;
    }
    for (int q = 0; q < n; q++) {
        const int i = c->idx[s + q];
        const double pc[3] = {h->pc.x[i], h->pc.y[i], h->pc.z[i]};
        if (!(dist(pc, eye) > h->split_m)) h->part[s + nf + nn++] = i;
    }
    h->nfar[k] = nf;
    return nf > 0 && nn > 0;
}

void atmos__harris_split(atmos__harris_plan *h, const atmos__view *v, const int rect[4], const int *how, int *side)
{
    const atmos__pclusters *c = &h->clouds;
    const double *eye = v->cam.position;
    h->splits = 0, h->split_m = INFINITY;
    for (int k = 0; k < c->n; k++) side[k] = ATMOS__HARRIS_NEAR;
    const atmos__harris_objects *ob = h->obj;
    if (!ob || ob->box[0] >= ob->box[1] || ob->box[2] >= ob->box[3]) return; /* none in view */
    h->split_m = dist(ob->centre, eye);
    for (int k = 0; k < c->n; k++) {
        if (!how[k]) continue;
        const double d = dist(c->centre[k], eye);
        h->offset[k] = h->split_m - d;
        side[k] = d > h->split_m ? ATMOS__HARRIS_FAR : ATMOS__HARRIS_NEAR;
        if (fabs(d - h->split_m) >= c->radius[k]) continue; /* wholly on one side */
        int bb[4];
        double Z;
        if (atmos__pcloud_screen_box(&v->cam, c->centre[k], c->radius[k], rect, bb, &Z) &&
            (bb[1] <= ob->box[0] || bb[0] >= ob->box[1] || bb[3] <= ob->box[2] || bb[2] >= ob->box[3]))
            continue; /* not in front of the objects nor behind them */
        if (partition(h, eye, k)) side[k] = ATMOS__HARRIS_SPLIT, h->splits++;
        else side[k] = h->nfar[k] ? ATMOS__HARRIS_FAR : ATMOS__HARRIS_NEAR;
    }
}

int atmos__harris_piece(const atmos__harris_plan *h, int k, int pass, int how, int side, const atmos__pimpostor **im,
                        const int **idx, int *n)
{
    const atmos__pclusters *c = &h->clouds;
    if (!how || (side == ATMOS__HARRIS_NEAR && pass == 0) || (side == ATMOS__HARRIS_FAR && pass == 1)) return 0;
    if (side != ATMOS__HARRIS_SPLIT) {
        *im = &h->imp[k], *idx = c->idx + c->start[k], *n = c->start[k + 1] - c->start[k];
        return how;
    }
    const int s = c->start[k], nf = h->nfar[k];
    *im = &h->split[2 * k + pass];
    *idx = h->part + s + (pass ? nf : 0), *n = pass ? c->start[k + 1] - s - nf : nf;
    return how;
}
