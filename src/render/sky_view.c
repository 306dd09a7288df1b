/* The sky-view table (sky_view.h; Hillaire 2020 §5.3): made by the atmosphere's batch over the
 * table's node directions, read bilinearly a pixel with the pixel's azimuth and elevation from
 * a polynomial arctangent (within 1e-5 radian, far inside a cell) in vector loops. */
#include "render/sky_view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NA ATMOS__SKY_VIEW_AZIMUTHS
#define NE ATMOS__SKY_VIEW_ELEVATIONS
#define HALF_PI 1.5707963267948966
#define HORIZON_EL 1e-5 /* the nodes next to the horizon: just above it, just below (radians) */

int atmos__sky_view_wanted(const atmos_atmosphere *atm, const double eye[3])
{
    const atmos_atmosphere_kind k = atmos_atmosphere_get_kind(atm);
    return (k == ATMOS_ATMOSPHERE_RILEY || k == ATMOS_ATMOSPHERE_HOMOGENEOUS) && eye[1] > 0.0;
}

/* The direction of node (half, j, i): half 0 the sky above the horizon, 1 the ground below. */
static void node_dir(const atmos__sky_view *t, int half, int j, int i, double d[3])
{
    const double v = (double)j / (NE - 1), el = (half ? -1.0 : 1.0) * fmax(HALF_PI * v * v, HORIZON_EL);
    const double phi = ATMOS_PI * i / (NA - 1), ce = cos(el), cp = cos(phi), sp = sin(phi);
    for (int a = 0; a < 3; a++) d[a] = ce * (cp * t->e1[a] + sp * t->e2[a]);
    d[1] += sin(el);
}

static int make(atmos__sky_view *t, const atmos__atm_batch *batch, int n, int threads)
{
    const int stride = (n + 4) & ~3;
    if (!t->tab || t->stride != stride) {
        free(t->tab);
        if (!(t->tab = malloc(sizeof(float) * 2 * NE * NA * (size_t)stride))) return t->atm = NULL, 0;
    }
    t->n = n, t->stride = stride;
    const double hs = hypot(batch->sun[0], batch->sun[2]);
    t->e1[0] = hs > 1e-9 ? batch->sun[0] / hs : 1.0, t->e1[1] = 0.0, t->e1[2] = hs > 1e-9 ? batch->sun[2] / hs : 0.0;
    t->e2[0] = -t->e1[2], t->e2[1] = 0.0, t->e2[2] = t->e1[0]; /* up x e1 with up = +y, up to sign */
    int nomem = 0;
#pragma omp parallel num_threads(threads)
    {
        float *mem = malloc(sizeof(float) * NA * (4 + (size_t)n + ATMOS__ATM_BATCH_SCRATCH));
        if (!mem) {
#pragma omp atomic write
            nomem = 1;
        }
#pragma omp for schedule(dynamic, 2)
        for (int row = 0; row < 2 * NE; row++) {
            if (!mem) continue;
            float *dx = mem, *dy = mem + NA, *dz = mem + 2 * NA, *w = mem + 3 * NA, *acc = mem + 4 * NA;
            for (int i = 0; i < NA; i++) {
                double d[3];
                node_dir(t, row / NE, row % NE, i, d);
                dx[i] = (float)d[0], dy[i] = (float)d[1], dz[i] = (float)d[2], w[i] = 1.0f;
            }
            memset(acc, 0, sizeof(float) * NA * (size_t)n);
            atmos__atm_batch_eval(batch, NA, dx, dy, dz, w, acc, acc + (size_t)NA * n);
            for (int i = 0; i < NA; i++) {
                float *node = t->tab + ((size_t)row * NA + i) * stride;
                for (int k = 0; k < stride; k++) node[k] = k < n ? acc[(size_t)k * NA + i] : 1.0f;
            }
        }
        free(mem);
    }
    if (nomem) return t->atm = NULL, 0;
    return 1;
}

int atmos__sky_view_update(atmos__sky_view *t, const atmos_atmosphere *atm, const atmos__atm_batch *batch,
                           int threads)
{
    const int n = atmos_atmosphere_wavelengths(atm)->count;
    if (t->atm == atm && t->n == n && !memcmp(t->sun, batch->sun, sizeof t->sun) &&
        fabs(batch->eye[1] - t->height) <= ATMOS__SKY_VIEW_REMAKE_M)
        return 1;
    if (!make(t, batch, n, threads)) return 0;
    t->atm = atm, t->height = batch->eye[1];
    memcpy(t->sun, batch->sun, sizeof t->sun);
    return 1;
}

void atmos__sky_view_free(atmos__sky_view *t)
{
    free(t->tab);
    memset(t, 0, sizeof *t);
}

/* atan2(y, x) within 1e-5 radian, without branches (a minimax polynomial of atan over [0, 1]). */
static inline float fast_atan2(float y, float x)
{
    const float ax = fabsf(x), ay = fabsf(y), mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
    const float q = mx > 0.0f ? mn / mx : 0.0f, q2 = q * q;
    float r = q * (0.99997726f + q2 * (-0.33262347f + q2 * (0.19354346f + q2 * (-0.11643287f + q2 * (0.05265332f +
                                                                                               q2 * -0.01172120f)))));
    r = ay > ax ? 1.57079633f - r : r;
    r = x < 0.0f ? 3.14159265f - r : r;
    return y < 0.0f ? -r : r;
}

/* The table coordinates of the row's pixels: coord[x] the column, coord[count + x] the row within
 * its half, coord[2 count + x] the half (0 the sky, 1 the ground; 2 near the sun). */
ATMOS_CLONES
static void row_coords(const atmos__sky_view *t, const double base[3], const double right[3], const float *u_of,
                       int count, double cos_near, float *coord)
{
    const double *sn = t->sun;
    const float sb = (float)base[1], sr = (float)right[1];
    const float ab = (float)(base[0] * t->e1[0] + base[2] * t->e1[2]), ar = (float)(right[0] * t->e1[0] + right[2] * t->e1[2]);
    const float bb = (float)(base[0] * t->e2[0] + base[2] * t->e2[2]), br = (float)(right[0] * t->e2[0] + right[2] * t->e2[2]);
    const float cb = (float)(base[0] * sn[0] + base[1] * sn[1] + base[2] * sn[2]),
                cr = (float)(right[0] * sn[0] + right[1] * sn[1] + right[2] * sn[2]);
    const float cn2 = (float)(cos_near * fabs(cos_near)), ka = (float)((NA - 1) / ATMOS_PI),
                ke = (float)(1.0 / HALF_PI), ve = (float)(NE - 1);
    float *restrict col = coord, *restrict row = coord + count, *restrict half = coord + 2 * (size_t)count;
    for (int x = 0; x < count; x++) {
        const float u = u_of[x];
        const float s = sb + u * sr, a = ab + u * ar, b = fabsf(bb + u * br), c = cb + u * cr;
        const float h2 = a * a + b * b, h = sqrtf(h2);
        const float phi = fast_atan2(b, a), el = fast_atan2(s, h);
        const int near = c > 0.0f && c * c >= cn2 * (h2 + s * s);
        col[x] = phi * ka;
        row[x] = sqrtf(fabsf(el) * ke) * ve;
        half[x] = near ? 2.0f : s < 0.0f ? 1.0f : 0.0f;
    }
}

int atmos__sky_view_row(const atmos__sky_view *t, const double base[3], const double right[3], const float *u,
                        int count, double cos_near, float *dst, int C, float *coord, int *near)
{
    row_coords(t, base, right, u, count, cos_near, coord);
    const int n = t->n, S = t->stride;
    int m = 0;
    for (int x = 0; x < count; x++) {
        const int half = (int)coord[2 * (size_t)count + x];
        if (half == 2) {
            near[m++] = x;
            continue;
        }
        const float cx = coord[x], cy = coord[count + x];
        int i = (int)cx, j = (int)cy;
        i = i < NA - 2 ? i : NA - 2, j = j < NE - 2 ? j : NE - 2;
        const float fx = cx - (float)i, fy = cy - (float)j;
        const float *p = t->tab + (((size_t)half * NE + j) * NA + i) * S, *q = p + (size_t)NA * S;
        const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
        float *px = dst + (size_t)x * C;
#if defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
        if (S == 4 && C == 4) { /* RGB + alpha: a node and a pixel as one vector of four (alpha 1) */
            typedef float v4f __attribute__((vector_size(16)));
            v4f a, b, c, d;
            memcpy(&a, p, 16), memcpy(&b, p + 4, 16), memcpy(&c, q, 16), memcpy(&d, q + 4, 16);
            v4f o = w00 * a + w01 * b + w10 * c + w11 * d;
            o[3] = 1.0f;
            memcpy(px, &o, 16);
            continue;
        }
#endif
        for (int k = 0; k < n; k++) px[k] = w00 * p[k] + w01 * p[S + k] + w10 * q[k] + w11 * q[S + k];
        px[n] = 1.0f;
    }
    return m;
}
