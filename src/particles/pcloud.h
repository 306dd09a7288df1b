/* Particle clouds (Harris 2002 §1.1.1, §2.3): a cloud as a set of soft particles, each a
 * Gaussian blob of number density n(x) = n0 exp(-|x - c|^2 / (2 s^2)) of one particle type
 * (a field of the volume it came from, whose optics give its cross sections and phase
 * function), cut at CUT s. The blob's optical depth along a line at distance b from its
 * centre is tau(b) = sigma_ext n0 s sqrt(2 pi) exp(-b^2 / (2 s^2)) erf(sqrt((CUT^2 s^2 -
 * b^2) / (2 s^2))): a (nearly) Gaussian splat on screen, which is what Harris draws, and a
 * sum of such blobs is a density field the path tracer can render as it is (pconvert.c),
 * so the two renderers see the very same cloud.
 *
 * Internal to the library (src/particles/, above core and volume). Structure of arrays. */
#ifndef ATMOS_PCLOUD_H
#define ATMOS_PCLOUD_H

#include "atmos/atmos.h"
#include "core/fastmath.h"

#include <math.h>

#include <stdint.h>

/* Splats and grids stop at this many s from a centre (the density is exp(-4.5) = 1.1 % of
 * the peak there). */
#define ATMOS__PCLOUD_CUT 3.0

/* The column of a particle cut at CUT = 3 widths, at distance b from its centre, relative to
 * tc = sigma_ext n0 s sqrt(2 pi): exp(-u / 2) erf(sqrt((9 - u) / 2)), u = b^2 / s^2 (0 beyond
 * the cut). With Abramowitz & Stegun 7.1.26 for erf (|error| <= 1.5e-7), erf(z) = 1 - P(t)
 * exp(-z^2), t = 1 / (1 + 0.3275911 z), and exp(-u / 2) exp(-z^2) = exp(-4.5): one exponential,
 * no branch (the loops over texels and pixels vectorise). */
static inline float atmos__pcloud_column(float u)
{
    u = u < 9.0f ? u : 9.0f;
    const float z = sqrtf(0.5f * (9.0f - u)), t = 1.0f / (1.0f + 0.3275911f * z);
    const float P = t * (0.254829592f + t * (-0.284496736f + t * (1.421413741f + t * (-1.453152027f + t * 1.061405429f))));
    const float c = atmos__expf_poly(-0.5f * u) - 0.011108996538242306f * P; /* exp(-4.5) */
    return c > 0.0f ? c : 0.0f;
}

/* The peak n0 of a particle of width s holding the particles of a cell of edge h at mean
 * density mean: mean h^3 / (0.9707 (2 pi)^(3/2) s^3), 0.9707 = P(chi^2_3 <= 9) = erf(3 / sqrt 2)
 * - sqrt(18 / pi) exp(-4.5), the share of a 3-D Gaussian's mass within the cut. */
static inline double atmos__pcloud_peak(double mean, double h, double s)
{
    return mean * h * h * h / (0.9707091134651118 * 15.749609945722419 * s * s * s);
}

/* Lays texel coordinates (tx, ty) of the w x h texture tex (C channels: colour, coverage),
 * read bilinearly, over pixel px: px (1 - coverage) + colour. */
static inline void atmos__pcloud_over(const float *tex, int w, int h, int C, double tx, double ty, float *px)
{
    tx = tx > 0.0 ? (tx < w - 1.001 ? tx : w - 1.001) : 0.0, ty = ty > 0.0 ? (ty < h - 1.001 ? ty : h - 1.001) : 0.0;
    const int i0 = (int)tx, j0 = (int)ty;
    const double ax = tx - i0, ay = ty - j0;
    const float *t00 = tex + ((size_t)j0 * w + i0) * C, *t01 = t00 + C, *t10 = t00 + (size_t)w * C, *t11 = t10 + C;
    if (C == 4) { /* three wavelengths and coverage: in single precision, the four as one vector */
        const float bx = (float)ax, by = (float)ay;
        float q[4];
        for (int k = 0; k < 4; k++) q[k] = (1 - by) * ((1 - bx) * t00[k] + bx * t01[k]) + by * ((1 - bx) * t10[k] + bx * t11[k]);
        const float keep4 = 1.0f - q[3];
        for (int k = 0; k < 3; k++) px[k] = px[k] * keep4 + q[k];
        px[3] = 1.0f - (1.0f - px[3]) * keep4;
        return;
    }
    float v[ATMOS_MAX_WAVELENGTHS + 1] = {0};
    for (int k = 0; k < C; k++)
        v[k] = (float)((1 - ay) * ((1 - ax) * t00[k] + ax * t01[k]) + ay * ((1 - ax) * t10[k] + ax * t11[k]));
    const float keep = 1.0f - v[C - 1];
    for (int k = 0; k < C - 1; k++) px[k] = px[k] * keep + v[k];
    px[C - 1] = 1.0f - (1.0f - px[C - 1]) * keep;
}

typedef struct atmos__pcloud {
    int n, cap;
    float *x, *y, *z;     /* centres, m (world) */
    float *s;             /* Gaussian widths, m */
    float *n0;            /* peak number densities, m^-3 */
    uint8_t *field;       /* particle type: the field of the source volume */
    int nfields;
    char field_name[ATMOS_VOLUME_MAX_FIELDS][32];
    char particle[ATMOS_VOLUME_MAX_FIELDS][64];
} atmos__pcloud;

/* Appends a particle; returns ATMOS_E_NOMEM when it cannot grow. */
atmos_status atmos__pcloud_add(atmos__pcloud *pc, double x, double y, double z, double s, double n0, int field);
void atmos__pcloud_free(atmos__pcloud *pc);
/* The box holding every particle's splat (centres +- CUT s); empty cloud: lo > hi. */
void atmos__pcloud_bounds(const atmos__pcloud *pc, double lo[3], double hi[3]);

/* ---- pconvert.c */
/* Particles from a volume: one per cell of spacing h (m; 0: the volume's voxel, at least so
 * many that at most max_particles are made, 0 = 2 million) whose mean density over the cell
 * is above 1e-4 of the field's largest, at the cell's density-weighted centre, with
 * s = 0.6 h and n0 = mean h^3 / (0.9707 (2 pi)^(3/2) s^3) (0.9707: the Gaussian's mass within
 * the cut), so that each particle holds its cell's particles and the sum over a lattice
 * reproduces a uniform field within 0.2 %. offset: added
 * to the volume's positions. */
atmos_status atmos__pcloud_from_volume(atmos_context *ctx, const atmos_volume *vol, const double offset[3], double h,
                                       int max_particles, atmos__pcloud *out);
/* The density grid of particles (voxels of edge voxel_m over their bounds, one field per
 * particle type): the same cloud for the path tracer and the slice renderer. */
atmos_status atmos__pcloud_to_volume(atmos_context *ctx, const atmos__pcloud *pc, double voxel_m, atmos_volume **out);

/* ---- pgenerate.c: particle clouds made as Harris's notes describe them (§1.1.1): clusters
 * of ellipsoids filled with particles */
/* The presets ("harris_cumulus": one fair-weather cumulus; "harris_field": a field of 120 of
 * them over 30 x 30 km), NULL-terminated. */
const char *const *atmos__pcloud_generator_names(void);
/* Makes a preset's particles (one "cloud" field of droplets; world positions as a generated
 * volume's: about x = z = 0, the bases at 1.5 km times scale); same seed, same particles. scale multiplies the extent (0:
 * 1). *voxel_m: the grid spacing for atmos__pcloud_to_volume (half the finest particle spacing,
 * at most 640 voxels across: a field's grid blurs its smallest clouds). spacing_m > 0: the
 * particles' lattice edge in every cloud (0: the preset's, 1/24 of the cumulus's width, 42 m in
 * every cloud of the field, each cut to a fractal outline (pfootprint.c); a given spacing leaves
 * a field's clouds in other places than the preset's, the same for every spacing). */
atmos_status atmos__pcloud_generate(atmos_context *ctx, const char *preset, uint64_t seed, double scale,
                                    double spacing_m, atmos__pcloud *out, double *voxel_m);

/* ---- pfootprint.c: the fractal outline a field's particle cloud is cut to */
typedef struct atmos__pfootprint_desc {
    uint64_t seed;         /* the outline's noise */
    double cx, cz, w;      /* the cloud's centre and width (the noise's unit) */
    double a, b;           /* the outline's smooth ellipse: semi-axes along x and z */
    double reach_a, reach_b; /* no column outside this ellipse is kept */
    double core;           /* the columns where the smooth ellipse's 1 - (x/a)^2 - (z/b)^2 >= core: never cut */
    double x0, z0, h;      /* column (i, k) at (x0 + i h, z0 + k h) */
    int nx, nz;
} atmos__pfootprint_desc;
typedef struct atmos__pfootprint {
    int nx, nz;
    float *phi; /* [k nx + i]: the outline's function (>= 0 inside), -1 where cut or not joined to the core */
} atmos__pfootprint;
/* The columns' outline function; ATMOS_E_NOMEM (nothing held) if out of memory. */
atmos_status atmos__pfootprint_make(const atmos__pfootprint_desc *d, atmos__pfootprint *out);
void atmos__pfootprint_free(atmos__pfootprint *f);

/* ---- pcluster.c: the clouds of a particle set (what Harris's impostors are made of) */
typedef struct atmos__pclusters {
    int n;                /* clouds */
    int *start;           /* [n + 1]: cloud c's particles are idx[start[c] .. start[c + 1]) */
    int *idx;             /* particle indices, cloud by cloud, ascending within each */
    double (*centre)[3];  /* the middle of each cloud's box */
    double *radius;       /* the sphere about it that holds every splat of the cloud */
} atmos__pclusters;
/* Groups the particles into clouds: two particles whose splats (CUT s) overlap or come
 * within link metres belong to one cloud (connected components; clouds numbered by their
 * lowest particle). */
atmos_status atmos__pcloud_cluster(atmos_context *ctx, const atmos__pcloud *pc, double link, atmos__pclusters *out);
void atmos__pclusters_free(atmos__pclusters *c);

/* ---- pshade.c: Harris's multiple forward scattering (§2.2.1, Eq. 8) */
/* What the light pass and the eye pass need of each particle type, per wavelength. */
typedef struct atmos__poptics {
    int nw;                                               /* wavelengths */
    double sigma_ext[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS]; /* m^2 */
    double albedo[ATMOS_VOLUME_MAX_FIELDS][ATMOS_MAX_WAVELENGTHS];
    const atmos_msphase *ms[ATMOS_VOLUME_MAX_FIELDS];    /* Ams_n and F_n of each type */
    /* NULL, or ms[f]'s Ams_n on the scattering angle's cosine for the eye pass (pphase.h: no
     * acos, within its error of ms[f]); the owner makes and frees them */
    const struct atmos__pphase *ph[ATMOS_VOLUME_MAX_FIELDS];
} atmos__poptics;

/* The light reaching each particle from the sun (direction sun, toward it): light[p * nw + k]
 * is the share of the sunlight outside the cloud that arrives at particle p's centre, and
 * order[p] the expected count of scatterings behind it (Riley's n: the scattering optical
 * depth on the way, Eq. 21; mean over the wavelengths). Harris's recurrence
 * I_k = g_{k-1} + T_{k-1} I_{k-1} on a light buffer seen from the sun, the particles
 * splatted nearest-first, with Riley's forward share: a particle of optical depth tau along
 * a texel leaves T + (1 - T) a F_{n+1} of the light, T = exp(-tau) (Eq. 25 for a thin slab),
 * F_{n+1} the forward fraction at the particle's scattering count. The wavelengths go in
 * groups of up to 4 through one pass, which computes a texel's column once for the group (each
 * wavelength's light the same as in a pass of its own), one thread per group (the result does
 * not depend on the thread count). Only the particles idx[0..nidx)
 * (idx NULL: all) are lit and shade each other: a cloud at a time, each with a buffer fitted
 * to it. res: the buffer's texels per
 * side (0: texels of texel_scale x 0.7 of the smallest particle's width, at most 1024). */
atmos_status atmos__pcloud_shade(atmos_context *ctx, const atmos__pcloud *pc, const int *idx, int nidx,
                                 const atmos__poptics *o, const double sun[3], int res, double texel_scale, float *light,
                                 float *order);

/* Points (not particles) that read a light pass as particles do, and splat nothing: the
 * vertices of an object inside a cloud (Harris §3.2), lit by the light buffer. light[i * nw + k]
 * receives the share of the light arriving at point i (1 where the buffer does not reach). */
typedef struct atmos__pprobes {
    int n;
    const float *xyz;     /* [3 n], world metres */
    float *light;         /* [n nw] */
} atmos__pprobes;
/* atmos__pcloud_shade with probes pr (NULL: none; the particles' light is the same with and
 * without them). */
atmos_status atmos__pcloud_shade_probes(atmos_context *ctx, const atmos__pcloud *pc, const int *idx, int nidx,
                                        const atmos__poptics *o, const double sun[3], int res, double texel_scale,
                                        float *light, float *order, const atmos__pprobes *pr);

/* ---- psplat.c: the eye pass (§2.2.2, Eq. 9) */
/* ---- pscreen.c: where a sphere falls on the image */
/* The pixels of rect [x0, y0, x1, y1) that the sphere (c, r) may cover seen by cam (pinhole,
 * fisheye or equirect): bb[4] = [x0, x1) x [y0, y1); *Z its centre's depth along a pinhole's
 * view, its distance from the eye for the others. 0 when the sphere holds the eye, lies behind
 * a pinhole or out of a fisheye's field, or misses rect. */
int atmos__pcloud_screen_box(const atmos_camera *cam, const double c[3], double r, const int rect[4], int bb[4],
                             double *Z);
/* The lights of a frame: n lights toward dir[j] with irradiance e[j] outside the cloud, their
 * light passes (light[j], order[j]: atmos__pcloud_shade's), and the air from the eye to each
 * particle (air_t: transmittance, air_l: in-scattered radiance, [p * nw + k]; NULL: none). */
typedef struct atmos__plights {
    int n;
    const float *const *light, *const *order;
    const double (*dir)[3];
    const double (*e)[ATMOS_MAX_WAVELENGTHS];
    const float *air_t, *air_l;
    const float *diffuse; /* NULL, or [p * nw + k]: radiance particle p scatters toward the eye besides the
                             lights' (the diffuse light field's), added to its colour before the air */
} atmos__plights;
/* Composites the particles idx[0..nidx) (idx NULL: all) over img (width x height, nw + 1
 * channels: radiance per wavelength, then coverage) back to front, within rect [x0, y0, x1,
 * y1): a particle adds (a sum_j Ams_{n_j+1}(theta_j) E_j I_pj + diffuse_p) (1 - T) and leaves T =
 * exp(-tau(b)) of what is behind it, b the pixel ray's distance from its centre (Harris's
 * splat, exactly), theta_j the scattering angle from light j toward the eye; seen through the
 * air its colour is air_l + air_t colour (exact for an opaque particle; the air behind a
 * translucent one is in what it covers). Every camera type (a wide one's pixel rays from
 * atmos_camera_ray); particles whose splat holds the eye are left out. Threads over tiles of 32 x 32 pixels (the image does not depend on the
 * thread count). *drawn: the particles drawn (may be NULL). */
atmos_status atmos__pcloud_splat(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o,
                                 const atmos__plights *L, const int *idx, int nidx, const atmos_camera *cam,
                                 const int rect[4], atmos_image *img, int *drawn);

/* ---- pimpostor.c: Harris's dynamically generated impostors (§3) */
/* One cloud's impostor: its particles splatted into a res x res image (nw + 1 channels:
 * colour, coverage) by a camera at `view` fitted to the cloud's sphere. */
typedef struct atmos__pimpostor {
    int valid, res;
    double split;         /* the caller's: where a split cloud was cut for it (m from the cloud's centre) */
    double view[3];
    atmos_camera cam;
    atmos_image *img;
    int has_box, box[4]; /* atmos__pimpostor_make's: the texels holding anything, [x0, x1) x [y0, y1) */
} atmos__pimpostor;
/* The texels a cloud of radius r needs seen from distance d by a frame of focal length f
 * pixels: its projected diameter 2 r f / d (Schaufler's resolution, Harris Eq. 11), rounded
 * up to a multiple of 8, in [8, max_res]. */
int atmos__pimpostor_res(double r, double d, double f, int max_res);
/* The texels a particle's width s (its Gaussian's standard deviation) spans at least in an
 * impostor limited by atmos__pimpostor_max_res: the splats are smooth over that scale, so the
 * impostor's bilinear reading between texels holds them (test_particles' impostor_texels). */
#define ATMOS__PIMPOSTOR_TEXELS_PER_WIDTH 2.0
/* The most texels an impostor of a cloud of radius r whose narrowest particle has width smin
 * needs whatever the view: the fewest, a multiple of 8, across which smin spans
 * ATMOS__PIMPOSTOR_TEXELS_PER_WIDTH texels; in [8, max_res] (max_res when smin is not > 0). */
int atmos__pimpostor_max_res(double r, double smin, int max_res);
/* Whether im still serves the eye e for the cloud (centre c, radius r): the eye outside the
 * sphere, the angle at the centre between im's view and e within tol radians (Harris's
 * translation error), and im's texels at least what the view needs (the resolution error). */
int atmos__pimpostor_serves(const atmos__pimpostor *im, const double c[3], double r, const double e[3], double tol,
                            double f, int max_res);
/* How far im is from serving the eye e (the larger of the angle round the centre over tol and
 * the texels needed over im's): above 1 where atmos__pimpostor_serves says no, INFINITY for an
 * impostor never made or the eye inside the sphere. Orders the impostors to make again. */
double atmos__pimpostor_error(const atmos__pimpostor *im, const double c[3], double r, const double e[3], double tol,
                              double f, int max_res);
/* Makes im for the eye e: the particles idx[0..nidx) splatted by a camera at e looking at c
 * whose field just holds the sphere of radius r. */
atmos_status atmos__pimpostor_make(atmos_context *ctx, atmos__pimpostor *im, const atmos__pcloud *pc,
                                   const atmos__poptics *o, const atmos__plights *L, const int *idx, int nidx,
                                   const double c[3], double r, const double e[3], int res);
/* Makes rows [y0, y1) of im's image as atmos__pimpostor_make makes them (the same values): the
 * first piece (y0 0) sets im's camera and clears its image, im valid once the last (y1 res) is
 * made; the pieces in order from the same eye e, so a make can be spread over several calls. */
atmos_status atmos__pimpostor_make_rows(atmos_context *ctx, atmos__pimpostor *im, const atmos__pcloud *pc,
                                        const atmos__poptics *o, const atmos__plights *L, const int *idx, int nidx,
                                        const double c[3], double r, const double e[3], int res, int y0, int y1);
/* Draws the impostors ims[0..n) in that order (far to near; cloud q's centre c[q], radius r[q])
 * over img seen by cam within rect: each pixel's ray meets an impostor's plane (through its
 * cloud's centre, facing its view), the texture is read there (bilinear), and the pixel
 * becomes pixel (1 - coverage) + colour. One pass over the rows on the threads for up to 64
 * impostors. */
void atmos__pimpostor_draw(atmos_context *ctx, int n, const atmos__pimpostor *const *ims, const double *const *c,
                           const double *r, const atmos_camera *cam, const int rect[4], atmos_image *img);
void atmos__pimpostor_free(atmos__pimpostor *im);

/* ---- pinside.c: Harris §3.1, the head in the clouds */
/* The particles idx[0..nidx) splatted into an image of 1/factor of cam's pixels (a pinhole) per
 * axis (the same view), then laid over img within rect, read bilinearly: pixel (1 - coverage) +
 * colour. layer_px > 0: the particles nearer than where a splat of the narrowest one spans
 * layer_px pixels of an image 2, 4 or 8 times coarser still are splatted into that image (depth
 * bands, so each layer lies wholly in front of the ones behind it), laid over the 1/factor one
 * bilinearly, nearest last. 0: every particle at 1/factor. */
atmos_status atmos__pimpostor_screen(atmos_context *ctx, const atmos__pcloud *pc, const atmos__poptics *o,
                                     const atmos__plights *L, const int *idx, int nidx, const atmos_camera *cam,
                                     int factor, double layer_px, const int rect[4], atmos_image *img);

#endif
