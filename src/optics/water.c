/* Phase function of a polydisperse ensemble of water spheres at one wavelength.
 *
 * Size averaging. The single-size phase function of a large drop is full of
 * interference fringes (period ~ pi/x in angle, ~ 1-3 in x at a fixed angle: the
 * "ripple" between reflected and refracted rays, whose coarse period in x is
 * ~ pi/(n-1) ~ 10 and whose finer structure is ~ 1) and narrow resonances. A real
 * cloud or rain shower averages them away; so must the table. We integrate over the
 * cross-section-weighted size distribution
 *     a(r) = n(r) r^2 / <r^2>                                (pdf of r)
 * because every quantity we need is linear in n(r) pi r^2 Q:
 *     sigma_ext = pi <r^2> E_a[Q_ext],  sigma_sca = pi <r^2> E_a[Q_sca],
 *     dsigma_sca/dOmega = <r^2> E_a[(|S1|^2 + |S2|^2) / (2 x^2)],
 * (BH Eq. 3.16 and 4.61, with k r = x), <r^2> being the number-weighted mean computed
 * by quadrature of n(r). Sizes are drawn by stratified sampling of a(r): N strata of
 * equal cross-section weight, one size per stratum at a deterministic jittered
 * quantile (golden-ratio sequence), so each size carries weight 1/N and the
 * large drops that dominate the scattering get the samples. Jitter turns what would be
 * coherent aliasing of the x-ripple into noise that falls as 1/sqrt(N) and as the
 * strata shrink below the ripple period.
 *
 * N is set by the size spread in x (strata at most DX_TARGET wide in x) and capped by a
 * cost budget (the Mie cost is ~ x * number of distinct |cos theta|): clouds (x < 500)
 * get ripple-resolving strata; rain (x ~ 1e4 .. 4e4) gets as many sizes as the budget
 * allows, and the residual fringe noise is then removed by averaging each single-size
 * intensity over its grid cell in angle (see cell_average): a table value stands for the
 * cell around its angle, and a drop's fringes finer than the cell carry no information
 * the grid could hold. Accuracies of the two qualities are in docs/optics.md.
 *
 * Threads: sizes are computed in batches by OpenMP threads into per-size slots and
 * summed by the calling thread in size order, so the result does not depend on the
 * thread count. Progress is reported between batches from the calling thread.
 */
#include "core/internal.h"
#include "optics/optics_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* Widest stratum in x in normal quality: well below the ripple period (~1-3). */
#define DX_TARGET 0.25
/* Cost budget per wavelength, in Mie (series term x distinct angle) units; one unit is
 * ~3.7 ns on one core of a 2020s x86 machine, so normal quality is ~30 core-seconds
 * per wavelength at most and fast quality 1/16 of it. */
#define BUDGET_NORMAL 8.0e9
#define BUDGET_FAST (BUDGET_NORMAL / 16.0)
#define MIN_SIZES_NORMAL 32
#define MIN_SIZES_FAST 12
#define MAX_SIZES 20000
/* Tail weight left out at each end of the size range when r_min / r_max are automatic. */
#define TAIL 0.5e-6
#define TABLE_N 8193
#define BATCH 32

/* log of the number density per unit ln r, up to a constant: n(r) r. */
static double log_density_lnr(const atmos_size_distribution *s, double lnr)
{
    switch (s->kind) {
    case ATMOS_SIZE_LOGNORMAL: {
        double d = (lnr - log(s->r_m)) / s->sigma;
        return -0.5 * d * d; /* n(r) ~ exp(-d^2/2) / r, so n(r) r is the Gaussian */
    }
    case ATMOS_SIZE_GAMMA: {
        /* n(r) ~ r^alpha exp(-b r^gamma), b = alpha / (gamma r_m^gamma) (Deirmendjian 1969) */
        double rr = exp(lnr - log(s->r_m)); /* r / r_m */
        return (s->alpha + 1.0) * (lnr - log(s->r_m)) - s->alpha / s->gamma * pow(rr, s->gamma);
    }
    default:
        return 0.0;
    }
}

static atmos_status check_distribution(atmos_context *ctx, const atmos_size_distribution *s)
{
    if (!(s->r_m > 0.0 && s->r_m < 1.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "water particle: size.r_m must be in (0, 1) m, got %g", s->r_m);
    if (s->kind == ATMOS_SIZE_LOGNORMAL && !(s->sigma > 0.0 && s->sigma <= 2.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "water particle: lognormal size.sigma must be in (0, 2], got %g",
                            s->sigma);
    if (s->kind == ATMOS_SIZE_GAMMA && !(s->alpha > 0.0 && s->alpha <= 1000.0 && s->gamma > 0.0 && s->gamma <= 100.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "water particle: gamma size.alpha must be in (0, 1000] and size.gamma in (0, 100], got "
                            "alpha %g, gamma %g",
                            s->alpha, s->gamma);
    if (s->kind != ATMOS_SIZE_MONODISPERSE && s->kind != ATMOS_SIZE_LOGNORMAL && s->kind != ATMOS_SIZE_GAMMA)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "water particle: unknown size distribution kind %d", (int)s->kind);
    if (!(s->r_min >= 0.0) || !(s->r_max >= 0.0) || (s->r_max > 0.0 && s->r_min >= s->r_max))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "water particle: size.r_min, r_max must be >= 0 with r_min < r_max, got %g, %g", s->r_min,
                            s->r_max);
    return ATMOS_OK;
}

/* A tabulated distribution on a ln r grid: cdf of the cross-section-weighted pdf a(r)
 * and the number-weighted <r^2>. */
typedef struct {
    double lo, hi;            /* ln r range of the table */
    double cdf[TABLE_N];      /* of a(r), normalised to 1 at hi */
    double mean_r2;           /* number-weighted <r^2>, m^2 */
} size_table;

static void build_table(const atmos_size_distribution *s, size_table *t)
{
    double c = log(s->r_m);
    /* the densities are negligible (< e^-40 of their peak) outside this window */
    double lo = c - 12.0, hi = c + 12.0;
    if (s->kind == ATMOS_SIZE_LOGNORMAL) lo = c - 9.0 * s->sigma, hi = c + 2.0 * s->sigma * s->sigma + 9.0 * s->sigma;
    if (s->r_min > 0.0) lo = fmax(lo, log(s->r_min));
    if (s->r_max > 0.0) hi = fmin(hi, log(s->r_max));
    if (hi <= lo) hi = lo + 1e-9;
    const double h = (hi - lo) / (TABLE_N - 1);
    /* peak of the log-densities to avoid overflow */
    double pk_a = -INFINITY, pk_n = -INFINITY;
    for (int i = 0; i < TABLE_N; i++) {
        double u = lo + i * h, ln = log_density_lnr(s, u);
        pk_n = fmax(pk_n, ln);
        pk_a = fmax(pk_a, ln + 2.0 * (u - c));
    }
    double sa = 0.0, sn = 0.0, sn2 = 0.0, prev_a = 0.0, prev_n = 0.0, prev_n2 = 0.0;
    for (int i = 0; i < TABLE_N; i++) {
        double u = lo + i * h, ln = log_density_lnr(s, u);
        double fa = exp(ln + 2.0 * (u - c) - pk_a), fn = exp(ln - pk_n), fn2 = fn * exp(2.0 * (u - c));
        if (i > 0) {
            sa += 0.5 * h * (fa + prev_a);
            sn += 0.5 * h * (fn + prev_n);
            sn2 += 0.5 * h * (fn2 + prev_n2);
        }
        t->cdf[i] = sa;
        prev_a = fa, prev_n = fn, prev_n2 = fn2;
    }
    for (int i = 0; i < TABLE_N; i++) t->cdf[i] /= sa;
    t->lo = lo, t->hi = hi;
    t->mean_r2 = s->r_m * s->r_m * sn2 / sn;
}

/* ln r at cross-section quantile q (linear interpolation of the tabulated cdf). */
static double table_quantile(const size_table *t, double q)
{
    int a = 0, b = TABLE_N - 1;
    while (b - a > 1) {
        int mid = (a + b) / 2;
        if (t->cdf[mid] < q) a = mid;
        else b = mid;
    }
    double h = (t->hi - t->lo) / (TABLE_N - 1);
    double d = t->cdf[b] - t->cdf[a], f = d > 0 ? (q - t->cdf[a]) / d : 0.5;
    return t->lo + (a + f) * h;
}

/* Averages |S1|^2 + |S2|^2 over the grid cell of each angle [mid(i-1, i), mid(i, i+1)],
 * weighting by sin theta, from ns sub-samples per cell; the sub-sample values are
 * v[i * ns + j]. */
static void cell_average(int n, int ns, const double *sub_sin, const double *v, double *out)
{
    for (int i = 0; i < n; i++) {
        double s = 0.0, w = 0.0;
        for (int j = 0; j < ns; j++) {
            s += v[i * ns + j] * sub_sin[i * ns + j];
            w += sub_sin[i * ns + j];
        }
        out[i] = w > 0.0 ? s / w : v[i * ns + ns / 2];
    }
}

/* The angles at which each cell is sampled: ns points evenly inside the cell (the grid
 * angle itself when ns = 1). Cells at 0 and 180 degrees are one-sided. */
static void cell_samples(int n, const double *deg, int ns, double *mu, double *sw)
{
    for (int i = 0; i < n; i++) {
        double a = i > 0 ? 0.5 * (deg[i - 1] + deg[i]) : deg[i];
        double b = i + 1 < n ? 0.5 * (deg[i] + deg[i + 1]) : deg[i];
        for (int j = 0; j < ns; j++) {
            double t = ns == 1 ? deg[i] : a + (b - a) * (j + 0.5) / ns;
            double th = t * ATMOS_DEG2RAD;
            mu[i * ns + j] = t <= 0.0 ? 1.0 : t >= 180.0 ? -1.0 : cos(th);
            /* sin weight, but never zero: the end cells average their one-sided half */
            sw[i * ns + j] = ns == 1 ? 1.0 : fmax(sin(th), 1e-12);
        }
    }
}

static atmos_status check_args(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                               const double *theta_deg, const double *phase, const atmos__phase_result *res)
{
    if (!p || !theta_deg || !phase || !res || n_angles < 2)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "water phase: missing argument or fewer than 2 angles (%d)",
                            n_angles);
    if (!(nm >= 100.0 && nm <= 100000.0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "water phase: wavelength must be in [100, 1e5] nm, got %g", nm);
    for (int i = 0; i < n_angles; i++)
        if (!(theta_deg[i] >= 0.0 && theta_deg[i] <= 180.0) || (i > 0 && !(theta_deg[i] > theta_deg[i - 1])))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                                "water phase: angles must increase within [0, 180] degrees; theta[%d] = %g", i,
                                theta_deg[i]);
    return check_distribution(ctx, &p->size);
}

/* How one wavelength samples the drop sizes and the angles. */
typedef struct {
    atmos_complex m;   /* refractive index */
    double k;          /* wavenumber, 1/m */
    int mono;          /* one size: p->size.r_m */
    size_table *tab;   /* the distribution (NULL when mono) */
    double q_lo, q_hi; /* range of cross-section quantiles sampled */
    double mean_r2;    /* number-weighted <r^2>, m^2 */
    int ns;            /* sub-samples per angle cell */
    int n_sizes;       /* sizes, one per stratum */
} size_plan;

/* Sub-samples per cell: two per fringe period (2 pi / x) of the median drop in the
 * widest cell, at most 2 in normal quality (cost) and 1 in fast quality. Number of
 * sizes: strata DX_TARGET wide in x, within the cost budget. */
static void plan_counts(const atmos_particle_desc *p, int n_angles, const double *theta_deg, double r_lo, double r_hi,
                        size_plan *sp)
{
    const double k = sp->k;
    double max_cell = 0.0;
    for (int i = 0; i + 1 < n_angles; i++) max_cell = fmax(max_cell, theta_deg[i + 1] - theta_deg[i]);
    /* typical sampled size: the median of the cross-section weight */
    double x_mean = sp->mono ? k * p->size.r_m : k * exp(table_quantile(sp->tab, 0.5));
    int ns = (int)ceil(max_cell * ATMOS_DEG2RAD * x_mean / ATMOS_PI);
    if (ns < 1) ns = 1;
    if (ns > (p->fast ? 1 : 2)) ns = p->fast ? 1 : 2;
    if (sp->mono) ns = 1;
    int n_sizes = 1;
    if (!sp->mono) {
        double span = k * (r_hi - r_lo);
        double want = ceil(span / (p->fast ? 8.0 * DX_TARGET : DX_TARGET));
        /* theta and 180 - theta share one evaluation only without cell sub-samples */
        double cost_each = (x_mean + 4.0 * cbrt(x_mean) + 2.0) * (ns == 1 ? 0.5 * n_angles + 1.0 : (double)n_angles * ns);
        double afford = (p->fast ? BUDGET_FAST : BUDGET_NORMAL) / cost_each;
        double nmin = p->fast ? MIN_SIZES_FAST : MIN_SIZES_NORMAL;
        n_sizes = (int)fmin(fmax(fmin(want, afford), nmin), MAX_SIZES);
    }
    sp->ns = ns;
    sp->n_sizes = n_sizes;
}

/* The size range (refused beyond the Mie limit) and the sample counts. sp->tab is
 * allocated here and freed by the caller whatever this returns. */
static atmos_status plan_sizes(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                               const double *theta_deg, size_plan *sp)
{
    sp->m = atmos_refractive_index_water(nm);
    sp->k = 2.0 * ATMOS_PI / (nm * 1e-9);
    sp->mono = p->size.kind == ATMOS_SIZE_MONODISPERSE;
    sp->tab = sp->mono ? NULL : malloc(sizeof *sp->tab);
    if (!sp->mono && !sp->tab) return atmos__error(ctx, ATMOS_E_NOMEM, "water phase: out of memory");
    const double k = sp->k;
    sp->q_lo = 0.0, sp->q_hi = 1.0, sp->mean_r2 = p->size.r_m * p->size.r_m;
    if (!sp->mono) {
        build_table(&p->size, sp->tab);
        sp->mean_r2 = sp->tab->mean_r2;
        if (p->size.r_min <= 0.0) sp->q_lo = TAIL;
        if (p->size.r_max <= 0.0) sp->q_hi = 1.0 - TAIL;
    }
    double r_lo = sp->mono ? p->size.r_m : exp(table_quantile(sp->tab, sp->q_lo));
    double r_hi = sp->mono ? p->size.r_m : exp(table_quantile(sp->tab, sp->q_hi));
    if (k * r_hi > 1e5)
        return atmos__error(ctx, ATMOS_E_LIMIT,
                            "water phase: drops up to r = %g m at %g nm need size parameter %g > 1e5 (Mie limit); "
                            "set size.r_max_m (scene files) / size.r_max",
                            r_hi, nm, k * r_hi);
    plan_counts(p, n_angles, theta_deg, r_lo, r_hi, sp);
    atmos__log(ctx, ATMOS_LOG_DEBUG,
               "water phase %g nm: m = %.6f%+.3gi, r %.4g..%.4g m (x %.1f..%.1f), %d sizes, %d sub-angles per cell",
               nm, sp->m.re, sp->m.im, r_lo, r_hi, k * r_lo, k * r_hi, sp->n_sizes, sp->ns);
    return ATMOS_OK;
}

/* Radius of size i: stratum i of the cross-section weight, jittered by the
 * golden-ratio sequence. */
static double size_radius(const atmos_particle_desc *p, const size_plan *sp, int i)
{
    const double golden = 0.6180339887498949;
    if (sp->mono) return p->size.r_m;
    double jit = fmod(0.5 + golden * (i + 1), 1.0);
    double q = sp->q_lo + (sp->q_hi - sp->q_lo) * (i + jit) / sp->n_sizes;
    return exp(table_quantile(sp->tab, q));
}

/* Buffers: the sub-sample angles and weights, per-size slots of one batch, the sums. */
typedef struct {
    int n_angles, nsub, batch;
    double *mu, *sw;   /* cos theta and sin weight of each sub-sample (nsub) */
    double *slot;      /* per size: cell-averaged |S|^2/(2x^2) (batch x n_angles) */
    double *slot_q;    /* per size: Q_ext, Q_sca, g Q_sca (batch x 3) */
    double *acc;       /* sum over sizes of the slots (n_angles) */
    double qext_sum, qsca_sum, gq_sum;
} water_work;

static int work_alloc(water_work *w, int n_angles, const size_plan *sp)
{
    memset(w, 0, sizeof *w);
    w->n_angles = n_angles;
    w->nsub = n_angles * sp->ns;
    w->batch = sp->n_sizes < BATCH ? sp->n_sizes : BATCH;
    w->mu = malloc((size_t)w->nsub * sizeof *w->mu);
    w->sw = malloc((size_t)w->nsub * sizeof *w->sw);
    w->slot = malloc((size_t)w->batch * n_angles * sizeof *w->slot);
    w->slot_q = malloc((size_t)w->batch * 3 * sizeof *w->slot_q);
    w->acc = calloc((size_t)n_angles, sizeof *w->acc);
    return w->mu && w->sw && w->slot && w->slot_q && w->acc ? 0 : -1;
}

static void work_free(water_work *w)
{
    free(w->mu), free(w->sw), free(w->slot), free(w->slot_q), free(w->acc);
}

/* Progress within a batch: a large drop's batch (rain: 32 sizes, one batch a wavelength) takes
 * tens of seconds, so the calling thread (thread 0) reports after each size it sees done. */
typedef struct {
    atmos__phase_progress fn;
    void *user;
    int done, cancel;
} batch_progress;

/* Sizes b0 .. b0 + nb - 1 by Mie theory, in parallel, each into its slot. Returns
 * the worst status of any size (ATMOS_E_CANCELLED when pr's callback asked to stop). */
static atmos_status mie_batch(atmos_context *ctx, const atmos_particle_desc *p, const size_plan *sp, int b0, int nb,
                              water_work *w, batch_progress *pr)
{
    const int nsub = w->nsub, n_angles = w->n_angles;
    int bst = ATMOS_OK;
    pr->done = 0;
#pragma omp parallel num_threads(atmos__threads(ctx)) reduction(max : bst)
    {
        bst = ATMOS_OK; /* the private copy of a max reduction starts at INT_MIN */
        atmos_complex *s1 = malloc((size_t)nsub * sizeof *s1), *s2 = malloc((size_t)nsub * sizeof *s2);
        double *v = malloc((size_t)nsub * sizeof *v);
        if (!s1 || !s2 || !v) bst = ATMOS_E_NOMEM;
#pragma omp for schedule(dynamic, 1)
        for (int j = 0; j < nb; j++) {
            int stop;
#pragma omp atomic read
            stop = pr->cancel;
            if (bst != ATMOS_OK || stop) continue;
            double x = sp->k * size_radius(p, sp, b0 + j);
            atmos_mie_result mr;
            atmos_status s = atmos_mie(NULL, sp->m, x, nsub, w->mu, s1, s2, &mr);
            if (s != ATMOS_OK) {
                bst = s;
                continue;
            }
            double f = 1.0 / (2.0 * x * x);
            for (int a = 0; a < nsub; a++)
                v[a] = f * (s1[a].re * s1[a].re + s1[a].im * s1[a].im + s2[a].re * s2[a].re + s2[a].im * s2[a].im);
            cell_average(n_angles, sp->ns, w->sw, v, w->slot + (size_t)j * n_angles);
            w->slot_q[3 * j] = mr.qext;
            w->slot_q[3 * j + 1] = mr.qsca;
            w->slot_q[3 * j + 2] = mr.g * mr.qsca;
            int now;
#pragma omp atomic capture
            now = ++pr->done;
            if (pr->fn && omp_get_thread_num() == 0 && now < nb &&
                pr->fn(pr->user, (double)(b0 + now) / sp->n_sizes)) {
#pragma omp atomic write
                pr->cancel = 1;
            }
        }
        free(s1), free(s2), free(v);
    }
    return pr->cancel && bst == ATMOS_OK ? ATMOS_E_CANCELLED : (atmos_status)bst;
}

/* Adds a batch's slots to the sums: sizes in index order, independent of threads. */
static void accumulate(water_work *w, int nb)
{
    for (int j = 0; j < nb; j++) {
        const double *sv = w->slot + (size_t)j * w->n_angles;
        for (int a = 0; a < w->n_angles; a++) w->acc[a] += sv[a];
        w->qext_sum += w->slot_q[3 * j];
        w->qsca_sum += w->slot_q[3 * j + 1];
        w->gq_sum += w->slot_q[3 * j + 2];
    }
}

/* All sizes, batch by batch, with progress (and cancellation) between batches. */
static atmos_status sum_sizes(atmos_context *ctx, const atmos_particle_desc *p, double nm, const size_plan *sp,
                              water_work *w, atmos__phase_progress progress, void *progress_user)
{
    batch_progress pr = {progress, progress_user, 0, 0};
    for (int b0 = 0; b0 < sp->n_sizes; b0 += w->batch) {
        int nb = sp->n_sizes - b0 < w->batch ? sp->n_sizes - b0 : w->batch;
        atmos_status bst = mie_batch(ctx, p, sp, b0, nb, w, &pr);
        if (bst == ATMOS_E_CANCELLED) return atmos__error(ctx, bst, "water phase: cancelled at %g nm", nm);
        if (bst != ATMOS_OK)
            return atmos__error(ctx, bst, "water phase: Mie computation failed at %g nm (%s)", nm,
                                atmos_status_string(bst));
        accumulate(w, nb);
        if (progress && progress(progress_user, (double)(b0 + nb) / sp->n_sizes))
            return atmos__error(ctx, ATMOS_E_CANCELLED, "water phase: cancelled at %g nm", nm);
    }
    return ATMOS_OK;
}

/* The phase function from the sums, normalised on the grid, and the cross-sections:
 * dsigma/dOmega / sigma_sca = E[|S|^2/(2x^2)] / (pi E[Q_sca]). */
static atmos_status finish(atmos_context *ctx, double nm, const double *theta_deg, const size_plan *sp,
                           const water_work *w, double *phase, atmos__phase_result *res)
{
    const int n_angles = w->n_angles;
    double norm = ATMOS_PI * w->qsca_sum;
    for (int a = 0; a < n_angles; a++) phase[a] = w->acc[a] / norm;
    double integral = atmos__sphere_integral(n_angles, theta_deg, phase);
    atmos__log(ctx, ATMOS_LOG_DEBUG, "water phase %g nm: integral of P over the sphere before normalising: %.8f", nm,
               integral);
    if (!(integral > 0.0 && isfinite(integral)))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "water phase: the angle grid does not resolve the phase function at %g nm "
                            "(integral %g)",
                            nm, integral);
    for (int a = 0; a < n_angles; a++) phase[a] /= integral;
    res->sigma_ext_m2 = ATMOS_PI * sp->mean_r2 * w->qext_sum / sp->n_sizes;
    res->albedo = w->qsca_sum / w->qext_sum;
    res->g = w->gq_sum / w->qsca_sum;
    return ATMOS_OK;
}

atmos_status atmos__water_phase(atmos_context *ctx, const atmos_particle_desc *p, double nm, int n_angles,
                                const double *theta_deg, double *phase, atmos__phase_result *res,
                                atmos__phase_progress progress, void *progress_user)
{
    atmos_status st = check_args(ctx, p, nm, n_angles, theta_deg, phase, res);
    if (st != ATMOS_OK) return st;
    size_plan sp;
    memset(&sp, 0, sizeof sp);
    water_work w;
    memset(&w, 0, sizeof w);
    st = plan_sizes(ctx, p, nm, n_angles, theta_deg, &sp);
    if (st == ATMOS_OK && work_alloc(&w, n_angles, &sp) != 0)
        st = atmos__error(ctx, ATMOS_E_NOMEM, "water phase: out of memory for %d angles", n_angles);
    if (st == ATMOS_OK) {
        cell_samples(n_angles, theta_deg, sp.ns, w.mu, w.sw);
        st = sum_sizes(ctx, p, nm, &sp, &w, progress, progress_user);
    }
    if (st == ATMOS_OK) st = finish(ctx, nm, theta_deg, &sp, &w, phase, res);
    work_free(&w);
    free(sp.tab);
    return st;
}
