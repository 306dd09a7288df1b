/* The sun of the beam renderer (beams_sun.h): the fog's optical depth along a ray, the sun's
 * orthographic shadow map of the meshes, and the sunlight the fog scatters along a ray. */
#include "render/beams_sun.h"
#include "render/beams_raster.h"
#include "core/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Along o + t d the fog is A exp(-k t): A at the eye, k = d_y / H (0 for uniform fog). */
static void fog_line(const atmos__beams_fog *f, const double o[3], const double d[3], double *A, double *k)
{
    *A = f->height_m > 0 ? f->sigma0 * exp(-(o[1] - f->base_m) / f->height_m) : f->sigma0;
    *k = f->height_m > 0 ? d[1] / f->height_m : 0;
}

/* int_0^t A exp(-k s) ds */
static double line_tau(double A, double k, double t)
{
    if (t == INFINITY) return k > 0 ? A / k : A > 0 ? INFINITY : 0;
    return fabs(k * t) < 1e-9 ? A * t : A * -expm1(-k * t) / k;
}

/* The t where the optical depth reaches tau (INFINITY if it never does). */
static double line_t(double A, double k, double tau)
{
    if (!(A > 0)) return INFINITY;
    if (fabs(k) * tau < 1e-9 * A) return tau / A;
    const double x = k * tau / A;
    return x >= 1 ? INFINITY : -log1p(-x) / k;
}

double atmos__beams_fog_tau(const atmos__beams_fog *f, const double o[3], const double d[3], double t)
{
    double A, k;
    fog_line(f, o, d, &A, &k);
    return line_tau(A, k, t);
}

void atmos__beams_sun_free(atmos__beams_sun *s)
{
    free(s->depth);
    s->depth = NULL, s->n = 0;
}

/* One triangle (u, v in texels, depth) into the map: depth is linear in an orthographic view. */
static void draw(atmos__beams_sun *s, const double v[3][3])
{
    const double x[3] = {v[0][0], v[1][0], v[2][0]}, y[3] = {v[0][1], v[1][1], v[2][1]}, z[3] = {v[0][2], v[1][2], v[2][2]};
    atmos__beams_raster(s->depth, s->n, x, y, z, 0);
}

atmos_status atmos__beams_sun_build(atmos_context *ctx, atmos__beams_sun *s, const double dir[3], atmos_mesh *const *mesh,
                                    int nmesh, int size)
{
    atmos__beams_sun_free(s);
    for (int a = 0; a < 3; a++) s->dir[a] = dir[a], s->fwd[a] = -dir[a];
    const double ref[3] = {fabs(s->fwd[1]) < 0.9 ? 0 : 1, fabs(s->fwd[1]) < 0.9 ? 1 : 0, 0};
    atmos__cross3(s->fwd, ref, s->right);
    atmos__normalize3(s->right);
    atmos__cross3(s->right, s->fwd, s->up);
    if (nmesh == 0) return ATMOS_OK;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int m = 0; m < nmesh; m++)
        for (int i = 0; i < mesh[m]->vertex_count; i++) {
            const float *p = mesh[m]->positions + 3 * i;
            const double q[3] = {p[0], p[1], p[2]}, u = atmos__dot3(q, s->right), v = atmos__dot3(q, s->up);
            lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u), lo[1] = fmin(lo[1], v), hi[1] = fmax(hi[1], v);
        }
    const double ext = fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), 1e-6);
    s->n = size, s->texel = ext / (size - 2); /* a texel of margin on each side */
    s->u0 = lo[0] - s->texel, s->v0 = lo[1] - s->texel;
    s->bias = 0.5 * s->texel;
    if (!(s->depth = malloc(sizeof(float) * (size_t)size * size))) {
        s->n = 0;
        return atmos__error(ctx, ATMOS_E_NOMEM, "render beams: out of memory for a %dx%d sun shadow map", size, size);
    }
    for (size_t i = 0; i < (size_t)size * size; i++) s->depth[i] = INFINITY;
    for (int m = 0; m < nmesh; m++)
        for (int t = 0; t < mesh[m]->triangle_count; t++) {
            double v[3][3];
            for (int k = 0; k < 3; k++) {
                const float *p = mesh[m]->positions + 3 * mesh[m]->indices[3 * t + k];
                const double q[3] = {p[0], p[1], p[2]};
                v[k][0] = (atmos__dot3(q, s->right) - s->u0) / s->texel;
                v[k][1] = (atmos__dot3(q, s->up) - s->v0) / s->texel;
                v[k][2] = atmos__dot3(q, s->fwd);
            }
            draw(s, v);
        }
    return ATMOS_OK;
}

/* H at texel coordinates (fx, fy) and depth z (the bias taken off): the four nearest
 * comparisons, blended; 1 beside the map. */
static double lookup(const atmos__beams_sun *s, double fx, double fy, double z)
{
    const int n = s->n;
    if (!(fx > -1 && fx < n && fy > -1 && fy < n)) return 1; /* beside every object */
    const int x0 = (int)(fx + 1) - 1, y0 = (int)(fy + 1) - 1;
    const double ax = fx - x0, ay = fy - y0;
    const int xa = x0 < 0 ? 0 : x0, xb = x0 + 1 > n - 1 ? n - 1 : x0 + 1;
    const int ya = y0 < 0 ? 0 : y0, yb = y0 + 1 > n - 1 ? n - 1 : y0 + 1;
    const float *ra = s->depth + (size_t)ya * n, *rb = s->depth + (size_t)yb * n;
    const double top = (1 - ax) * (z < ra[xa]) + ax * (z < ra[xb]), bottom = (1 - ax) * (z < rb[xa]) + ax * (z < rb[xb]);
    return (1 - ay) * top + ay * bottom;
}

double atmos__beams_sun_visibility(const atmos__beams_sun *s, const double p[3])
{
    if (!s->n) return 1;
    return lookup(s, (atmos__dot3(p, s->right) - s->u0) / s->texel - 0.5, (atmos__dot3(p, s->up) - s->v0) / s->texel - 0.5,
                  atmos__dot3(p, s->fwd) - s->bias);
}

double atmos__beams_sun_fog_in(const atmos__beams_fog *f, const double sun[3], const double p[3])
{
    if (!(f->height_m > 0)) return 0; /* a uniform fog has no top: lit as it is */
    if (!(sun[1] > 0)) return INFINITY;
    return f->sigma0 * exp(-(p[1] - f->base_m) / f->height_m) * f->height_m / sun[1];
}

double atmos__beams_sun_airlight(const atmos__beams_sun *s, const atmos__beams_fog *f, const double o[3],
                                 const double d[3], double T, double epsilon, int max_steps)
{
    double A, k;
    fog_line(f, o, d, &A, &k);
    /* the sunlight at t is dimmed by C exp(-k t), C its optical depth in at the eye: with the
     * eye's optical depth tau as the variable (d tau = sigma dt, exp(-k t) = 1 - k tau / A) the
     * integrand is exp(-C) exp(-gamma tau), gamma = 1 - d_y / sun_y (1 in uniform fog) */
    const double C = atmos__beams_sun_fog_in(f, s->dir, o);
    if (!(C < 700)) return 0;
    const double gamma = f->height_m > 0 ? 1 - d[1] / s->dir[1] : 1, tauT = line_tau(A, k, T);
    const int flat = !(fabs(gamma * tauT) > 1e-9);
    const double whole = flat ? tauT : -expm1(-gamma * tauT) / gamma; /* int_0^tau(T) exp(-gamma tau) */
    if (!(whole > 0)) return 0;
    int n = (int)ceil(1 / fmax(epsilon, 1e-9));
    n = n < 1 ? 1 : n > max_steps ? max_steps : n;
    double sum = 0;
    if (!s->n) sum = n;
    /* the map's coordinates along the ray, linear in t: x0 + t x1 */
    const double x0 = (atmos__dot3(o, s->right) - s->u0) / s->texel - 0.5, x1 = atmos__dot3(d, s->right) / s->texel;
    const double y0 = (atmos__dot3(o, s->up) - s->v0) / s->texel - 0.5, y1 = atmos__dot3(d, s->up) / s->texel;
    const double z0 = atmos__dot3(o, s->fwd) - s->bias, z1 = atmos__dot3(d, s->fwd);
    for (int i = 0; s->n && i < n; i++) { /* step i: from i whole / n to (i + 1) whole / n of the integral */
        const double q = (i + 0.5) * whole / n, tau = flat ? q : -log1p(-gamma * q) / gamma;
        const double tm = fmin(T, line_t(A, k, tau));
        sum += tm < INFINITY ? lookup(s, x0 + tm * x1, y0 + tm * y1, z0 + tm * z1) : 1;
    }
    const double c = atmos__dot3(s->dir, d);
    return f->albedo * (f->phase ? atmos__fog_phase(f->phase, c) : atmos_phase_hg(c, f->g)) * exp(-C) * whole * sum / n;
}
