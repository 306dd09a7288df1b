/* The wide uniform slab lit from the zenith that the tests of the fields of the orders >= 2 share
 * (test_nishita_mc.c, test_slice_do.c): NX x NS x NX voxels of VS m, uniform, in a grid of NY
 * voxels' height (empty voxels above and below, so that its faces are where the renderers' grids
 * put them), seen from above in a vacuum with the sun at the zenith, and its reflected radiance
 * per unit irradiance by the independent adding-doubling solver (path_ad.h). Header-only (static
 * inline), included after test.h. */
#ifndef ATMOS_TEST_SLAB_H
#define ATMOS_TEST_SLAB_H
#include "path_ad.h"

#define NX 96
#define NY 16 /* the slab's 12 voxels and 2 empty ones above and below */
#define NS 12
#define VS 50.0
#define SIGMA 1e-9

/* A slab nx voxels wide each way, of optical depth tau across its NS voxels (particles of
 * cross-section SIGMA). */
static inline atmos_volume *test_slab_nx(atmos_context *ctx, double tau, int nx)
{
    float *buf = calloc((size_t)nx * NY * nx, sizeof(float));
    for (int k = 0; buf && k < nx; k++)
        for (int j = (NY - NS) / 2; j < (NY + NS) / 2; j++)
            for (int i = 0; i < nx; i++) buf[((size_t)k * NY + j) * nx + i] = (float)(tau / (SIGMA * VS * NS));
    const int dims[3] = {nx, NY, nx};
    atmos_volume *v = buf ? test_cloud_volume(ctx, dims, VS, buf) : NULL;
    free(buf);
    return v;
}

/* The wide slab (NX voxels each way). */
static inline atmos_volume *test_slab(atmos_context *ctx, double tau) { return test_slab_nx(ctx, tau, NX); }

/* A vacuum, the sun at the zenith (irradiance 1), the camera 20 km from the slab's top centre
 * looking down at it from zenith angle acos(mu), a narrow view (12 x 12 pixels) of the slab's
 * middle; the caller sets the renderer. */
static inline void test_slab_scene(atmos_scene *s, double mu)
{
    test_vacuum_scene(s, 90, 0);
    s->sun.irradiance_count = 1, s->sun.irradiance[0] = 1.0;
    s->width = s->height = 12;
    const double top = 1000 + 0.5 * (NY + NS) * VS, D = 20000, st = sqrt(1 - mu * mu);
    const double pos[3] = {0, top + D * mu, D * st};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &s->camera);
    s->camera.look_at[0] = 0, s->camera.look_at[1] = top, s->camera.look_at[2] = 0;
    s->camera.fov_deg = 1.5;
}

/* The mean of img's first 3 channels over its pixels. */
static inline double test_image_mean(const atmos_image *img)
{
    double s = 0;
    for (int i = 0; i < img->width * img->height; i++)
        for (int c = 0; c < 3; c++) s += img->pixels[i * img->channels + c];
    return s / (3.0 * img->width * img->height);
}

/* The radiance rad[] per unit irradiance (adding-doubling's radiance_up or radiance_down) at mu,
 * linear between its nodes. */
static inline double test_ad_at(const ad_result *r, const double *rad, double mu)
{
    int lo = -1, hi = -1;
    for (int i = 1; i < r->D; i++) {
        if (r->mu[i] <= mu && (lo < 0 || r->mu[i] > r->mu[lo])) lo = i;
        if (r->mu[i] >= mu && (hi < 0 || r->mu[i] < r->mu[hi])) hi = i;
    }
    if (lo < 0 || hi < 0 || lo == hi) return rad[lo < 0 ? hi : lo];
    const double t = (mu - r->mu[lo]) / (r->mu[hi] - r->mu[lo]);
    return (1 - t) * rad[lo] + t * rad[hi];
}

/* The reflected radiance per unit irradiance at mu. */
static inline double test_ad_up(const ad_result *r, double mu) { return test_ad_at(r, r->radiance_up, mu); }

/* The diffusely transmitted radiance per unit irradiance at mu (below the slab, mu from the nadir). */
static inline double test_ad_down(const ad_result *r, double mu) { return test_ad_at(r, r->radiance_down, mu); }

/* The radiance per unit irradiance at mu of the slab of optical depth tau (HG g, albedo 1, the
 * sun at the zenith), reflected (down 0) or diffusely transmitted (down 1; mu < 1), as the
 * discrete-ordinates field's own approximation would give it if solved exactly in angle and
 * depth: delta-M of degree lt (adding-doubling with the scaled moments above lt dropped) with its
 * first order replaced by the full phase's (TMS, Nakajima & Tanaka 1988, J. Quant. Spectrosc.
 * Radiat. Transfer 40, 51), as the slice renderer's eye pass draws it. Its difference from the
 * full solution is the degree's truncation alone. */
static inline double test_ad_tms(double tau, double g, int lt, double mu, int down)
{
    ad_result r;
    if (!ad_slab_lt(tau, 1.0, 1.0, g, 0.0, 1.0, 32, lt, &r)) return 0;
    const double PI = 3.14159265358979323846, c = down ? mu : -mu, f = pow(g, lt + 1), ts = (1 - f) * tau;
    double ps = 0, p0 = 1, p1 = c; /* the scaled phase of degree lt at the scattering angle */
    for (int l = 0; l <= lt; l++) {
        const double pl = l == 0 ? 1 : l == 1 ? c : ((2 * l - 1) * c * p1 - (l - 1) * p0) / l;
        if (l >= 2) p0 = p1, p1 = pl;
        ps += (2 * l + 1) * (pow(g, l) - f) / (1 - f) * pl;
    }
    const double pf = (1 - g * g) / pow(1 + g * g - 2 * g * c, 1.5); /* 4 pi HG */
    /* the first order per unit phase (4 pi normalised) in the scaled slab, seen at mu */
    const double geo = down ? (exp(-ts) - exp(-ts / mu)) / (4 * PI * (1 - mu))
                            : (1 - exp(-ts * (1 + 1 / mu))) / (4 * PI * (1 + mu));
    return (down ? test_ad_down(&r, mu) : test_ad_up(&r, mu)) - ps * geo + pf / (1 - f) * geo;
}

#endif
