/* Fast float evaluation of Riley's sky (see riley_batch.h and riley.c). */
#include "atmosphere/atmosphere_internal.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/fastmath.h"

void atmos__sky_batch_init(atmos__sky_batch *b, const atmos_atmosphere *sky, double eye_y, const double sun[3])
{
    memset(b, 0, sizeof *b);
    b->n = sky->wl.count;
    b->gamma = (float)sky->gamma;
    b->eye_y = (float)eye_y;
    b->ly = (float)sun[1];
    for (int k = 0; k < 3; k++) b->sun[k] = (float)sun[k];
    b->sun_up = sun[1] > 0;
    b->high = sky->gamma * eye_y > ATMOS__RILEY_HIGH_EYE;
    double ey = exp(-sky->gamma * eye_y), ground[ATMOS_MAX_WAVELENGTHS], skyl[ATMOS_MAX_WAVELENGTHS];
    atmos__riley_sunlight(sky, 0.0, sun, b->n, NULL, ground);
    atmos__flat_skylight(sky, sun[1], skyl);
    for (int i = 0; i < b->n; i++) {
        double be = sky->beta_sl[i] * ey;
        b->beta_eye[i] = (float)be;
        double ts0 = b->sun_up ? be / (sky->gamma * sun[1]) : 0.0;
        b->ts0[i] = (float)fmin(ts0, 1e30);
        b->e_ts0[i] = (float)exp(-ts0);
        b->sun_e[i] = (float)sky->sun_e[i];
        b->ground[i] = (float)(sky->desc.ground_albedo / ATMOS_PI * (fmax(sun[1], 0.0) * ground[i] + skyl[i]));
    }
}

/* Built for AVX2 as well as the baseline; the loader picks the best at run time. */
ATMOS_CLONES
void atmos__sky_batch_eval(const atmos__sky_batch *b, int count, const float *dx, const float *dy, const float *dz,
                           const float *weight, float *out, float *scratch)
{
    if (!b->sun_up) return; /* flat earth: no sunlight reaches the air or the ground */
    float *PE = scratch;               /* P(theta) * weight */
    float *G = scratch + count;        /* tau_v(K) / beta_eye */
    float *c = scratch + 2 * count;    /* 1 - p_y / l_y */
    float *eend = scratch + 3 * count; /* beta(K) / beta_eye */
    float *gm = scratch + 4 * count;   /* weight if the ray ends on the ground, else 0 */
    const float gamma = b->gamma, eye_y = b->eye_y, ly = b->ly, inv_ly = 1.0f / b->ly;
    const float sx = b->sun[0], sy = b->sun[1], sz = b->sun[2];
    const float k_ray = 3.0f / (16.0f * 3.14159265358979f);
#pragma omp simd
    for (int i = 0; i < count; i++) {
        /* Branch-free so that it vectorises: both sides of every select are computed
         * with safe denominators, then blended. */
        float py = dy[i];
        float mu = dx[i] * sx + py * sy + dz[i] * sz;
        PE[i] = k_ray * (1.0f + mu * mu) * weight[i];
        float down = py < 0.0f ? 1.0f : 0.0f;
        /* Ground distance K = y / -p_y for descending rays. */
        float K = down * (eye_y / (py < -1e-30f ? -py : 1e-30f));
        float z = gamma * py * K; /* <= 0 for ground rays, 0 otherwise */
        float e = atmos__expf_poly(-z);  /* beta(K)/beta_eye = exp(-gamma p_y K) */
        float zs = fabsf(z) < 1e-3f ? 1.0f : z;
        float gz = fabsf(z) < 1e-3f ? 1.0f - 0.5f * z + z * z * (1.0f / 6.0f) : (1.0f - e) / zs;
        float Gd = K * gz;
        /* Rays to space: G = 1/(gamma p_y); level rays are unbounded (clamped). */
        float pu = py > 1e-20f ? py : 1e-20f;
        float Gu = 1.0f / (gamma * pu);
        Gu = Gu > 1e20f ? 1e20f : Gu;
        G[i] = down > 0.0f ? Gd : Gu;
        eend[i] = down * e;
        c[i] = 1.0f - py * inv_ly;
        gm[i] = down * weight[i];
    }
    (void)ly;
    for (int k = 0; k < b->n; k++) {
        const float be = b->beta_eye[k], ts0 = b->ts0[k], a = b->e_ts0[k], E = b->sun_e[k], gr = b->ground[k];
        float *o = out + (size_t)k * count;
#pragma omp simd
        for (int i = 0; i < count; i++) {
            float x = be * G[i];
            float D = c[i] * x;
            float bexp = atmos__expf_poly(-(x + ts0 * eend[i]));
            /* e^{-ts0} h(D) = (e^{-ts0} - e^{-(x + tsK)}) / D, by series near D = 0. */
            float series = a * (1.0f - D * (0.5f - D * (1.0f / 6.0f - D * (1.0f / 24.0f))));
            float Ds = fabsf(D) < 1e-2f ? 1.0f : D;
            float F = fabsf(D) < 1e-2f ? series : (a - bexp) / Ds;
            /* F >= 0 exactly; in float a = e^{-ts0} underflows to 0 for ts0 > ~104 while the
             * polynomial's clamp leaves bexp at e^-87, which made F, and the radiance, a
             * tiny negative (a NaN stays a NaN for the image check). */
            F = F < 0.0f ? 0.0f : F;
            float L = PE[i] * E * x * F + gm[i] * gr * atmos__expf_poly(-x);
            o[i] += L;
        }
    }
}
