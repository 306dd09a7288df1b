/* Phase functions of ice and snow crystals: Monte Carlo geometric optics (the tracer in
 * crystal_geometry.c) plus Fraunhofer diffraction, binned onto the phase-table grid.
 *
 * Physics (docs/optics-crystals.md has the full account):
 *  - extinction paradox: sigma_ext = 2 <A>, <A> the orientation-mean projected area,
 *    which for a convex body is a quarter of its surface area (Cauchy's theorem); half
 *    of it is scattered by reflection and refraction (the rays), half by diffraction
 *    (van de Hulst 1957, §8.22; Takano & Liou 1989 J. Atmos. Sci. 46, 3).
 *  - diffraction: each orientation diffracts like a circular aperture of its own
 *    projected area (Airy pattern), mixed with weights equal to that area (see
 *    diffraction() below): an approximation to the average over the hexagonal shadows
 *    that differs mainly in the ring structure.
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
#include <omp.h>
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
    double *hist; /* 2 NBINS: energies by scattering angle (delta transmission excluded),
                     then the sums of their squares (for the effective sample size) */
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
    memset(cr->hist, 0, sizeof(double) * 2 * NBINS);
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
            cr->hist[NBINS + b] += ray.weight[e] * ray.weight[e];
        }
    }
}

/* The histogram after tracing: energies e[b], squared energies e2[b], their prefix
 * sums, and the solid angle of each bin. */
typedef struct binned {
    const double *e, *omega;
    const double *c1, *c2; /* c1[b] = sum of e[0..b), c2 likewise for e2; NBINS + 1 entries */
    double k0;             /* kernel width away from the poles, degrees */
} binned;

/* Kernel standard deviation at theta (degrees): k0, widened linearly towards the poles
 * (the solid angle per degree vanishes there), and widened wherever the histogram
 * holds fewer than MIN_EFFECTIVE_RAYS effective rays (Kish: (sum w)^2 / sum w^2) per
 * kernel, up to MAX_KERNEL_DEG: a balloon-type adaptive kernel (Terrell & Scott 1992,
 * Ann. Stat. 20, 1236) that keeps the noise near MIN_EFFECTIVE_RAYS^-1/2 where the
 * phase function is low (the back hemisphere) while the bright halos keep k0. */
#define MIN_EFFECTIVE_RAYS 400.0
#define MAX_KERNEL_DEG 3.0
#define WINDOW_BINS ((int)(1.0 / BIN_DEG + 0.5)) /* +-1° window for the local ray count */

static double kernel_at(const binned *h, double theta)
{
    double psi = fmin(theta, 180.0 - theta);
    double sd = h->k0;
    if (psi < POLE_DEG) sd = h->k0 + (POLE_KERNEL_DEG - h->k0) * (1.0 - psi / POLE_DEG);
    int b = (int)(theta / BIN_DEG);
    int lo = b - WINDOW_BINS, hi = b + WINDOW_BINS + 1;
    if (lo < 0) lo = 0;
    if (hi > NBINS) hi = NBINS;
    double s1 = h->c1[hi] - h->c1[lo], s2 = h->c2[hi] - h->c2[lo];
    double n_eff = s2 > 0.0 ? s1 * s1 / s2 : 0.0;
    /* A Gaussian of width sd holds about 2.5 sd / 2° of the window's rays. */
    double need = n_eff > 0.0 ? MIN_EFFECTIVE_RAYS * 2.0 / (2.5 * n_eff) : MAX_KERNEL_DEG;
    if (need > MAX_KERNEL_DEG) need = MAX_KERNEL_DEG;
    return sd > need ? sd : need;
}

/* Energy per steradian at theta from the histogram: the kernel-weighted energy over the
 * kernel-weighted solid angle of the bins (a ratio estimator, which stays unbiased for
 * a constant density even where the kernel is cut by 0° or 180°). */
static double smoothed_density(const binned *h, double theta)
{
    double sd = kernel_at(h, theta);
    int lo = (int)floor((theta - 4.0 * sd) / BIN_DEG), hi = (int)ceil((theta + 4.0 * sd) / BIN_DEG);
    if (lo < 0) lo = 0;
    if (hi > NBINS - 1) hi = NBINS - 1;
    /* Gaussian weights at equally spaced bins by the exact recurrence
     * g(x + d) = g(x) exp(-(2 x d + d^2) / 2), whose ratio shrinks by exp(-d^2) per
     * step: three exp() per angle instead of one per bin. */
    double x0 = ((lo + 0.5) * BIN_DEG - theta) / sd, d = BIN_DEG / sd;
    double k = exp(-0.5 * x0 * x0), ratio = exp(-(2.0 * x0 * d + d * d) / 2.0), q = exp(-d * d);
    double num = 0.0, den = 0.0;
    for (int b = lo; b <= hi; b++) {
        num += k * h->e[b];
        den += k * h->omega[b];
        k *= ratio;
        ratio *= q;
    }
    return den > 0.0 ? num / den : 0.0;
}

/* Airy pattern [2 J1(x) / x]^2 (Born & Wolf §8.5.2), x = k a sin(theta), averaged over
 * the grid cell [th0, th1] so that rings finer than the grid are replaced by their mean
 * instead of being aliased; beyond x = 100 by the ring average 4 / (pi x^3) of the
 * asymptotic form (J1(x)^2 ~ 2 cos^2(...) / (pi x)). Zero beyond 90°, where Fraunhofer's
 * small-angle diffraction does not apply (the pattern is ~(ka)^-3 there anyway). */
static double airy(double x) { return fabs(x) < 1e-8 ? 1.0 : pow(2.0 * j1(x) / x, 2.0); }

static double airy_cell(double ka, double th0, double th1)
{
    if (th0 >= 90.0) return 0.0;
    if (th1 > 90.0) th1 = 90.0;
    double x0 = ka * sin(th0 * ATMOS_DEG2RAD), x1 = ka * sin(th1 * ATMOS_DEG2RAD);
    if (x0 > 100.0) {
        double x = 0.5 * (x0 + x1);
        return 4.0 / (ATMOS_PI * x * x * x);
    }
    int m = (int)ceil(fabs(x1 - x0) / 0.25);
    if (m < 1) return airy(0.5 * (x0 + x1));
    if (m > 512) m = 512;
    double s = 0.0;
    for (int i = 0; i < m; i++) s += airy(x0 + (i + 0.5) * (x1 - x0) / m);
    return s / m;
}

/* Diffraction by the randomly oriented prism. Each orientation diffracts the light
 * falling on its shadow, area A(d), like a circular aperture of the same area; the
 * phase function is the mixture of these Airy patterns weighted by A(d) (the energy
 * each orientation intercepts). A(d) is tabulated on a Fibonacci lattice of directions
 * and split into DIFF_SIZES strata of equal intercepted energy, one Airy pattern each.
 * The spread of A(d) (a factor ~2-4) washes out the rings beyond the first few, as
 * the hexagonal shape would; the first dark ring of a single circle survives only
 * softened. Output: per-steradian values (unnormalised) at the grid angles. */
#define DIFF_DIRS 4096
#define DIFF_SIZES 24

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void diffraction(const atmos__crystal *c, double k, int n, const double *theta_deg, double *out)
{
    static const double golden = 2.39996322972865332; /* pi (3 - sqrt 5) */
    double areas[DIFF_DIRS], total = 0.0;
    for (int i = 0; i < DIFF_DIRS; i++) {
        double z = 1.0 - (2.0 * i + 1.0) / DIFF_DIRS, r = sqrt(fmax(0.0, 1.0 - z * z));
        double d[3] = {r * cos(golden * i), r * sin(golden * i), z};
        areas[i] = atmos__crystal_projected_area(c, d);
    }
    qsort(areas, DIFF_DIRS, sizeof *areas, cmp_double);
    for (int i = 0; i < DIFF_DIRS; i++) total += areas[i];
    double ka[DIFF_SIZES];
    /* Stratum s holds the directions whose cumulative area falls in [s, s+1) / DIFF_SIZES
     * of the total; its representative area is its area-weighted mean A2 / A. */
    double cum = 0.0, sa = 0.0, sa2 = 0.0;
    int s = 0;
    for (int i = 0; i < DIFF_DIRS && s < DIFF_SIZES; i++) {
        sa += areas[i];
        sa2 += areas[i] * areas[i];
        cum += areas[i];
        if (cum >= total * (s + 1) / DIFF_SIZES || i == DIFF_DIRS - 1) {
            ka[s++] = k * sqrt(sa2 / sa / ATMOS_PI);
            sa = sa2 = 0.0;
        }
    }
    for (int j = s; j < DIFF_SIZES; j++) ka[j] = ka[s - 1];
    for (int i = 0; i < n; i++) {
        double a = i > 0 ? 0.5 * (theta_deg[i - 1] + theta_deg[i]) : theta_deg[0];
        double b = i + 1 < n ? 0.5 * (theta_deg[i] + theta_deg[i + 1]) : theta_deg[i];
        double v = 0.0;
        /* (ka)^2 / (4 pi): the Airy pattern normalised over the sphere (small angles). */
        for (int j = 0; j < DIFF_SIZES; j++) v += ka[j] * ka[j] / (4.0 * ATMOS_PI) * airy_cell(ka[j], a, b);
        out[i] = v / DIFF_SIZES;
    }
}

static uint64_t hash_double(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return atmos__splitmix64(&u);
}

/* ------------------------------------------------------------ the phase function */

/* Rejects settings and grids the computation cannot use. */
static atmos_status check_args(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                               const double *theta_deg, const double *phase)
{
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
    return ATMOS_OK;
}

/* The crystal, its optics and the ray budget, resolved from the particle's settings
 * and defaults; st gets the resolved parameters (radius, length, index, tilt, rays,
 * kernel). */
static atmos_status setup_job(atmos_context *ctx, const atmos_particle_desc *p, double nm, const char *what, job *jb,
                              atmos__crystal_stats *st)
{
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

    atmos_complex m = atmos_refractive_index_ice(nm);
    if (!(m.re > 1.0 && m.re < 3.0 && m.im <= 0.0 && isfinite(m.im)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "%s phase: refractive index %g%+gi at %g nm unusable", what, m.re,
                            m.im, nm);

    atmos__crystal_init(&jb->crystal, radius, 2.0 * radius * aspect);
    jb->optics.n = m.re;
    jb->optics.alpha = 4.0 * ATMOS_PI * -m.im / (nm * 1e-9);
    jb->optics.tilt = tilt;
    jb->optics.max_hits = MAX_HITS;
    jb->optics.cutoff = ENERGY_CUTOFF;
    jb->seed = hash_double(nm) ^ ((uint64_t)p->kind << 56);
    jb->rays = rays;

    memset(st, 0, sizeof *st);
    st->radius_m = radius;
    st->length_m = jb->crystal.length;
    st->mean_projected_area_m2 = 0.25 * jb->crystal.surface_area; /* Cauchy */
    st->n_real = m.re;
    st->k_imag = -m.im;
    st->tilt_rad = tilt;
    st->rays = rays;
    st->kernel_deg = snow ? KERNEL_DEG_SNOW : p->fast ? KERNEL_DEG_ICE_FAST : KERNEL_DEG_ICE;
    return ATMOS_OK;
}

/* Traces the chunks in parallel into cr[]. Chunks are handed out dynamically (no
 * barrier per batch, so a thread slowed by other processes does not hold the others
 * up) and merged in chunk order afterwards. Returns nonzero if progress cancelled. */
static int trace_chunks(atmos_context *ctx, const job *jb, chunk_result *cr, atmos__phase_progress progress,
                        void *progress_user)
{
    int threads = atmos__threads(ctx);
    if (threads < 1) threads = 1;
    if (threads > CHUNKS) threads = CHUNKS;
    int done = 0, cancel = 0;
#pragma omp parallel num_threads(threads)
    {
#pragma omp for schedule(dynamic, 1)
        for (int c = 0; c < CHUNKS; c++) {
            int stop;
#pragma omp atomic read
            stop = cancel;
            if (stop) continue;
            run_chunk(jb, c, &cr[c]);
            int now;
#pragma omp atomic capture
            now = ++done;
            /* Thread 0 of the team is the calling thread: only it reports. */
            if (progress && omp_get_thread_num() == 0 && now < CHUNKS && progress(progress_user, (double)now / CHUNKS)) {
#pragma omp atomic write
                cancel = 1;
            }
        }
    }
    return cancel || (progress && progress(progress_user, 1.0));
}

/* Adds the chunks' histograms into total (2 NBINS) and their energies, per ray, into
 * st, in chunk order whatever thread ran what: bit-identical for any thread count. */
static void merge_chunks(const chunk_result *cr, double *total, atmos__crystal_stats *st)
{
    double reflected = 0.0, transmitted = 0.0, absorbed = 0.0, lost = 0.0, delta = 0.0;
    for (int c = 0; c < CHUNKS; c++) {
        for (int bn = 0; bn < 2 * NBINS; bn++) total[bn] += cr[c].hist[bn];
        reflected += cr[c].reflected;
        transmitted += cr[c].transmitted;
        absorbed += cr[c].absorbed;
        lost += cr[c].lost;
        delta += cr[c].delta;
    }
    double nr = (double)st->rays;
    st->reflected = reflected / nr;
    st->transmitted = transmitted / nr;
    st->absorbed = absorbed / nr;
    st->lost = lost / nr;
    st->delta_transmitted = delta / nr;
}

/* Work memory: total (2 NBINS), omega (NBINS), prefix sums (2 (NBINS + 1)), one
 * histogram (2 NBINS) per chunk (~9 MB), and one value per grid angle. */
typedef struct work {
    double *mem, *airy;
    double *total, *omega, *c1, *c2;
    chunk_result cr[CHUNKS];
} work;

static int work_alloc(work *w, int n_angles)
{
    w->mem = calloc((size_t)NBINS * (size_t)(2 * CHUNKS + 5) + 2, sizeof(double));
    w->airy = malloc(sizeof(double) * (size_t)n_angles);
    if (!w->mem || !w->airy) return -1;
    w->total = w->mem;
    w->omega = w->mem + 2 * (size_t)NBINS;
    w->c1 = w->mem + 3 * (size_t)NBINS;
    w->c2 = w->c1 + NBINS + 1;
    double *slots = w->c2 + NBINS + 1;
    for (int c = 0; c < CHUNKS; c++) w->cr[c].hist = slots + (size_t)c * 2 * NBINS;
    return 0;
}

static void work_free(work *w)
{
    free(w->mem);
    free(w->airy);
}

/* The phase function on the grid from the merged histogram and the diffraction
 * pattern, normalised on the grid; *g its asymmetry parameter. */
static atmos_status assemble_phase(atmos_context *ctx, const job *jb, const atmos__crystal_stats *st, double nm,
                                   const char *what, int n_angles, const double *theta_deg, double *phase, work *w,
                                   double *g)
{
    double *total = w->total, *omega = w->omega, *c1 = w->c1, *c2 = w->c2, *airy_tab = w->airy;
    for (int b = 0; b < NBINS; b++) {
        c1[b + 1] = c1[b] + total[b];
        c2[b + 1] = c2[b] + total[NBINS + b];
    }
    binned h = {total, omega, c1, c2, st->kernel_deg};
    for (int b = 0; b < NBINS; b++)
        omega[b] = 2.0 * ATMOS_PI * (cos(b * BIN_DEG * ATMOS_DEG2RAD) - cos((b + 1) * BIN_DEG * ATMOS_DEG2RAD));
    /* Energy that left the crystal through the rays; the lost part (still inside after
     * MAX_HITS interactions, typically < 1e-3) is given the same angular distribution
     * as the rest by normalising with what left. */
    const double nr = (double)st->rays;
    double out_energy = 0.0;
    for (int b = 0; b < NBINS; b++) out_energy += total[b];
    out_energy += st->delta_transmitted * nr;

    diffraction(&jb->crystal, 2.0 * ATMOS_PI / (nm * 1e-9), n_angles, theta_deg, airy_tab);
    double airy_norm = atmos__sphere_integral(n_angles, theta_deg, airy_tab);
    if (!(airy_norm > 0.0) || !(out_energy > 0.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "%s phase at %g nm: no scattered energy (grid too coarse for the diffraction peak?)", what,
                            nm);
    /* Scattering cross-sections in units of <A>: diffraction 1, rays 1 - absorbed. */
    double w_geo = 1.0 - st->absorbed, w_dif = 1.0;
    double f_delta = st->delta_transmitted * nr / out_energy;
    for (int i = 0; i < n_angles; i++) {
        double geo = smoothed_density(&h, theta_deg[i]) / out_energy;
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
    *g = atmos__sphere_integral(n_angles, theta_deg, airy_tab);
    return ATMOS_OK;
}

atmos_status atmos__crystal_phase_ex(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                     const double *theta_deg, double *phase, atmos__phase_result *res,
                                     atmos__phase_progress progress, void *progress_user,
                                     atmos__crystal_stats *stats)
{
    atmos_status s = check_args(ctx, p, nm, n_angles, theta_deg, phase);
    if (s != ATMOS_OK) return s;
    const char *what = p->kind == ATMOS_PARTICLE_ICE ? "ice" : "snow";
    job jb;
    atmos__crystal_stats st;
    if ((s = setup_job(ctx, p, nm, what, &jb, &st)) != ATMOS_OK) return s;
    work w;
    if (work_alloc(&w, n_angles) != 0) {
        work_free(&w);
        return atmos__error(ctx, ATMOS_E_NOMEM, "%s phase: out of memory for histograms", what);
    }
    double g = 0.0;
    if (trace_chunks(ctx, &jb, w.cr, progress, progress_user)) {
        s = atmos__error(ctx, ATMOS_E_CANCELLED, "%s phase at %g nm: cancelled", what, nm);
    } else {
        merge_chunks(w.cr, w.total, &st);
        s = assemble_phase(ctx, &jb, &st, nm, what, n_angles, theta_deg, phase, &w, &g);
    }
    work_free(&w);
    if (s != ATMOS_OK) return s;
    if (res) {
        /* Scattering cross-sections in units of <A>: diffraction 1, rays 1 - absorbed,
         * of the extinction 2 <A>. */
        const double w_geo = 1.0 - st.absorbed, w_dif = 1.0;
        res->sigma_ext_m2 = 2.0 * st.mean_projected_area_m2;
        res->albedo = (w_geo + w_dif) / 2.0;
        res->g = g;
    }
    if (stats) *stats = st;
    atmos__log(ctx, ATMOS_LOG_DEBUG,
               "%s phase at %g nm: R %.3g um, L %.3g um, n %.5f, %ld rays: reflected %.4f, transmitted %.4f "
               "(delta %.4f), absorbed %.2e, lost %.2e; g %.4f",
               what, nm, st.radius_m * 1e6, st.length_m * 1e6, st.n_real, st.rays, st.reflected, st.transmitted,
               st.delta_transmitted, st.absorbed, st.lost, g);
    return ATMOS_OK;
}

atmos_status atmos__crystal_phase(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                  const double *theta_deg, double *phase, atmos__phase_result *res,
                                  atmos__phase_progress progress, void *progress_user)
{
    return atmos__crystal_phase_ex(ctx, p, nm, n_angles, theta_deg, phase, res, progress, progress_user, NULL);
}
