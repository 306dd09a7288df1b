/* The sky renderer: what every view ray sees of the atmosphere (Riley et al. 2004 §4.1,
 * §4.2.4 for Riley's kind), the sun's disk antialiased. Rows are evaluated many rays at a
 * time in single precision by the atmosphere's batch (atmosphere_ops.h). Each pixel's value
 * depends only on its own rays (a fixed Hammersley set of sample positions, no random
 * numbers), so the image is the same for any thread count and any region. */
#include "atmosphere/atmosphere_ops.h"
#include "render/sky_view.h"
#include "render/view.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Van der Corput radical inverse in base 2: the second coordinate of the
 * Hammersley set used for deterministic, thread-independent pixel samples. */
static double radical_inverse2(unsigned i)
{
    i = (i << 16) | (i >> 16);
    i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
    i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
    i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
    i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
    return i * (1.0 / 4294967296.0);
}

typedef struct {
    const atmos_atmosphere *atm;
    const atmos_camera *cam;
    double sun[3];
    int spp;
    int n;
    double sun_radius;      /* radians */
    double sun_radiance[ATMOS_MAX_WAVELENGTHS];
    int sun_visible;        /* disk drawn and sun above the horizon */
    double cos_disk_search; /* cos(sun radius + 1.5 pixel footprints) */
    int ground_below;       /* 1: a ray meets the ground exactly when it points down (a flat kind's plane
                               y = 0 seen from above it: atmos_atmosphere_ground_distance's answer) */
} sky_job;

/* An upper bound on the angle one pixel spans, radians. */
static double pixel_footprint(const atmos_camera *cam)
{
    switch (cam->type) {
    case ATMOS_CAMERA_PINHOLE: return 2.0 * cam->tan_half_fov / cam->height; /* largest at the centre */
    case ATMOS_CAMERA_FISHEYE: return cam->fov_deg * ATMOS_DEG2RAD / (cam->width < cam->height ? cam->width : cam->height);
    default: return fmax(2.0 * ATMOS_PI / cam->width, ATMOS_PI / cam->height);
    }
}

static double angle_between(const double a[3], const double b[3])
{
    double c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), c);
}

/* Fraction of the pixel (x, y) covered by the sun's disk, by 16x16 supersampling;
 * called only for pixels near the sun so that the 0.5° disk is antialiased even
 * when it spans a few pixels. */
static double sun_coverage(const sky_job *job, int x, int y)
{
    const int S = 16;
    int inside = 0, valid = 0;
    double d[3];
    for (int j = 0; j < S; j++)
        for (int i = 0; i < S; i++) {
            if (!atmos_camera_ray(job->cam, x + (i + 0.5) / S, y + (j + 0.5) / S, d)) continue;
            valid++;
            if (atmos_atmosphere_ground_distance(job->atm, job->cam->position, d) < INFINITY) continue;
            if (angle_between(d, job->sun) <= job->sun_radius) inside++;
        }
    return valid ? (double)inside / (S * S) : 0.0;
}

/* A pinhole camera's rays of row y (row_rays), in double precision; built for AVX2 as well as
 * the baseline, where the square roots and divisions go four at a time (the same bits). */
ATMOS_CLONES
static void pinhole_rays(const atmos_camera *cam, int y, int x0, int count, double sx, double sy, float *dx,
                         float *dy, float *dz, float *w)
{
    const double t = cam->tan_half_fov, H = cam->height, W = cam->width;
    const double v = (H - 2.0 * (y + sy)) / H * t;
    const double bx = cam->forward[0] + v * cam->up[0], by = cam->forward[1] + v * cam->up[1],
                 bz = cam->forward[2] + v * cam->up[2];
    const double rx = cam->right[0], ry = cam->right[1], rz = cam->right[2];
    for (int i = 0; i < count; i++) {
        const double u = (2.0 * (x0 + i + sx) - W) / H * t;
        const double ox = bx + u * rx, oy = by + u * ry, oz = bz + u * rz;
        const double inv = 1.0 / sqrt(ox * ox + oy * oy + oz * oz);
        dx[i] = (float)(ox * inv), dy[i] = (float)(oy * inv), dz[i] = (float)(oz * inv);
        w[i] = 1.0f;
    }
}

/* Directions of the rays through (x + sx, y + sy) for x in [x0, x0 + count) into SoA
 * arrays (index x - x0); w = 1 for a valid ray, 0 outside a fisheye's circle. The
 * equirectangular camera reads azimuth sines and cosines from a per-sample column table. */
static void row_rays(const sky_job *job, int y, int x0, int count, double sx, double sy, const float *col_sc,
                     float *dx, float *dy, float *dz, float *w)
{
    const atmos_camera *cam = job->cam;
    const int W = cam->width;
    if (cam->type == ATMOS_CAMERA_EQUIRECT && col_sc) {
        double el = (90.0 - ((y + sy) / cam->height) * 180.0) * ATMOS_DEG2RAD;
        float ce = (float)cos(el), se = (float)sin(el);
        for (int i = 0; i < count; i++) {
            dx[i] = ce * col_sc[2 * (x0 + i)];
            dy[i] = se;
            dz[i] = -ce * col_sc[2 * (x0 + i) + 1];
            w[i] = 1.0f;
        }
        return;
    }
    if (cam->type == ATMOS_CAMERA_PINHOLE) {
        pinhole_rays(cam, y, x0, count, sx, sy, dx, dy, dz, w);
        return;
    }
    if (cam->type == ATMOS_CAMERA_FISHEYE) {
        /* Equidistant: angle from the axis proportional to the distance from the centre. */
        const double S = W < cam->height ? W : cam->height;
        const float half = (float)(0.5 * cam->fov_deg * ATMOS_DEG2RAD);
        const float v = (float)((cam->height - 2.0 * (y + sy)) / S);
        float f[3], r[3], u[3];
        for (int k = 0; k < 3; k++) f[k] = (float)cam->forward[k], r[k] = (float)cam->right[k], u[k] = (float)cam->up[k];
        for (int i = 0; i < count; i++) {
            float uu = (float)((2.0 * (x0 + i + sx) - W) / S);
            float rr = sqrtf(uu * uu + v * v);
            float th = rr * half;
            float st = sinf(th), ct = cosf(th);
            float k1 = rr > 0 ? st / rr : half; /* sin(theta)/r -> half as r -> 0 */
            float ox = ct * f[0] + k1 * (uu * r[0] + v * u[0]);
            float oy = ct * f[1] + k1 * (uu * r[1] + v * u[1]);
            float oz = ct * f[2] + k1 * (uu * r[2] + v * u[2]);
            float inv = 1.0f / sqrtf(ox * ox + oy * oy + oz * oz);
            dx[i] = ox * inv, dy[i] = oy * inv, dz[i] = oz * inv;
            w[i] = rr <= 1.0f ? 1.0f : 0.0f;
        }
        return;
    }
    for (int i = 0; i < count; i++) {
        double d[3];
        int ok = atmos_camera_ray(cam, x0 + i + sx, y + sy, d);
        dx[i] = (float)d[0], dy[i] = (float)d[1], dz[i] = (float)d[2];
        w[i] = ok ? 1.0f : 0.0f;
    }
}

/* Sample offsets within the pixel: the centre for one sample, else a Hammersley
 * set (deterministic, identical for every pixel and thread). */
static void sample_offset(int s, int spp, double *sx, double *sy)
{
    *sx = spp == 1 ? 0.5 : (s + 0.5) / spp;
    *sy = spp == 1 ? 0.5 : radical_inverse2((unsigned)s);
}

typedef struct {
    float *dx, *dy, *dz, *w, *acc, *scratch, *hits;
    float *tu, *tcoord, *tval; /* the sky-view table's reads: u, coordinates, values (n + 1 a pixel) */
    int *tnear, *txs;          /* the pixels near the sun among them, and their columns */
} row_buffers;

/* Pixels x0 .. x0 + count - 1 of row y into dst (the row's first pixel). */
static void shade_row(const sky_job *job, const atmos__atm_batch *batch, const float *col_sc, int y, int x0, int count,
                      row_buffers *rb, float *dst, int C)
{
    const int W = job->cam->width, n = job->n, spp = job->spp;
    memset(rb->acc, 0, sizeof(float) * (size_t)count * n);
    memset(rb->hits, 0, sizeof(float) * (size_t)count);
    for (int s = 0; s < spp; s++) {
        double sx, sy;
        sample_offset(s, spp, &sx, &sy);
        row_rays(job, y, x0, count, sx, sy, col_sc ? col_sc + (size_t)2 * W * s : NULL, rb->dx, rb->dy, rb->dz, rb->w);
        atmos__atm_batch_eval(batch, count, rb->dx, rb->dy, rb->dz, rb->w, rb->acc, rb->scratch);
        for (int i = 0; i < count; i++) rb->hits[i] += rb->w[i];
    }
    const float inv = 1.0f / spp;
    for (int i = 0; i < count; i++) {
        float *px = dst + (size_t)(x0 + i) * C;
        for (int k = 0; k < n; k++) px[k] = rb->acc[(size_t)k * count + i] * inv;
        px[n] = rb->hits[i] * inv;
    }
    if (!job->sun_visible) return;
    /* The sun's disk, antialiased by supersampling the few pixels near it. The
     * search uses the last sample's rays (within a pixel of the centre). */
    const float sx = (float)job->sun[0], sy = (float)job->sun[1], sz = (float)job->sun[2];
    const float cs = (float)job->cos_disk_search;
    for (int i = 0; i < count; i++) {
        if (rb->w[i] == 0.0f || rb->dx[i] * sx + rb->dy[i] * sy + rb->dz[i] * sz < cs) continue;
        double cov = sun_coverage(job, x0 + i, y);
        float *px = dst + (size_t)(x0 + i) * C;
        for (int k = 0; k < n; k++) px[k] += (float)(cov * job->sun_radiance[k]);
    }
}

static void job_init(sky_job *job, const atmos_atmosphere *atm, const atmos__view *v)
{
    memset(job, 0, sizeof *job);
    job->atm = atm;
    job->cam = &v->cam;
    memcpy(job->sun, v->sun, sizeof job->sun);
    job->n = atmos_atmosphere_wavelengths(atm)->count;
    job->spp = v->samples_per_pixel > 0 ? v->samples_per_pixel : 1;
    job->sun_radius = 0.5 * atmos_atmosphere_get_desc(atm)->sun_diameter_deg * ATMOS_DEG2RAD;
    atmos_atmosphere_sun_radiance(atm, v->cam.position, job->sun, job->sun_radiance);
    job->sun_visible = atmos_atmosphere_sun_disk_visible(atm, job->sun);
    const atmos_atmosphere_kind kind = atmos_atmosphere_get_kind(atm);
    job->ground_below = (kind == ATMOS_ATMOSPHERE_RILEY || kind == ATMOS_ATMOSPHERE_HOMOGENEOUS) && v->cam.position[1] > 0;
    /* Disk radius plus 2.5 pixel footprints: a sample ray is within one footprint
     * of the pixel centre, the pixel's far corner within another. */
    double foot = pixel_footprint(&v->cam);
    /* The equirect footprint grows towards the poles; search wider there. */
    if (v->cam.type == ATMOS_CAMERA_EQUIRECT) foot /= fmax(1e-3, sqrt(fmax(0.0, 1.0 - job->sun[1] * job->sun[1])));
    double search = job->sun_radius + 2.5 * foot;
    job->cos_disk_search = search >= ATMOS_PI ? -1.0 : cos(search);
}

/* Equirectangular: per-sample tables of the columns' azimuth sines and cosines (NULL for
 * other cameras, or when too large: the rays are then computed one by one). */
static float *column_table(const sky_job *job)
{
    const atmos_camera *cam = job->cam;
    const int W = cam->width;
    if (cam->type != ATMOS_CAMERA_EQUIRECT || (size_t)job->spp * W > ((size_t)1 << 22)) return NULL;
    float *col_sc = malloc(sizeof(float) * 2 * (size_t)W * job->spp);
    if (col_sc)
        for (int s = 0; s < job->spp; s++) {
            double sx, sy;
            sample_offset(s, job->spp, &sx, &sy);
            for (int x = 0; x < W; x++) {
                double az = ((x + sx) / W - 0.5) * 2.0 * ATMOS_PI;
                col_sc[(size_t)2 * W * s + 2 * x] = (float)sin(az);
                col_sc[(size_t)2 * W * s + 2 * x + 1] = (float)cos(az);
            }
        }
    return col_sc;
}

/* ---- the sky every `step` pixels (atmos__view.sky_step; pinhole cameras, one sample a pixel):
 * the sky is smooth, so it is evaluated on a grid of pixel centres every step pixels and read
 * bilinearly between them, except in the cells of the grid where that could err by more than
 * COARSE_TOL of the value in a wavelength (bends), where the horizon crosses (the corners' rays
 * do not all meet the ground or all miss it) and near the sun (its disk): those are evaluated
 * pixel by pixel. */
#define COARSE_TOL 1e-3f

/* The rays of pixel centres xs[0..m) of row y, as pinhole_rays makes them. */
static void pinhole_cols(const atmos_camera *cam, int y, const int *xs, int m, float *dx, float *dy, float *dz, float *w)
{
    const double t = cam->tan_half_fov, H = cam->height, W = cam->width;
    const double v = (H - 2.0 * (y + 0.5)) / H * t;
    const double bx = cam->forward[0] + v * cam->up[0], by = cam->forward[1] + v * cam->up[1],
                 bz = cam->forward[2] + v * cam->up[2];
    for (int i = 0; i < m; i++) {
        const double u = (2.0 * (xs[i] + 0.5) - W) / H * t;
        const double ox = bx + u * cam->right[0], oy = by + u * cam->right[1], oz = bz + u * cam->right[2];
        const double inv = 1.0 / sqrt(ox * ox + oy * oy + oz * oz);
        dx[i] = (float)(ox * inv), dy[i] = (float)(oy * inv), dz[i] = (float)(oz * inv);
        w[i] = 1.0f;
    }
}

static void eval_cols(const sky_job *job, const atmos__atm_batch *batch, const atmos__sky_view *t, int y, const int *xs,
                      int m, row_buffers *rb, float *val, unsigned char *flags, double cos_near);

/* Radiance of pixels xs[0..m) of row y read from the sky-view table t into val[i * n + k]; the
 * pixels near the sun (its disk) evaluated by the batch, their disk added. */
static void table_cols(const sky_job *job, const atmos__atm_batch *batch, const atmos__sky_view *t, int y, const int *xs,
                       int m, row_buffers *rb, float *val)
{
    const atmos_camera *cam = job->cam;
    const int n = job->n;
    const double tn = cam->tan_half_fov, H = cam->height, W = cam->width, v = (H - 2.0 * (y + 0.5)) / H * tn;
    const double base[3] = {cam->forward[0] + v * cam->up[0], cam->forward[1] + v * cam->up[1],
                            cam->forward[2] + v * cam->up[2]};
    for (int i = 0; i < m; i++) rb->tu[i] = (float)((2.0 * (xs[i] + 0.5) - W) / H * tn);
    const int q = atmos__sky_view_row(t, base, cam->right, rb->tu, m, job->cos_disk_search, rb->tval, n + 1, rb->tcoord,
                                      rb->tnear);
    for (int i = 0; i < m; i++)
        for (int k = 0; k < n; k++) val[(size_t)i * n + k] = rb->tval[(size_t)i * (n + 1) + k];
    if (!q) return;
    for (int j = 0; j < q; j++) rb->txs[j] = xs[rb->tnear[j]];
    eval_cols(job, batch, NULL, y, rb->txs, q, rb, rb->tval, NULL, 1.0);
    for (int j = 0; j < q; j++)
        for (int k = 0; k < n; k++) val[(size_t)rb->tnear[j] * n + k] = rb->tval[(size_t)j * n + k];
}

/* Radiance of pixels xs[0..m) of row y into val[i * n + k] (the sun's disk added), from the
 * sky-view table t when not NULL, else evaluated; flags[i] (may be NULL): 1 when the pixel's ray
 * meets the ground, + 2 when it is within the angle whose cosine is cos_near of the sun. */
static void eval_cols(const sky_job *job, const atmos__atm_batch *batch, const atmos__sky_view *t, int y, const int *xs,
                      int m, row_buffers *rb, float *val, unsigned char *flags, double cos_near)
{
    const int n = job->n;
    pinhole_cols(job->cam, y, xs, m, rb->dx, rb->dy, rb->dz, rb->w);
    if (flags && job->ground_below) { /* the horizon test by the ray's sign, in a vector loop */
        const double s0 = job->sun[0], s1 = job->sun[1], s2 = job->sun[2];
        const int sun = job->sun_visible;
        for (int i = 0; i < m; i++)
            flags[i] = (unsigned char)((rb->dy[i] < 0.0f) +
                                       2 * (sun && rb->dx[i] * s0 + rb->dy[i] * s1 + rb->dz[i] * s2 >= cos_near));
        flags = NULL;
    }
    for (int i = 0; flags && i < m; i++) {
        const double d[3] = {rb->dx[i], rb->dy[i], rb->dz[i]};
        flags[i] = (unsigned char)((atmos_atmosphere_ground_distance(job->atm, job->cam->position, d) < INFINITY) +
                                   2 * (job->sun_visible && d[0] * job->sun[0] + d[1] * job->sun[1] + d[2] * job->sun[2] >= cos_near));
    }
    if (t) {
        table_cols(job, batch, t, y, xs, m, rb, val);
        return;
    }
    memset(rb->acc, 0, sizeof(float) * (size_t)m * n);
    atmos__atm_batch_eval(batch, m, rb->dx, rb->dy, rb->dz, rb->w, rb->acc, rb->scratch);
    const float sx = (float)job->sun[0], sy = (float)job->sun[1], sz = (float)job->sun[2], cs = (float)job->cos_disk_search;
    for (int i = 0; i < m; i++) {
        for (int k = 0; k < n; k++) val[(size_t)i * n + k] = rb->acc[(size_t)k * m + i];
        if (!job->sun_visible || rb->dx[i] * sx + rb->dy[i] * sy + rb->dz[i] * sz < cs) continue;
        const double cov = sun_coverage(job, xs[i], y);
        for (int k = 0; k < n; k++) val[(size_t)i * n + k] += (float)(cov * job->sun_radiance[k]);
    }
}

typedef struct coarse {
    int step, nx, ny, *cx, *cy;  /* the grid's columns and rows (pixel indices) */
    float *val;                  /* [ny nx n] */
    unsigned char *flags, *fine; /* [ny nx]: the node's eval_cols flags; cell (j, i) evaluated pixel by pixel */
    unsigned char *bent;         /* [ny nx]: the node's bends, found once for the four cells about it */
} coarse;

/* Whether the sky bends too much about node (j, i) for a bilinear read: its second differences
 * along the grid's rows and columns (where it has neighbours), over 8 times the tolerance of its
 * value (bilinear reading errs by at most an eighth of the second difference over a cell). */
static int bends(const coarse *g, int n, int j, int i)
{
    const float *c = g->val + ((size_t)j * g->nx + i) * n;
    const size_t dx = (size_t)n, dy = (size_t)g->nx * n;
    for (int k = 0; k < n; k++) {
        const float lim = 8.0f * COARSE_TOL * fabsf(c[k]);
        if (i > 0 && i < g->nx - 1 && !(fabsf(c[k - dx] - 2.0f * c[k] + c[k + dx]) <= lim)) return 1;
        if (j > 0 && j < g->ny - 1 && !(fabsf(c[k - dy] - 2.0f * c[k] + c[k + dy]) <= lim)) return 1;
    }
    return 0;
}

/* Whether cell (j, i) must be evaluated pixel by pixel: the horizon crosses it, the sky bends
 * at its corners, the sun is near, or it is the last row or column's narrower cell. */
static int cell_fine(const coarse *g, int j, int i)
{
    const int c[4] = {j * g->nx + i, j * g->nx + i + 1, (j + 1) * g->nx + i, (j + 1) * g->nx + i + 1};
    if (g->cx[i + 1] - g->cx[i] != g->step || g->cy[j + 1] - g->cy[j] != g->step) return 1;
    for (int q = 0; q < 4; q++)
        if (g->flags[c[q]] != (g->flags[c[0]] & 1)) return 1; /* the horizon between them, or the sun near */
    return g->bent[c[0]] | g->bent[c[1]] | g->bent[c[2]] | g->bent[c[3]];
}

/* Row y from the grid: cells read bilinearly, fine cells' pixels evaluated. The grid's two rows
 * about y are first read at y once a node (lrow, nx n values: a cell's left and right edges), a
 * cell's pixels then along x at the offsets fx[p] = p / step (a cell read bilinearly is a whole
 * step wide; the last column's takes one pixel more, at fx 1). */
ATMOS_CLONES static void coarse_row(const sky_job *job, const atmos__atm_batch *batch, const atmos__sky_view *t,
                                    const coarse *g, const atmos__rect *r, int y, row_buffers *rb, int *xs, float *val,
                                    float *dst, int C, const unsigned char *hidden)
{
    const int n = job->n, j = (y - r->y0) / g->step < g->ny - 1 ? (y - r->y0) / g->step : g->ny - 2;
    const float fy = (float)(y - g->cy[j]) / (float)(g->cy[j + 1] - g->cy[j]), inv = 1.0f / (float)g->step;
    const unsigned char *fine = g->fine + (size_t)j * g->nx;
    float *lrow = rb->acc, fx[16 + 1]; /* sky_step is at most 16; rb->acc is free until eval_cols below */
    for (int p = 0; p <= g->step; p++) fx[p] = (float)p * inv;
    const float *a = g->val + (size_t)j * g->nx * n, *b = a + (size_t)g->nx * n;
    for (int q = 0; q < g->nx * n; q++) lrow[q] = (1 - fy) * a[q] + fy * b[q];
    int m = 0;
    for (int i = 0; i < g->nx - 1; i++) {
        const int xa = g->cx[i], xb = i == g->nx - 2 ? g->cx[i + 1] + 1 : g->cx[i + 1];
        const float *l0 = lrow + (size_t)i * n, *r0 = l0 + n;
        if (fine[i]) {
            for (int x = xa; x < xb; x++) {
                float *px = dst + (size_t)x * C;
                px[n] = 1.0f;
                if (!hidden || !hidden[x - r->x0]) xs[m++] = x;
                else /* not shown: read bilinearly (x - xa < step, so fx[x - xa] is within the cell) */
                    for (int k = 0; k < n; k++) px[k] = l0[k] + fx[x - xa] * (r0[k] - l0[k]);
            }
            continue;
        }
        float *px = dst + (size_t)xa * C;
#if defined(__GNUC__) && !defined(__SANITIZE_ADDRESS__)
        if (n == 3 && C == 4) { /* RGB + alpha: a pixel as one vector of four (alpha 1 + fx 0) */
            typedef float v4f __attribute__((vector_size(16)));
            const v4f lv = {l0[0], l0[1], l0[2], 1.0f}, dv = {r0[0] - l0[0], r0[1] - l0[1], r0[2] - l0[2], 0.0f};
            for (int p = 0; p < xb - xa; p++) {
                const v4f o = lv + fx[p] * dv;
                memcpy(px + (size_t)p * 4, &o, sizeof o);
            }
            continue;
        }
#endif
        for (int p = 0; p < xb - xa; p++, px += C) {
            for (int k = 0; k < n; k++) px[k] = l0[k] + fx[p] * (r0[k] - l0[k]);
            px[n] = 1.0f;
        }
    }
    if (!m) return;
    eval_cols(job, batch, t, y, xs, m, rb, val, NULL, 1.0);
    for (int q = 0; q < m; q++)
        for (int k = 0; k < n; k++) dst[(size_t)xs[q] * C + k] = val[(size_t)q * n + k];
}

/* The sky of rect r every v->sky_step pixels (coarse_row), the values from the sky-view table t
 * when not NULL; 1 when it cannot (too small a rect: the caller renders every pixel). */
static int render_coarse(atmos_context *ctx, const sky_job *job, const atmos__atm_batch *batch, const atmos__sky_view *t,
                         const atmos__view *v, const atmos__rect *r, atmos_image *out, int *nomem,
                         const unsigned char *hidden)
{
    const int F = v->sky_step > 1 ? v->sky_step : 1, n = job->n, count = r->x1 - r->x0, rows = r->y1 - r->y0, C = out->channels;
    if (count < 2 || rows < 2) return 1;
    coarse g = {F, (count - 2 + F) / F + 1, (rows - 2 + F) / F + 1, NULL, NULL, NULL, NULL, NULL, NULL};
    g.cx = malloc(sizeof(int) * (size_t)(g.nx + g.ny)), g.cy = g.cx ? g.cx + g.nx : NULL;
    g.val = malloc(sizeof(float) * (size_t)g.nx * g.ny * n), g.flags = malloc(3 * (size_t)g.nx * g.ny);
    if (!g.cx || !g.val || !g.flags) {
        free(g.cx), free(g.val), free(g.flags);
        return *nomem = 1, 0;
    }
    g.fine = g.flags + (size_t)g.nx * g.ny, g.bent = g.fine + (size_t)g.nx * g.ny;
    for (int i = 0; i < g.nx; i++) g.cx[i] = r->x0 + i * F < r->x1 - 1 ? r->x0 + i * F : r->x1 - 1;
    for (int j = 0; j < g.ny; j++) g.cy[j] = r->y0 + j * F < r->y1 - 1 ? r->y0 + j * F : r->y1 - 1;
    const double cos_near = cos(job->sun_radius + (2.5 + 1.5 * F) * pixel_footprint(&v->cam));
    const int band = 8, nbands = (rows + band - 1) / band;
#pragma omp parallel num_threads(atmos__threads(ctx))
    {
        row_buffers rb = {0};
        const size_t per = (size_t)count;
        float *mem = malloc(sizeof(float) * per * (4 + 2 * (size_t)n + ATMOS__ATM_BATCH_SCRATCH));
        int *xs = malloc(sizeof(int) * per * 3);
        float *tmem = malloc(sizeof(float) * per * (5 + (size_t)n));
        if (mem && xs && tmem) {
            rb.dx = mem, rb.dy = mem + per, rb.dz = mem + 2 * per, rb.w = mem + 3 * per, rb.acc = mem + 4 * per;
            rb.scratch = rb.acc + per * n;
            rb.tu = tmem, rb.tcoord = tmem + per, rb.tval = tmem + 4 * per, rb.tnear = xs + per, rb.txs = xs + 2 * per;
        } else {
#pragma omp atomic write
            *nomem = 1;
        }
        float *val = mem ? rb.scratch + per * ATMOS__ATM_BATCH_SCRATCH : NULL;
#pragma omp for schedule(dynamic, 4)
        for (int j = 0; j < g.ny; j++)
            if (mem && xs && tmem) eval_cols(job, batch, t, g.cy[j], g.cx, g.nx, &rb, g.val + (size_t)j * g.nx * n, g.flags + (size_t)j * g.nx,
                          cos_near);
#pragma omp for schedule(static)
        for (int j = 0; j < g.ny; j++)
            for (int i = 0; i < g.nx; i++) g.bent[j * g.nx + i] = (unsigned char)bends(&g, n, j, i);
#pragma omp for schedule(static)
        for (int j = 0; j < g.ny - 1; j++)
            for (int i = 0; i < g.nx - 1; i++) g.fine[j * g.nx + i] = (unsigned char)cell_fine(&g, j, i);
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < nbands; b++)
            for (int y = r->y0 + b * band; mem && xs && tmem && y < r->y1 && y < r->y0 + (b + 1) * band; y++)
                coarse_row(job, batch, t, &g, r, y, &rb, xs, val, out->pixels + (size_t)y * v->cam.width * C, C,
                           hidden ? hidden + (size_t)(y - r->y0) * count : NULL);
        free(mem), free(xs), free(tmem);
    }
    free(g.cx), free(g.val), free(g.flags);
    return 0;
}

struct atmos__sky_keep {
    atmos__atm_batch batch; /* zeroed until the first frame */
    atmos__sky_view table;  /* zeroed until a frame asks for it */
};

atmos__sky_keep *atmos__sky_keep_create(void) { return calloc(1, sizeof(atmos__sky_keep)); }

void atmos__sky_keep_destroy(atmos__sky_keep *k)
{
    if (k) atmos__atm_batch_release(&k->batch), atmos__sky_view_free(&k->table);
    free(k);
}

/* A black vacuum seen through a pinhole, one sample a pixel: every ray's radiance is 0 (no air,
 * no ground, no sun's disk) and its weight 1, so each pixel of r is what the rows would give it
 * (0, alpha 1), written without evaluating the rays. Returns 0 for any other sky. */
static int black_vacuum(atmos_context *ctx, const atmos_atmosphere *atm, const atmos__view *v, const sky_job *job,
                        const atmos__rect *r, atmos_image *out)
{
    if (atmos_atmosphere_get_kind(atm) != ATMOS_ATMOSPHERE_VACUUM ||
        atmos_atmosphere_get_desc(atm)->background_radiance != 0 || v->cam.type != ATMOS_CAMERA_PINHOLE ||
        job->spp != 1 || job->sun_visible)
        return 0;
    const int W = v->cam.width, C = out->channels, n = job->n;
#pragma omp parallel for schedule(static) num_threads(atmos__threads(ctx))
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) {
            float *px = out->pixels + ((size_t)y * W + x) * C;
            for (int k = 0; k < n; k++) px[k] = 0.0f;
            px[n] = 1.0f;
        }
    return 1;
}

atmos_status atmos__sky_render(atmos_context *ctx, const atmos_atmosphere *atm, const atmos__view *v,
                               const atmos__rect *r, atmos_image *out, atmos__sky_keep *keep)
{
    return atmos__sky_render_hidden(ctx, atm, v, r, out, keep, NULL);
}

atmos_status atmos__sky_render_hidden(atmos_context *ctx, const atmos_atmosphere *atm, const atmos__view *v,
                                      const atmos__rect *r, atmos_image *out, atmos__sky_keep *keep,
                                      const unsigned char *hidden)
{
    sky_job job;
    job_init(&job, atm, v);
    const int W = v->cam.width, C = out->channels, count = r->x1 - r->x0;
    if (count <= 0 || r->y1 <= r->y0) return ATMOS_OK;
    const int band = 8; /* rows per work item: small enough for progress and balance */
    const int nbands = (r->y1 - r->y0 + band - 1) / band;
    int done = 0, cancelled = 0, nomem = 0;
    atmos__atm_batch own, *bp = keep ? &keep->batch : &own;
    if (keep) atmos__atm_batch_update(bp, atm, v->cam.position, job.sun, atmos__threads(ctx));
    else atmos__atm_batch_init(bp, atm, v->cam.position, job.sun, atmos__threads(ctx));
    const atmos__atm_batch *batch = bp;
    if (black_vacuum(ctx, atm, v, &job, r, out)) {
        if (!keep) atmos__atm_batch_release(&own);
        atmos__progress(ctx, "render sky", 1.0);
        return ATMOS_OK;
    }
    const atmos__sky_view *table = NULL;
    if (v->sky_table && keep && v->cam.type == ATMOS_CAMERA_PINHOLE && job.spp == 1 &&
        atmos__sky_view_wanted(atm, v->cam.position)) {
        if (!atmos__sky_view_update(&keep->table, atm, batch, atmos__threads(ctx)))
            return atmos__error(ctx, ATMOS_E_NOMEM, "render: out of memory for the sky-view table");
        table = &keep->table;
    }
    if ((v->sky_step > 1 || table) && v->cam.type == ATMOS_CAMERA_PINHOLE && job.spp == 1 &&
        !render_coarse(ctx, &job, batch, table, v, r, out, &nomem, hidden)) {
        if (!keep) atmos__atm_batch_release(&own);
        if (nomem) return atmos__error(ctx, ATMOS_E_NOMEM, "render: out of memory for the sky's grid");
        atmos__progress(ctx, "render sky", 1.0);
        return ATMOS_OK;
    }
    float *col_sc = column_table(&job);
#pragma omp parallel num_threads(atmos__threads(ctx))
    {
        row_buffers rb = {0};
        const size_t per = (size_t)count;
        float *mem = malloc(sizeof(float) * per * (5 + (size_t)job.n + ATMOS__ATM_BATCH_SCRATCH));
        if (mem) {
            rb.dx = mem, rb.dy = mem + per, rb.dz = mem + 2 * per, rb.w = mem + 3 * per, rb.hits = mem + 4 * per;
            rb.acc = mem + 5 * per;
            rb.scratch = rb.acc + per * job.n;
        } else {
#pragma omp atomic write
            nomem = 1;
        }
        /* Bands are handed out dynamically for balance; each pixel's value depends
         * only on its own position, so the image is identical for any thread count. */
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < nbands; b++) {
            if (atmos__cancelled(&cancelled) || !mem) continue;
            for (int y = r->y0 + b * band; y < r->y1 && y < r->y0 + (b + 1) * band; y++)
                shade_row(&job, batch, col_sc, y, r->x0, count, &rb, out->pixels + (size_t)y * W * C, C);
            atmos__progress_step(ctx, "render sky", &done, nbands, &cancelled);
        }
        free(mem);
    }
    free(col_sc);
    if (!keep) atmos__atm_batch_release(&own);
    if (nomem) return atmos__error(ctx, ATMOS_E_NOMEM, "render: out of memory for row buffers");
    if (cancelled) return atmos__error(ctx, ATMOS_E_CANCELLED, "render: cancelled");
    atmos__progress(ctx, "render sky", 1.0);
    return ATMOS_OK;
}
