/* Harris's multiple forward scattering on the CPU (pcloud.h, atmos__pcloud_shade). The
 * light buffer is an orthographic view from the sun over the particles' box: per texel and
 * wavelength the share of the sunlight still travelling (trans) and the scattering optical
 * depth met (taus). Harris reads the frame buffer back at each particle's centre before
 * splatting it; here the buffer is an array and the read is bilinear. */
#include "particles/pcloud.h"
#include "core/fastmath.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SQRT_2PI 2.5066282746310002

typedef struct lframe {
    double e1[3], e2[3], L[3];
    double u0, v0, texel;
    int res;
} lframe;

static double dot(const double *a, const float x, const float y, const float z) { return a[0] * x + a[1] * y + a[2] * z; }

static void make_frame(const atmos__pcloud *pc, const int *idx, int n, const double sun[3], int res, double texel_scale,
                       lframe *f)
{
    memcpy(f->L, sun, sizeof f->L);
    const double a[3] = {fabs(sun[0]) < 0.9 ? 1.0 : 0.0, fabs(sun[0]) < 0.9 ? 0.0 : 1.0, 0.0};
    const double c = a[0] * sun[0] + a[1] * sun[1] + a[2] * sun[2];
    double t[3] = {a[0] - c * sun[0], a[1] - c * sun[1], a[2] - c * sun[2]};
    const double l = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int i = 0; i < 3; i++) f->e1[i] = t[i] / l;
    f->e2[0] = sun[1] * f->e1[2] - sun[2] * f->e1[1];
    f->e2[1] = sun[2] * f->e1[0] - sun[0] * f->e1[2];
    f->e2[2] = sun[0] * f->e1[1] - sun[1] * f->e1[0];
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, smin = INFINITY;
    for (int q = 0; q < n; q++) {
        const int p = idx ? idx[q] : q;
        const double u = dot(f->e1, pc->x[p], pc->y[p], pc->z[p]), v = dot(f->e2, pc->x[p], pc->y[p], pc->z[p]);
        const double r = ATMOS__PCLOUD_CUT * pc->s[p];
        lo[0] = fmin(lo[0], u - r), hi[0] = fmax(hi[0], u + r);
        lo[1] = fmin(lo[1], v - r), hi[1] = fmax(hi[1], v + r);
        smin = fmin(smin, pc->s[p]);
    }
    const double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    /* texels of 0.7 the smallest width (times texel_scale), 32..1024 per side */
    f->res = res > 0 ? res : (int)fmin(1024.0, fmax(32.0, ceil(ext / (0.7 * texel_scale * smin))));
    f->texel = ext / f->res;
    f->u0 = lo[0], f->v0 = lo[1];
}

/* Bilinear read of buffer b at texel coordinates (x, y). */
static double read_at(const float *b, int res, double x, double y)
{
    x = fmin(fmax(x - 0.5, 0.0), res - 1.001), y = fmin(fmax(y - 0.5, 0.0), res - 1.001);
    const int i = (int)x, j = (int)y;
    const double ax = x - i, ay = y - j;
    const float *r0 = b + (size_t)j * res + i, *r1 = r0 + res;
    return (1 - ay) * ((1 - ax) * r0[0] + ax * r0[1]) + ay * ((1 - ax) * r1[0] + ax * r1[1]);
}

/* The wavelengths a light pass carries at once (their buffers side by side): the particle's
 * column over a texel, the same at every wavelength, is computed once for all of them. */
#define GROUP 4
#define CHUNK 64

/* The splat of particle p into the light buffers of the group's G wavelengths (plane g of
 * trans and taus: res x res texels each) at texel coordinates (x, y): row by row over the
 * texels within the cut, the column of a run of texels first, then each wavelength's
 * transmittance and scattering depth over the run (loops the compiler vectorises). */
static void splat(const atmos__pcloud *pc, int p, const lframe *f, int G, const float *tc, const float *aF,
                  const float *a, float x, float y, float *trans, float *taus)
{
    const int res = f->res;
    const size_t plane = (size_t)res * res;
    const float s = pc->s[p], k2 = (float)(f->texel * f->texel) / (s * s), rt = (float)(ATMOS__PCLOUD_CUT * s / f->texel);
    const int j0 = (int)fmaxf(0.0f, floorf(y - rt)), j1 = (int)fminf(res - 1.0f, ceilf(y + rt));
    float col[CHUNK];
    for (int j = j0; j <= j1; j++) {
        const float dy = (float)j + 0.5f - y, rem = rt * rt - dy * dy;
        if (rem < 0) continue;
        const float w = sqrtf(rem);
        const int i0 = (int)fmaxf(0.0f, ceilf(x - 0.5f - w)), i1 = (int)fminf(res - 1.0f, floorf(x - 0.5f + w));
        for (int c0 = i0; c0 <= i1; c0 += CHUNK) {
            const int m = i1 - c0 + 1 < CHUNK ? i1 - c0 + 1 : CHUNK;
            for (int i = 0; i < m; i++) {
                const float dx = (float)(c0 + i) + 0.5f - x;
                col[i] = atmos__pcloud_column((dx * dx + dy * dy) * k2);
            }
            for (int g = 0; g < G; g++) {
                float *tr = trans + g * plane + (size_t)j * res + c0, *ts = taus + g * plane + (size_t)j * res + c0;
                const float tg = tc[g], ag = aF[g], sg = a[g];
                for (int i = 0; i < m; i++) {
                    const float tau = tg * col[i];
                    const float T = atmos__expf_poly(-tau); /* tau <= a particle's column: far above -87 */
                    tr[i] *= T + (1.0f - T) * ag;
                    ts[i] += sg * tau;
                }
            }
        }
    }
}

/* The light at probe i (ord's index -1 - i) for wavelength k: the buffer's share where the
 * probe falls on it, 1 beside it (no particle of the cloud in the way). */
static void probe_read(const atmos__pprobes *pr, int i, const lframe *f, const float *trans, int k, int nw)
{
    const float *w = pr->xyz + 3 * (size_t)i;
    const double x = (dot(f->e1, w[0], w[1], w[2]) - f->u0) / f->texel, y = (dot(f->e2, w[0], w[1], w[2]) - f->v0) / f->texel;
    const int in = x >= 0 && y >= 0 && x <= f->res && y <= f->res;
    pr->light[(size_t)i * nw + k] = in ? (float)read_at(trans, f->res, x, y) : 1.0f;
}

/* The light pass of wavelengths k0 .. k0 + G - 1 (G <= GROUP; their buffers plane by plane in
 * trans and taus). The particles go in groups of depths within half the first one's width; a
 * group splats the front halves of its blobs (optical depth tc / 2), reads the light at its
 * particles' centres, then splats the back halves: particles side by side shade each other's
 * centres as the halves of a slab do. Probes (negative indices in ord) read the buffer with
 * their group's centres and splat nothing. Each wavelength's buffers see the same arithmetic
 * as in a pass of its own. */
static void pass(const atmos__pcloud *pc, int n, const atmos__poptics *o, const lframe *f, const atmos__keyed *ord, int k0,
                 int G, const atmos__pprobes *pr, float *trans, float *taus, float *light, float *ns)
{
    const int res = f->res, nw = o->nw;
    const size_t plane = (size_t)res * res;
    for (size_t t = 0; t < G * plane; t++) trans[t] = 1.0f, taus[t] = 0.0f;
    for (int q0 = 0, q1; q0 < n; q0 = q1) {
        const double dmax = ord[q0].key + (ord[q0].index >= 0 ? 0.5 * pc->s[ord[q0].index] : 0.0);
        for (q1 = q0 + 1; q1 < n && ord[q1].key < dmax; q1++) {}
        for (int phase = 0; phase < 3; phase++)
            for (int q = q0; q < q1; q++) {
                if (ord[q].index < 0) {
                    for (int g = 0; g < G && phase == 1; g++)
                        probe_read(pr, -1 - ord[q].index, f, trans + g * plane, k0 + g, nw);
                    continue;
                }
                const int p = ord[q].index, fi = pc->field[p];
                const double x = (dot(f->e1, pc->x[p], pc->y[p], pc->z[p]) - f->u0) / f->texel;
                const double y = (dot(f->e2, pc->x[p], pc->y[p], pc->z[p]) - f->v0) / f->texel;
                if (phase == 1) {
                    for (int g = 0; g < G; g++) {
                        const size_t at = (size_t)p * nw + k0 + g;
                        light[at] = (float)read_at(trans + g * plane, res, x, y);
                        ns[at] = (float)read_at(taus + g * plane, res, x, y);
                    }
                    continue;
                }
                float tc[GROUP], aF[GROUP], a[GROUP];
                for (int g = 0; g < G; g++) {
                    const int k = k0 + g;
                    const double sc = phase ? ns[(size_t)p * nw + k] : read_at(taus + g * plane, res, x, y);
                    const double F = o->ms[fi] ? atmos_msphase_forward(o->ms[fi], k, sc + 1.0) : 0.0;
                    const double ak = o->albedo[fi][k], tk = o->sigma_ext[fi][k] * pc->n0[p] * pc->s[p] * SQRT_2PI;
                    tc[g] = (float)(0.5 * tk), aF[g] = (float)(ak * F), a[g] = (float)ak;
                }
                splat(pc, p, f, G, tc, aF, a, (float)x, (float)y, trans, taus);
            }
    }
}

atmos_status atmos__pcloud_shade(atmos_context *ctx, const atmos__pcloud *pc, const int *idx, int nidx,
                                 const atmos__poptics *o, const double sun[3], int res, double texel_scale, float *light,
                                 float *order)
{
    return atmos__pcloud_shade_probes(ctx, pc, idx, nidx, o, sun, res, texel_scale, light, order, NULL);
}

atmos_status atmos__pcloud_shade_probes(atmos_context *ctx, const atmos__pcloud *pc, const int *idx, int nidx,
                                        const atmos__poptics *o, const double sun[3], int res, double texel_scale,
                                        float *light, float *order, const atmos__pprobes *pr)
{
    const int n = idx ? nidx : pc->n, np = pr ? pr->n : 0;
    if (n == 0) {
        for (size_t i = 0; i < (size_t)np * o->nw; i++) pr->light[i] = 1.0f;
        return ATMOS_OK;
    }
    lframe f;
    make_frame(pc, idx, n, sun, res, texel_scale > 0 ? texel_scale : 1.0, &f);
    atmos__keyed *ord = malloc(sizeof *ord * (size_t)(n + np));
    float *ns = malloc(sizeof(float) * (size_t)pc->n * o->nw);
    if (!ord || !ns) {
        free(ord), free(ns);
        return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the light pass");
    }
    for (int q = 0; q < n; q++) {
        const int p = idx ? idx[q] : q;
        ord[q].key = -dot(sun, pc->x[p], pc->y[p], pc->z[p]), ord[q].index = p;
    }
    for (int i = 0; i < np; i++) {
        const float *w = pr->xyz + 3 * (size_t)i;
        ord[n + i].key = -dot(sun, w[0], w[1], w[2]), ord[n + i].index = -1 - i;
    }
    atmos__keyed_sort(ord, (size_t)(n + np), 0);
    int nomem = 0;
    const int groups = (o->nw + GROUP - 1) / GROUP;
#pragma omp parallel for schedule(dynamic, 1) num_threads(atmos__threads(ctx))
    for (int gi = 0; gi < groups; gi++) {
        const int k0 = gi * GROUP, G = o->nw - k0 < GROUP ? o->nw - k0 : GROUP;
        const size_t plane = (size_t)f.res * f.res;
        float *buf = malloc(sizeof(float) * 2 * (size_t)G * plane);
        if (!buf) {
#pragma omp atomic write
            nomem = 1;
            continue;
        }
        pass(pc, n + np, o, &f, ord, k0, G, pr, buf, buf + G * plane, light, ns);
        free(buf);
    }
    for (int q = 0; q < n && order; q++) {
        const int p = idx ? idx[q] : q;
        double m = 0;
        for (int k = 0; k < o->nw; k++) m += ns[(size_t)p * o->nw + k];
        order[p] = (float)(m / o->nw);
    }
    free(ord), free(ns);
    if (nomem) return atmos__error(ctx, ATMOS_E_NOMEM, "particles: out of memory for the light buffer");
    return ATMOS_OK;
}
