/* Phase functions of ice and snow crystals: Monte Carlo geometric optics (the tracer in
 * crystal_geometry.c) plus Fraunhofer diffraction, binned onto the phase-table grid.
 *
 * Physics (docs/optics-crystals.md has the full account):
 *  - extinction paradox: sigma_ext = 2 <A>, <A> the orientation-mean projected area,
 *    which for a convex body is a quarter of its surface area (Cauchy's theorem); half
 *    of it is scattered by reflection and refraction (the rays), half by diffraction
 *    (van de Hulst 1957, §8.22; Takano & Liou 1989 J. Atmos. Sci. 46, 3).
 *  - diffraction: Fraunhofer pattern of a circular aperture with the same mean
 *    projected area (the Airy pattern), an approximation to the average over the
 *    hexagonal shadows that differs mainly in the ring structure, which the rendering
 *    never resolves anyway (and which a real size spread washes out).
 *  - delta transmission: rays leaving through a face parallel to the entry face keep the
 *    incident direction exactly; geometric optics gives a delta function at 0°. Like
 *    the diffracted light it is really spread by diffraction at the facet apertures, so
 *    we give it the same (Airy) angular shape (cf. Mishchenko & Macke 1998, J. Geophys.
 *    Res. 103, 1799, who show the delta part belongs with the forward diffraction peak).
 *  - snow: the same prisms with facet normals tilted at random at every interaction
 *    ("distorted" crystals, Macke, Mueller & Raschke 1996, J. Atmos. Sci. 53, 2813;
 *    Hess, Koelemeijer & Stammes 1998, JQSRT 60, 301), which smooths the halos away.
 *
 * Determinism: the rays are split into CHUNKS fixed chunks, each with its own RNG stream
 * seeded from (wavelength, chunk); chunks run in parallel and their histograms are added
 * in chunk order, so the result is bit-identical for any thread count.
 */
#include "optics/crystal_internal.h"
#include "optics/optics_internal.h"
#include "core/internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* j1() is POSIX (XSI), not C11; declared here to keep the strict C11 build. glibc's libm
 * has it. */
extern double j1(double);

#define CHUNKS 64
#define BIN_DEG 0.02                      /* histogram bin width */
#define NBINS ((int)(180.0 / BIN_DEG + 0.5))
#define MAX_HITS 30                       /* internal interactions followed per ray */
#define ENERGY_CUTOFF 1e-7                /* see atmos__crystal_optics.cutoff */
/* Rays per wavelength. Ice: the halos need ~1 % noise within a 0.1° kernel; 3 million
 * rays take ~3 s per wavelength on 2 cores. Snow has no sharp features, so a wider
 * kernel and fewer rays give the same noise. */
#define DEFAULT_RAYS_ICE 3000000L
#define DEFAULT_RAYS_ICE_FAST 200000L
#define DEFAULT_RAYS_SNOW 1000000L
#define DEFAULT_RAYS_SNOW_FAST 100000L
#define MAX_RAYS 2000000000L
#define DEFAULT_RADIUS_M 100e-6
#define DEFAULT_TILT_RAD 0.3
/* Smoothing kernel (Gaussian in theta, standard deviation in degrees). The 22° halo of
 * randomly oriented prisms is a step at the minimum deviation followed by a slower
 * decay: a Gaussian keeps the step's mid-point (the steepest rise) at D_min and moves
 * the maximum outwards by about twice its width, so the ice kernels stay small (the
 * maxima land ~0.2° outside D_min, the edges within 0.05°). Snow is smooth by design. */
#define KERNEL_DEG_ICE 0.08
#define KERNEL_DEG_ICE_FAST 0.12
#define KERNEL_DEG_SNOW 0.25
/* Near the poles (within POLE_DEG of 0° or 180°) the solid angle per degree vanishes, so
 * the kernel widens linearly to POLE_KERNEL_DEG to keep the noise bounded there. */
#define POLE_DEG 5.0
#define POLE_KERNEL_DEG 1.0
/* Exit angles below this are delta transmission (exactly 0 up to rounding). */
#define DELTA_RAD 1e-9

typedef struct chunk_result {
    double *hist; /* NBINS energies by scattering angle, delta transmission excluded */
    double reflected, transmitted, absorbed, lost, delta;
} chunk_result;

typedef struct job {
    atmos__crystal crystal;
    atmos__crystal_optics optics;
    uint64_t seed;
    long rays;
} job;

static long chunk_rays(long rays, int chunk)
{
    return rays / CHUNKS + (chunk < rays % CHUNKS ? 1 : 0);
}

static void run_chunk(const job *jb, int chunk, chunk_result *cr)
{
    memset(cr->hist, 0, sizeof(double) * NBINS);
    cr->reflected = cr->transmitted = cr->absorbed = cr->lost = cr->delta = 0.0;
    atmos__rng rng;
    atmos__rng_seed(&rng, jb->seed ^ (0xD1B54A32D192ED03ull * (uint64_t)(chunk + 1)));
    atmos__crystal_ray ray;
    long n = chunk_rays(jb->rays, chunk);
    for (long i = 0; i < n; i++) {
        atmos__crystal_trace(&jb->crystal, &jb->optics, &rng, &ray);
        cr->reflected += ray.reflected;
        cr->transmitted += ray.transmitted;
        cr->absorbed += ray.absorbed;
        cr->lost += ray.lost;
        for (int e = 0; e < ray.n_exit; e++) {
            double th = ray.theta[e];
            if (e > 0 && th < DELTA_RAD) {
                cr->delta += ray.weight[e];
                continue;
            }
            int b = (int)(th * ATMOS_RAD2DEG / BIN_DEG);
            if (b < 0) b = 0;
            if (b >= NBINS) b = NBINS - 1;
            cr->hist[b] += ray.weight[e];
        }
    }
}

/* Kernel standard deviation at theta (degrees). */
static double kernel_at(double theta, double k0)
{
    double psi = fmin(theta, 180.0 - theta);
    if (psi >= POLE_DEG) return k0;
    return k0 + (POLE_KERNEL_DEG - k0) * (1.0 - psi / POLE_DEG);
}

/* Energy per steradian at theta from the histogram: the kernel-weighted energy over the
 * kernel-weighted solid angle of the bins (a ratio estimator, which stays unbiased for
 * a constant density even where the kernel is cut by 0° or 180°). */
static double smoothed_density(const double *hist, const double *omega, double theta, double k0)
{
    double sd = kernel_at(theta, k0);
    int lo = (int)floor((theta - 4.0 * sd) / BIN_DEG), hi = (int)ceil((theta + 4.0 * sd) / BIN_DEG);
    if (lo < 0) lo = 0;
    if (hi > NBINS - 1) hi = NBINS - 1;
    double num = 0.0, den = 0.0;
    for (int b = lo; b <= hi; b++) {
        double x = ((b + 0.5) * BIN_DEG - theta) / sd;
        double k = exp(-0.5 * x * x);
        num += k * hist[b];
        den += k * omega[b];
    }
    return den > 0.0 ? num / den : 0.0;
}

/* Airy pattern [2 J1(x) / x]^2, x = k a sin(theta), averaged over the grid cell around
 * theta so that rings finer than the grid are replaced by their mean instead of being
 * aliased. Zero beyond 90°, where Fraunhofer's small-angle diffraction does not apply
 * (the pattern is ~(ka)^-3 there anyway). */
static double airy(double x) { return fabs(x) < 1e-8 ? 1.0 : pow(2.0 * j1(x) / x, 2.0); }

static double airy_cell(double ka, double th0, double th1)
{
    if (th0 >= 90.0) return 0.0;
    if (th1 > 90.0) th1 = 90.0;
    double x0 = ka * sin(th0 * ATMOS_DEG2RAD), x1 = ka * sin(th1 * ATMOS_DEG2RAD);
    int m = (int)ceil(fabs(x1 - x0) / 0.25);
    if (m < 1) return airy(0.5 * (x0 + x1));
    if (m > 2000) m = 2000;
    double s = 0.0;
    for (int i = 0; i < m; i++) s += airy(x0 + (i + 0.5) * (x1 - x0) / m);
    return s / m;
}

static uint64_t hash_double(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return atmos__splitmix64(&u);
}

atmos_status atmos__crystal_phase_ex(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                     const double *theta_deg, double *phase, atmos__phase_result *res,
                                     atmos__phase_progress progress, void *progress_user,
                                     atmos__crystal_stats *stats)
{
    /* ------------------------------------------------ arguments and resolved parameters */
    if (!p || !theta_deg || !phase || n_angles < 2)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "crystal phase: missing particle, grid or output (n_angles %d)",
                            n_angles);
    if (p->kind != ATMOS_PARTICLE_ICE && p->kind != ATMOS_PARTICLE_SNOW)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "crystal phase: particle kind %d is not ice or snow", (int)p->kind);
    const char *what = p->kind == ATMOS_PARTICLE_ICE ? "ice" : "snow";
    if (!(nm >= 100.0 && nm <= 100000.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: wavelength %g nm outside [100, 100000]", what, nm);
    if (p->habit != ATMOS_CRYSTAL_COLUMN && p->habit != ATMOS_CRYSTAL_PLATE)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: habit %d is neither column (0) nor plate (1)", what,
                            (int)p->habit);
    if (!(p->aspect_ratio == 0.0 || (p->aspect_ratio >= 0.01 && p->aspect_ratio <= 100.0)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: aspect_ratio must be 0 (default) or in [0.01, 100], got %g",
                            what, p->aspect_ratio);
    if (!(p->size.r_m >= 0.0 && p->size.r_m <= 0.1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: crystal radius must be in [0, 0.1] m, got %g", what,
                            p->size.r_m);
    if (!(p->sigma_ext_m2 >= 0.0 && p->sigma_ext_m2 <= 0.1))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: sigma_ext_m2 must be in [0, 0.1] m^2, got %g", what,
                            p->sigma_ext_m2);
    if (!(p->distortion >= 0.0 && p->distortion <= 1.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: distortion must be in [0, 1] rad, got %g", what,
                            p->distortion);
    if (p->rays < 0 || p->rays > MAX_RAYS)
        return atmos__error(ctx, ATMOS_E_LIMIT, "%s phase: rays must be in [0, %ld], got %ld", what, MAX_RAYS, p->rays);
    for (int i = 0; i < n_angles; i++)
        if (!(theta_deg[i] >= 0.0 && theta_deg[i] <= 180.0) || (i && !(theta_deg[i] > theta_deg[i - 1])))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: angle grid must increase within [0, 180] (index %d)",
                                what, i);

    double aspect = p->aspect_ratio > 0.0 ? p->aspect_ratio : (p->habit == ATMOS_CRYSTAL_PLATE ? 0.2 : 2.0);
    /* Surface area S = 3 sqrt(3) R^2 (two hexagons) + 6 R L (six rectangles), L = 2 R aspect. */
    double s_per_r2 = 3.0 * sqrt(3.0) + 12.0 * aspect;
    double radius;
    if (p->size.r_m > 0.0) radius = p->size.r_m;
    else if (p->sigma_ext_m2 > 0.0) radius = sqrt(2.0 * p->sigma_ext_m2 / s_per_r2); /* 2 S/4 = sigma_ext */
    else radius = DEFAULT_RADIUS_M;
    if (!(radius > 1e-9))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: crystal radius %g m too small", what, radius);
    double tilt = p->kind == ATMOS_PARTICLE_SNOW ? (p->distortion > 0.0 ? p->distortion : DEFAULT_TILT_RAD) : 0.0;
    int snow = p->kind == ATMOS_PARTICLE_SNOW;
    long rays = p->rays > 0 ? p->rays
                            : snow ? (p->fast ? DEFAULT_RAYS_SNOW_FAST : DEFAULT_RAYS_SNOW)
                                   : (p->fast ? DEFAULT_RAYS_ICE_FAST : DEFAULT_RAYS_ICE);
    if (rays < CHUNKS) rays = CHUNKS;
    double k0 = snow ? KERNEL_DEG_SNOW : p->fast ? KERNEL_DEG_ICE_FAST : KERNEL_DEG_ICE;

    atmos_complex m = atmos_refractive_index_ice(nm);
    if (!(m.re > 1.0 && m.re < 3.0 && m.im <= 0.0 && isfinite(m.im)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: refractive index %g%+gi at %g nm unusable", what, m.re,
                            m.im, nm);

    job jb;
    atmos__crystal_init(&jb.crystal, radius, 2.0 * radius * aspect);
    jb.optics.n = m.re;
    jb.optics.alpha = 4.0 * ATMOS_PI * -m.im / (nm * 1e-9);
    jb.optics.tilt = tilt;
    jb.optics.max_hits = MAX_HITS;
    jb.optics.cutoff = ENERGY_CUTOFF;
    jb.seed = hash_double(nm) ^ ((uint64_t)p->kind << 56);
    jb.rays = rays;
    const double mean_area = 0.25 * jb.crystal.surface_area; /* Cauchy */

    /* ------------------------------------------------ rays, chunk batches in parallel */
    int threads = atmos__threads(ctx);
    if (threads < 1) threads = 1;
    if (threads > CHUNKS) threads = CHUNKS;
    double *hist = calloc((size_t)NBINS * (size_t)(threads + 2), sizeof(double));
    double *airy_tab = malloc(sizeof(double) * (size_t)n_angles);
    if (!hist || !airy_tab) {
        free(hist);
        free(airy_tab);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s phase: out of memory for histograms", what);
    }
    double *total = hist, *omega = hist + NBINS, *slots = hist + 2 * (size_t)NBINS;
    chunk_result cr[CHUNKS];
    double reflected = 0.0, transmitted = 0.0, absorbed = 0.0, lost = 0.0, delta = 0.0;
    for (int c0 = 0; c0 < CHUNKS; c0 += threads) {
        int nb = CHUNKS - c0 < threads ? CHUNKS - c0 : threads;
        for (int j = 0; j < nb; j++) cr[j].hist = slots + (size_t)j * NBINS;
#pragma omp parallel for num_threads(threads) schedule(static, 1)
        for (int j = 0; j < nb; j++) run_chunk(&jb, c0 + j, &cr[j]);
        /* Chunk order, whatever thread ran what. */
        for (int j = 0; j < nb; j++) {
            for (int b = 0; b < NBINS; b++) total[b] += cr[j].hist[b];
            reflected += cr[j].reflected;
            transmitted += cr[j].transmitted;
            absorbed += cr[j].absorbed;
            lost += cr[j].lost;
            delta += cr[j].delta;
        }
        if (progress && progress(progress_user, (double)(c0 + nb) / CHUNKS)) {
            free(hist);
            free(airy_tab);
            return atmos__error(ctx, ATMOS_E_CANCELLED, "%s phase at %g nm: cancelled", what, nm);
        }
    }
    double nr = (double)rays;
    reflected /= nr;
    transmitted /= nr;
    absorbed /= nr;
    lost /= nr;
    delta /= nr;

    /* ------------------------------------------------ assemble the phase function */
    for (int b = 0; b < NBINS; b++)
        omega[b] = 2.0 * ATMOS_PI * (cos(b * BIN_DEG * ATMOS_DEG2RAD) - cos((b + 1) * BIN_DEG * ATMOS_DEG2RAD));
    /* Energy that left the crystal through the rays; the lost part (still inside after
     * MAX_HITS interactions, typically < 1e-3) is given the same angular distribution
     * as the rest by normalising with what left. */
    double out_energy = 0.0;
    for (int b = 0; b < NBINS; b++) out_energy += total[b];
    out_energy += delta * nr;

    double ka = 2.0 * ATMOS_PI / (nm * 1e-9) * sqrt(mean_area / ATMOS_PI);
    for (int i = 0; i < n_angles; i++) {
        double a = i > 0 ? 0.5 * (theta_deg[i - 1] + theta_deg[i]) : theta_deg[0];
        double b = i + 1 < n_angles ? 0.5 * (theta_deg[i] + theta_deg[i + 1]) : theta_deg[i];
        airy_tab[i] = airy_cell(ka, a, b);
    }
    double airy_norm = atmos__sphere_integral(n_angles, theta_deg, airy_tab);
    if (!(airy_norm > 0.0) || !(out_energy > 0.0)) {
        free(hist);
        free(airy_tab);
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s phase at %g nm: no scattered energy (grid too coarse for the diffraction peak?)", what,
                            nm);
    }
    /* Scattering cross-sections in units of <A>: diffraction 1, rays 1 - absorbed. */
    double w_geo = 1.0 - absorbed, w_dif = 1.0;
    double f_delta = delta * nr / out_energy;
    for (int i = 0; i < n_angles; i++) {
        double geo = smoothed_density(total, omega, theta_deg[i], k0) / out_energy;
        double dif = airy_tab[i] / airy_norm;
        phase[i] = (w_geo * (geo + f_delta * dif) + w_dif * dif) / (w_geo + w_dif);
    }
    /* The trapezoid rule on the grid differs slightly from the exact integrals above:
     * normalise on the grid itself, which is what users of the table integrate with. */
    double norm = atmos__sphere_integral(n_angles, theta_deg, phase);
    for (int i = 0; i < n_angles; i++) {
        phase[i] /= norm;
        airy_tab[i] = phase[i] * cos(theta_deg[i] * ATMOS_DEG2RAD);
    }
    double g = atmos__sphere_integral(n_angles, theta_deg, airy_tab);

    if (res) {
        res->sigma_ext_m2 = 2.0 * mean_area;
        res->albedo = (w_geo + w_dif) / 2.0;
        res->g = g;
    }
    if (stats) {
        stats->radius_m = radius;
        stats->length_m = jb.crystal.length;
        stats->mean_projected_area_m2 = mean_area;
        stats->n_real = m.re;
        stats->k_imag = -m.im;
        stats->tilt_rad = tilt;
        stats->rays = rays;
        stats->reflected = reflected;
        stats->transmitted = transmitted;
        stats->absorbed = absorbed;
        stats->lost = lost;
        stats->delta_transmitted = delta;
        stats->kernel_deg = k0;
    }
    atmos__log(ctx, ATMOS_LOG_DEBUG,
               "%s phase at %g nm: R %.3g um, L %.3g um, n %.5f, %ld rays: reflected %.4f, transmitted %.4f "
               "(delta %.4f), absorbed %.2e, lost %.2e; g %.4f",
               what, nm, radius * 1e6, jb.crystal.length * 1e6, m.re, rays, reflected, transmitted, delta, absorbed,
               lost, g);
    free(hist);
    free(airy_tab);
    return ATMOS_OK;
}

atmos_status atmos__crystal_phase(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                  const double *theta_deg, double *phase, atmos__phase_result *res,
                                  atmos__phase_progress progress, void *progress_user)
{
    return atmos__crystal_phase_ex(ctx, p, nm, n_angles, theta_deg, phase, res, progress, progress_user, NULL);
}
