/* The path tracer's plan (include/atmos/path.h, docs/path.md): the medium and the phase
 * tables of the volume (built once), the sky-light table of the last sun, and an
 * accumulator of the last view to which every render adds samples.
 *
 * Per pixel, samples are added in their index order into double sums (and sums of squares,
 * for the variance); the random numbers of sample s of pixel p come from their own stream.
 * So a pixel's mean does not depend on the thread count, the schedule, the region or how
 * many calls it took to reach its sample count. */
#include "atmosphere/atmosphere_ops.h"
#include "render/path_trace.h"
#include "render/plan_internal.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* Forward peak (sr^-1) above which the aureole estimate pays for itself: cloud droplets
 * have 400-900, HG g = 0.9 15, g = 0.95 62. */
#define AUREOLE_PEAK 100.0
/* Share of the scattering above which a truncation has cut off a diffraction peak: cloud
 * droplets at 3 degrees 0.39-0.43, a 0.5 HG 0.99 + 0.5 HG 0.85 mixture 0.36, HG 0.95 0.12. */
#define AUREOLE_CUT 0.2

struct atmos__path_plan {
    path_medium med;
    path_phase ph;
    int has_medium;                /* a volume with something in it */
    path_lamps lamps;              /* the scene's lights, fog and objects (path_lamps.c) */
    int lamps_on;
    int aureole;                   /* the aureole estimate is used */
    double trunc_lo, trunc_hi;     /* the fraction of the scattering the truncation removed */
    double prepare_s;
    /* the sky-light table of env_sun */
    path_env env;
    int env_valid, env_on;
    double env_sun[3];
    /* the accumulator of view acc_view: per pixel NA doubles (sum and sum of squares per
     * wavelength, hits, sum Y, sum Y^2, sum order x Y, samples whose path met the volume)
     * and its sample count */
    double *acc;
    int *count;
    int NA, W, H;
    int acc_valid;
    atmos__view acc_view;
};

void atmos__path_plan_destroy(atmos__path_plan *pp)
{
    if (!pp) return;
    atmos__path_medium_free(&pp->med);
    atmos__path_phase_free(&pp->ph);
    atmos__path_lamps_free(&pp->lamps);
    free(pp->acc);
    free(pp->count);
    free(pp);
}

/* The medium and phase tables of the plan's volume, with the forward-peak truncation of the
 * scene's path settings. */
static atmos_status build_medium(atmos_plan *p, atmos__path_plan *pp)
{
    atmos_context *ctx = p->ctx;
    const int n = p->wl.count;
    atmos_status st = atmos__path_phase_build(ctx, p->optics, n, p->scene.path.truncate_deg, &pp->ph);
    if (st == ATMOS_OK)
        st = atmos__path_medium_build(ctx, p->volume, p->scene.volume.density_scale, p->offset, p->optics, n, &pp->med);
    if (st != ATMOS_OK) return st;
    const path_phase *ph = &pp->ph;
    if (ph->ic) {
        atmos__path_medium_truncate(&pp->med, n, (const float(*)[ATMOS_MAX_WAVELENGTHS])ph->trunc);
        for (int f = 0; f < ph->nf; f++) {
            double lo = 1, hi = 0;
            for (int k = 0; k < n; k++) {
                if (ph->trunc[f][k] < lo) lo = ph->trunc[f][k];
                if (ph->trunc[f][k] > hi) hi = ph->trunc[f][k];
            }
            atmos__log(ctx, ATMOS_LOG_INFO,
                       "render path: field %d: forward peak truncated at %g deg, scattering fraction removed %.4f-%.4f", f,
                       ph->cut_deg, lo, hi);
            if (f == 0 || lo < pp->trunc_lo) pp->trunc_lo = lo;
            if (hi > pp->trunc_hi) pp->trunc_hi = hi;
        }
    }
    pp->has_medium = !pp->med.empty;
    /* The aureole estimate where a phase function (as used: truncated or not) has a forward
     * peak of more than AUREOLE_PEAK sr^-1 (cloud droplets: 400-900), or where the truncation
     * cut off a diffraction peak (more than AUREOLE_CUT of the scattering): what it leaves,
     * flat within the cut at ~5-15 sr^-1 against ~0.1 sideways, still makes the sparkles of
     * next-event estimation at events heading within a few degrees of the sun (docs/path.md). */
    if (pp->has_medium && p->scene.path.aureole) {
        if (ph->ic && pp->trunc_hi > AUREOLE_CUT) pp->aureole = 1;
        path_angle ang;
        atmos__path_angle(ph, cos(0.05 * ATMOS_DEG2RAD), &ang);
        for (int f = 0; f < ph->nf; f++)
            for (int k = 0; k < n; k++)
                if (atmos__path_phase_eval(ph, f, k, &ang) > AUREOLE_PEAK) pp->aureole = 1;
    }
    return ATMOS_OK;
}

/* A scene with lights, fog or objects: what the path tracer does not trace with them yet,
 * every reason in one error (a user fixing one at a time would otherwise meet the next only
 * on the next try). The beam renderer's sun is among them: leaving it out would render its
 * light as black without a word. */
static atmos_status lamps_supported(const atmos_plan *p)
{
    const atmos_scene *s = &p->scene;
    const char *why[4];
    int n = 0;
    if (p->volume) why[n++] = "a cloud volume (remove it)";
    if (atmos_atmosphere_get_kind(p->atm) != ATMOS_ATMOSPHERE_VACUUM)
        why[n++] = "the sky's air (/background: set \"black\" or a uniform one)";
    if (s->fog.enabled && s->fog.height_m > 0)
        why[n++] = "a fog thinning with height (/fog/height_m: 0 makes it uniform, which is traced)";
    if (s->beams.sun) why[n++] = "the sun as a light (/beams/sun: set it false, or render with the beam renderer)";
    if (!n) return ATMOS_OK;
    char list[768] = "";
    for (int i = 0; i < n; i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s (%d) %s", i ? ";" : "", i + 1, why[i]);
    return atmos__error(p->ctx, ATMOS_E_INVALID_ARG,
                        "render path: lights, fog and objects are not traced yet together with what this scene has "
                        "(docs/path.md):%s",
                        list);
}

atmos_status atmos__path_plan_create(atmos_plan *p, atmos__path_plan **out)
{
    const double t0 = atmos__now();
    atmos__path_plan *pp = calloc(1, sizeof *pp);
    if (!pp) return atmos__error(p->ctx, ATMOS_E_NOMEM, "render path: out of memory");
    pp->NA = 2 * p->wl.count + 5;
    const atmos_scene *s = &p->scene;
    if (s->light_count > 0 || s->fog.enabled || s->object_count > 0) {
        atmos_status st = lamps_supported(p);
        if (st == ATMOS_OK) st = atmos__path_lamps_build(p->ctx, s, &p->wl, &pp->lamps);
        if (st != ATMOS_OK) {
            atmos__path_plan_destroy(pp);
            return st;
        }
        pp->lamps_on = 1;
    }
    if (p->volume && atmos_volume_field_count(p->volume) > 0) {
        atmos_status st = build_medium(p, pp);
        if (st != ATMOS_OK) {
            atmos__path_plan_destroy(pp);
            return st;
        }
    }
    pp->prepare_s = atmos__now() - t0;
    *out = pp;
    return ATMOS_OK;
}

/* The sky-light table (next-event estimation toward the sky) for the sun of the view, seen
 * from the middle of the volume's box; kept until the sun moves. (A uniform background is
 * left to the continuations: next-event estimation with uniform directions doubled the
 * noise of a slab before one; every escaping path already sees exactly the background.) */
static void sky_light(atmos_plan *p, atmos__path_plan *pp, const double sun[3])
{
    if (pp->env_valid && !memcmp(pp->env_sun, sun, sizeof pp->env_sun)) return;
    pp->env_on = 0;
    if (pp->has_medium && p->scene.path.sky_nee) {
        const path_medium *med = &pp->med;
        double qc[3], pc[3], Yw[ATMOS_MAX_WAVELENGTHS];
        for (int a = 0; a < 3; a++) qc[a] = 0.5 * (med->box_lo[a] + med->box_hi[a]);
        for (int a = 0; a < 3; a++) {
            pc[a] = med->org[a];
            for (int c = 0; c < 3; c++) pc[a] += med->R[3 * a + c] * qc[c] / med->inv_vs;
        }
        for (int k = 0; k < p->wl.count; k++) Yw[k] = p->wl.to_xyz[k][1];
        pp->env_on = atmos__path_env_build(p->atm, sun, pc, Yw, &pp->env);
    }
    memcpy(pp->env_sun, sun, sizeof pp->env_sun);
    pp->env_valid = 1;
}

/* The job of a view: everything one camera path reads. */
static void make_job(atmos_plan *p, atmos__path_plan *pp, const atmos__view *v, path_job *J)
{
    const atmos_atmosphere *atm = p->atm;
    memset(J, 0, sizeof *J);
    J->deadline = INFINITY;
    J->atm = atm;
    J->cam = v->cam;
    memcpy(J->sun, v->sun, sizeof J->sun);
    J->n = p->wl.count;
    const double r = 0.5 * atmos_atmosphere_get_desc(atm)->sun_diameter_deg * ATMOS_DEG2RAD;
    J->cos_sun = cos(r);
    J->sun_omega = atmos_atmosphere_sun_solid_angle(atm); /* > 0 even where cos_sun rounds to 1 */
    J->max_depth = p->scene.path.max_depth ? p->scene.path.max_depth : PATH_DEFAULT_DEPTH;
    J->depth_default = !p->scene.path.max_depth;
    J->seed = p->scene.path.seed;
    J->forced = p->scene.path.forced;
    J->albedo = atmos_atmosphere_ground_albedo(atm);
    J->disk_visible = atmos_atmosphere_sun_disk_visible(atm, J->sun);
    J->bg = atmos__atm_background(atm);
    if (pp->has_medium) J->med = &pp->med, J->ph = &pp->ph, J->aureole = pp->aureole;
    const atmos_atmosphere_kind kind = atmos_atmosphere_get_kind(atm);
    J->reference = !pp->has_medium && (kind == ATMOS_ATMOSPHERE_DOBASHI || kind == ATMOS_ATMOSPHERE_SPHERICAL);
    sky_light(p, pp, v->sun);
    if (pp->env_on) J->env = &pp->env;
    if (pp->lamps_on) J->lamps = &pp->lamps, J->reference = 0, J->roulette = p->scene.path.roulette;
}

/* The clock of a render's passes: the time budget, checked before every sample, and the
 * progress reports (by the calling thread, at most every REPORT_S seconds). */
#define REPORT_S 0.25
typedef struct {
    atmos_context *ctx;
    double start, deadline, budget, next_report;
    long long total;   /* samples this call is to take */
    atomic_llong done; /* samples taken so far */
    atomic_int stop;   /* 1: the budget is spent, 2: cancelled */
    atomic_int cut;    /* a path has reached the default depth limit */
    int cut_told;      /* ... and the calling thread has warned of it */
} path_clock;

/* The first path stopped by the default depth limit is told at once (by the calling thread,
 * at its next sample or pass), not only in the count at the render's end: such a render is
 * usually one that stalls. */
static void tell_cut(path_clock *c)
{
    if (c->cut_told || !atomic_load_explicit(&c->cut, memory_order_relaxed)) return;
    c->cut_told = 1;
    atmos__log(c->ctx, ATMOS_LOG_WARN,
               "render path: a path reached the default limit of %d scattering events and was stopped (the render "
               "goes on; their count comes at its end): paths this long make a render slow and lose light; "
               "path.max_depth sets the limit",
               PATH_DEFAULT_DEPTH);
}

/* Before a sample: 0 to take it, 1 to stop (budget spent or cancelled). */
static int clock_tick(path_clock *c)
{
    if (atomic_load_explicit(&c->stop, memory_order_relaxed)) return 1;
    const double now = atmos__now();
    if (now >= c->deadline) {
        atomic_store(&c->stop, 1);
        return 1;
    }
#ifdef _OPENMP
    if (omp_get_thread_num() != 0) return 0;
#endif
    tell_cut(c);
    if (now < c->next_report) return 0;
    c->next_report = now + REPORT_S;
    double f = c->total > 0 ? (double)atomic_load_explicit(&c->done, memory_order_relaxed) / (double)c->total : 1.0;
    if (c->budget > 0 && (now - c->start) / c->budget > f) f = (now - c->start) / c->budget;
    if (atmos__progress(c->ctx, "render path", f < 1 ? f : 0.999)) {
        atomic_store(&c->stop, 2);
        return 1;
    }
    return 0;
}

/* Samples s0..s1-1 of pixel (x, y) added to its sums A, while the clock lets; returns the
 * pixel's sample count reached. */
static int sample_pixel(const path_job *J, int x, int y, size_t pix, int s0, int s1, const double *Ybar, double *A,
                        path_counts *cnt, path_clock *clk)
{
    const int n = J->n;
    int smp = s0;
    for (; smp < s1 && !clock_tick(clk); smp++) {
        atmos__stream rng;
        atmos__stream_seed(&rng, J->seed, pix, (uint64_t)smp);
        /* The carried wavelengths: all of them in rgb mode; in spectral mode a uniformly
         * chosen hero and the wavelengths a quarter, half and three quarters of the set away,
         * each counted with weight N / PATH_B. */
        path_bundle b;
        double wgt = 1.0;
        if (n <= PATH_B) {
            b.m = n;
            for (int i = 0; i < n; i++) b.k[i] = i;
        } else {
            int k0 = (int)(atmos__stream_u(&rng) * n);
            if (k0 >= n) k0 = n - 1;
            b.m = PATH_B;
            for (int i = 0; i < PATH_B; i++) b.k[i] = (k0 + (i * n) / PATH_B) % n;
            wgt = (double)n / PATH_B;
        }
        double jx = atmos__stream_u(&rng), jy = atmos__stream_u(&rng), dir[3];
        double L[PATH_B] = {0, 0, 0, 0}, Lo[PATH_B] = {0, 0, 0, 0}, Y = 0, Yo = 0;
        if (atmos_camera_ray(&J->cam, x + jx, y + jy, dir)) {
            const long long cut0 = cnt->cut;
            const int met = atmos__path_trace(J, &b, J->cam.position, dir, &rng, L, Lo, cnt);
            if (cnt->cut != cut0) atomic_store_explicit(&clk->cut, 1, memory_order_relaxed);
            if (met == PATH_ABANDONED) {
                atomic_store(&clk->stop, 1);
                break;
            }
            if (met > 0) A[2 * n + 4] += 1;
            A[2 * n] += 1;
        }
        for (int i = 0; i < b.m; i++) {
            double v = L[i] * wgt;
            if (!isfinite(v)) v = 0; /* a non-finite sample counts 0 (every estimate is >= 0) */
            A[b.k[i]] += v;
            A[n + b.k[i]] += v * v;
            Y += Ybar[b.k[i]] * v;
            if (v != 0 && isfinite(Lo[i])) Yo += Ybar[b.k[i]] * Lo[i] * wgt;
        }
        A[2 * n + 1] += Y;
        A[2 * n + 2] += Y * Y;
        A[2 * n + 3] += Yo;
    }
    atomic_fetch_add_explicit(&clk->done, smp - s0, memory_order_relaxed);
    return smp;
}

/* One pass: every pixel of r brought to s1 samples (fewer where the clock stopped it). */
static void pass(atmos__path_plan *pp, const path_job *J, const atmos__rect *r, int s1, int threads, const double *Ybar,
                 path_clock *clk, atmos_path_stats *st)
{
    const int NA = pp->NA, W = pp->W;
    long long ev = 0, tc = 0, sh = 0, cut = 0, ended = 0, paths = 0;
    atmos__path_walks_ended(); /* the calling thread's count starts at 0 */
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : ev, tc, sh, cut, ended, paths)
    for (int y = r->y0; y < r->y1; y++) {
        path_counts cnt = {0, 0, 0, 0, 0};
        for (int x = r->x0; x < r->x1; x++) {
            const size_t pix = (size_t)y * W + x;
            if (pp->count[pix] >= s1) continue;
            const int got = sample_pixel(J, x, y, pix, pp->count[pix], s1, Ybar, pp->acc + pix * NA, &cnt, clk);
            paths += got - pp->count[pix];
            pp->count[pix] = got;
        }
        ev += cnt.events, tc += cnt.tentative, sh += cnt.shadow, cut += cnt.cut;
        ended += atmos__path_walks_ended();
    }
    st->events += ev, st->tentative += tc, st->shadow_rays += sh, st->paths += paths, st->cut_paths += cut;
    st->walks_ended += ended;
}

/* The accumulator's rows of r (sums and counts): saved before a pass that may be cut by the
 * budget, restored when it is. */
typedef struct {
    double *acc;
    int *count;
} path_saved;

static void save_rows(const atmos__path_plan *pp, const atmos__rect *r, path_saved *sv, int restore)
{
    const size_t first = (size_t)r->y0 * pp->W, n = (size_t)(r->y1 - r->y0) * pp->W;
    if (restore) {
        memcpy(pp->acc + first * pp->NA, sv->acc, sizeof(double) * n * pp->NA);
        memcpy(pp->count + first, sv->count, sizeof(int) * n);
    } else {
        memcpy(sv->acc, pp->acc + first * pp->NA, sizeof(double) * n * pp->NA);
        memcpy(sv->count, pp->count + first, sizeof(int) * n);
    }
}

/* The lowest sample count of r's pixels (at most cap) and how many pixels have none. */
static int lowest_count(const atmos__path_plan *pp, const atmos__rect *r, int cap, long long *empty)
{
    int lowest = cap;
    *empty = 0;
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) {
            const int c = pp->count[(size_t)y * pp->W + x];
            if (c < lowest) lowest = c;
            *empty += c == 0;
        }
    return lowest;
}

/* Passes of S samples per pixel of r until every pixel has target, S from the region's size
 * only. The time budget is checked before every sample: a pass it cuts is discarded (every
 * pixel keeps the samples of the whole passes before it, so the image is that of the passes
 * completed, whatever the thread count), except a first pass, whose samples are kept (pixels
 * it did not reach stay empty: st->empty_pixels). With a budget the passes start at one
 * sample per pixel and double while a pass takes less than 1/16 of the budget (up to S), so a
 * discarded pass costs little. (A pixel's sums depend on its sample count only, not on how the
 * samples were grouped into passes.) */
static atmos_status accumulate(atmos_plan *p, atmos__path_plan *pp, const path_job *J, const atmos__rect *r,
                               int target, atmos_path_stats *st)
{
    atmos_context *ctx = p->ctx;
    const int threads = atmos__threads(ctx);
    const size_t npix = (size_t)(r->x1 - r->x0) * (r->y1 - r->y0);
    int S = (int)(65536 / (npix ? npix : 1));
    S = S < 1 ? 1 : (S > 256 ? 256 : S);
    double Ybar[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < J->n; k++) Ybar[k] = p->wl.to_xyz[k][1];
    path_clock clk = {.ctx = ctx, .start = atmos__now(), .budget = p->scene.path.time_budget_s};
    clk.deadline = clk.budget > 0 ? clk.start + clk.budget : INFINITY;
    clk.next_report = clk.start + REPORT_S;
    atomic_init(&clk.done, 0);
    atomic_init(&clk.stop, 0);
    atomic_init(&clk.cut, 0);
    long long empty = 0;
    int lowest = lowest_count(pp, r, target, &empty);
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) {
            const int c = pp->count[(size_t)y * pp->W + x];
            clk.total += c < target ? target - c : 0;
        }
    path_saved sv = {NULL, NULL};
    const size_t nrow = (size_t)(r->y1 - r->y0) * pp->W;
    if (clk.budget > 0 && lowest < target) {
        sv.acc = malloc(sizeof(double) * nrow * pp->NA);
        sv.count = malloc(sizeof(int) * nrow);
        if (!sv.acc || !sv.count) {
            free(sv.acc), free(sv.count);
            return atmos__error(ctx, ATMOS_E_NOMEM, "render path: out of memory for the time budget's copy");
        }
    }
    atmos_status status = ATMOS_OK;
    int step = clk.budget > 0 ? 1 : S; /* with a budget: passes of 1, 2, 4 ... samples up to S */
    path_job Jb = *J; /* with the budget's deadline, past which a path is abandoned */
    Jb.deadline = clk.deadline;
    while (lowest < target) {
        const int s1 = lowest + step < target ? lowest + step : target;
        const int undo = sv.acc && lowest > 0;
        if (undo) save_rows(pp, r, &sv, 0);
        const double tp = atmos__now();
        pass(pp, &Jb, r, s1, threads, Ybar, &clk, st);
        tell_cut(&clk);
        if (step < S && 16.0 * (atmos__now() - tp) < clk.budget) step = 2 * step < S ? 2 * step : S;
        const int stop = atomic_load(&clk.stop);
        if (stop == 2) {
            status = atmos__error(ctx, ATMOS_E_CANCELLED, "render path: cancelled");
            break;
        }
        if (stop == 1) {
            st->budget_cut = 1;
            if (undo) save_rows(pp, r, &sv, 1);
            break;
        }
        lowest = s1;
        const double el = atmos__now() - clk.start;
        double frac = (double)atomic_load(&clk.done) / (double)(clk.total ? clk.total : 1);
        if (clk.budget > 0 && el / clk.budget > frac) frac = el / clk.budget;
        if (atmos__progress(ctx, "render path", frac)) {
            status = atmos__error(ctx, ATMOS_E_CANCELLED, "render path: cancelled");
            break;
        }
        if (clk.budget > 0 && el >= clk.budget) break;
    }
    free(sv.acc), free(sv.count);
    st->spp = lowest_count(pp, r, target, &empty);
    st->empty_pixels = empty;
    return status;
}

/* Ascending doubles, for qsort. */
static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The means of r into out, and the convergence figures: the mean over pixels with a nonzero
 * mean of the relative standard error of the pixel's mean luminance, and over the volume's
 * pixels (some sample scattered in the volume) its mean, median and 90th percentile. */
static void resolve(const atmos__path_plan *pp, int n, const atmos__rect *r, atmos_image *out, atmos_path_stats *st)
{
    const int NA = pp->NA, C = n + 1, W = pp->W;
    double rel_sum = 0, vol_sum = 0;
    long long rel_n = 0, vol_n = 0;
    double *vol = malloc(sizeof(double) * (size_t)(r->x1 - r->x0) * (size_t)(r->y1 - r->y0));
    for (int y = r->y0; y < r->y1; y++)
        for (int x = r->x0; x < r->x1; x++) {
            const size_t pix = (size_t)y * W + x;
            const double *A = pp->acc + pix * NA, N = pp->count[pix];
            float *px = out->pixels + pix * C;
            if (!(N > 0)) {
                for (int k = 0; k <= n; k++) px[k] = 0;
                continue;
            }
            for (int k = 0; k < n; k++) px[k] = (float)(A[k] / N);
            px[n] = (float)(A[2 * n] / N);
            const double my = A[2 * n + 1] / N;
            double vy = N > 1 ? (A[2 * n + 2] / N - my * my) / (N - 1) : 0;
            if (!(vy > 0)) vy = 0;
            if (my > 0 && N > 1) {
                rel_sum += sqrt(vy) / my;
                rel_n++;
                if (A[2 * n + 4] > 0) {
                    vol_sum += sqrt(vy) / my;
                    if (vol) vol[vol_n] = sqrt(vy) / my;
                    vol_n++;
                }
            }
        }
    st->mean_rel_error = rel_n ? rel_sum / rel_n : 0.0;
    st->volume_pixels = vol_n;
    st->volume_rel_error_mean = vol_n ? vol_sum / vol_n : 0.0;
    st->volume_rel_error_median = st->volume_rel_error_p90 = 0;
    if (vol && vol_n) {
        qsort(vol, (size_t)vol_n, sizeof *vol, cmp_double);
        st->volume_rel_error_median = vol[(vol_n - 1) / 2];
        if (!(vol_n & 1)) st->volume_rel_error_median = 0.5 * (vol[(vol_n - 1) / 2] + vol[vol_n / 2]);
        st->volume_rel_error_p90 = vol[(size_t)ceil(0.9 * (double)vol_n) - 1];
    }
    free(vol);
}

/* Warnings for what the render could not do: paths cut by the default depth limit, pixels
 * the time budget left without a sample. */
static void report(atmos_context *ctx, const atmos_path_stats *st)
{
    if (st->cut_paths > 0)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render path: %lld of %lld paths (%.3g %%) reached the default limit of %d scattering events and "
                   "were stopped, their further light lost (an optically very thick volume: a conservative slab of "
                   "optical depth 1000 loses about 4 %% of the light this way; or a fog that fills all space and "
                   "absorbs little, where paths wander without end: path.max_depth 1 gives its single scattering, "
                   "what the beam renderer draws); path.max_depth sets the limit",
                   st->cut_paths, st->paths, 100.0 * (double)st->cut_paths / (double)(st->paths ? st->paths : 1),
                   PATH_DEFAULT_DEPTH);
    if (st->walks_ended > 0)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render path: %lld free flights or shadow rays took more than %d steps and ended at their Russian "
                   "roulette (unbiased, but the light through such parts is noisy and mostly lost at these sample "
                   "counts): the volume is optically huge within its %d-voxel bricks (a density scale far too large?)",
                   st->walks_ended, PATH_WALK_RR, VOL_BRICK);
    if (st->empty_pixels > 0)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "render path: the time budget ran out in the first pass: %lld pixels have no sample (black, alpha 0)",
                   st->empty_pixels);
}

/* Starts the accumulator again for a view (a new camera or sun, a smaller budget). */
static atmos_status restart(atmos_plan *p, atmos__path_plan *pp, const atmos__view *v)
{
    const size_t npix = (size_t)v->cam.width * v->cam.height;
    if (!pp->acc || pp->W != v->cam.width || pp->H != v->cam.height) {
        free(pp->acc), free(pp->count);
        pp->acc = malloc(sizeof(double) * npix * pp->NA);
        pp->count = malloc(sizeof(int) * npix);
        pp->acc_valid = 0;
        if (!pp->acc || !pp->count) {
            free(pp->acc), free(pp->count);
            pp->acc = NULL, pp->count = NULL;
            return atmos__error(p->ctx, ATMOS_E_NOMEM, "render path: out of memory for the accumulators");
        }
        pp->W = v->cam.width, pp->H = v->cam.height;
    }
    memset(pp->acc, 0, sizeof(double) * npix * pp->NA);
    memset(pp->count, 0, sizeof(int) * npix);
    pp->acc_view = *v;
    pp->acc_valid = 1;
    return ATMOS_OK;
}

atmos_status atmos__path_render(atmos_plan *p, const atmos__view *v, const atmos__rect *r, atmos_image *out,
                                atmos_path_stats *st)
{
    atmos__path_plan *pp = p->path;
    const double t_start = atmos__now();
    memset(st, 0, sizeof *st);
    int over = 0; /* some pixel of r has more samples than the frame asks for */
    if (pp->acc_valid)
        for (int y = r->y0; y < r->y1 && !over; y++)
            for (int x = r->x0; x < r->x1; x++) over |= pp->count[(size_t)y * pp->W + x] > v->spp;
    const int same = pp->acc_valid && !memcmp(&pp->acc_view.cam, &v->cam, sizeof v->cam) &&
                     !memcmp(pp->acc_view.sun, v->sun, sizeof v->sun);
    atmos_status s = ATMOS_OK;
    if (!same || over) s = restart(p, pp, v);
    if (s != ATMOS_OK) return s;
    path_job J;
    make_job(p, pp, v, &J);
    const double t0 = atmos__now();
    st->prepare_s = pp->prepare_s;
    if ((s = accumulate(p, pp, &J, r, v->spp, st)) != ATMOS_OK) {
        pp->acc_valid = 0;
        return s;
    }
    st->trace_s = atmos__now() - t0;
    resolve(pp, p->wl.count, r, out, st);
    report(p->ctx, st);
    st->truncate_deg = pp->ph.ic ? pp->ph.cut_deg : 0.0;
    st->truncated_min = pp->trunc_lo, st->truncated_max = pp->trunc_hi;
    st->total_s = atmos__now() - t_start;
    return ATMOS_OK;
}

/* An image of the accumulator: per pixel f(A, N, px) for pixels with samples, 0 elsewhere. */
static atmos_status aux_image(const atmos_plan *p, int channels, void (*f)(const double *, double, int, float *),
                              atmos_image **out)
{
    const atmos__path_plan *pp = p->path;
    *out = NULL;
    if (!pp->acc_valid) return atmos__error(p->ctx, ATMOS_E_INVALID_ARG, "render path: nothing rendered yet");
    atmos_status st = atmos_image_create(p->ctx, pp->W, pp->H, channels, out);
    if (st != ATMOS_OK) return st;
    for (size_t pix = 0; pix < (size_t)pp->W * pp->H; pix++)
        if (pp->count[pix] > 0) f(pp->acc + pix * pp->NA, pp->count[pix], p->wl.count, (*out)->pixels + pix * channels);
    return ATMOS_OK;
}

/* The variance of the mean per wavelength, then the luminance's. */
static void pixel_variance(const double *A, double N, int n, float *px)
{
    for (int k = 0; k < n; k++) {
        const double mean = A[k] / N, v = N > 1 ? (A[n + k] / N - mean * mean) / (N - 1) : 0;
        px[k] = (float)(v > 0 ? v : 0);
    }
    const double my = A[2 * n + 1] / N;
    double vy = N > 1 ? (A[2 * n + 2] / N - my * my) / (N - 1) : 0;
    if (!(vy > 0)) vy = 0;
    px[n] = (float)vy;
}

/* The luminance-weighted mean scattering order. */
static void pixel_order(const double *A, double N, int n, float *px)
{
    (void)N;
    px[0] = A[2 * n + 1] > 0 ? (float)(A[2 * n + 3] / A[2 * n + 1]) : 0.0f;
}

atmos_status atmos__path_variance(const atmos_plan *p, atmos_image **out)
{
    return aux_image(p, p->wl.count + 1, pixel_variance, out);
}

atmos_status atmos__path_order(const atmos_plan *p, atmos_image **out) { return aux_image(p, 1, pixel_order, out); }

void atmos__path_describe(const atmos_plan *p, char *buf, size_t cap)
{
    const atmos_scene_path *s = &p->scene.path;
    const char *air = atmos_atmosphere_get_kind(p->atm) == ATMOS_ATMOSPHERE_VACUUM ? "vacuum" : "sky";
    int n = snprintf(buf, cap, "%d spp, seed %llu, max depth %d, %s", p->stats.path.spp, (unsigned long long)s->seed,
                     s->max_depth, air);
    if (p->path->ph.ic && n > 0 && (size_t)n < cap)
        snprintf(buf + n, cap - (size_t)n, ", forward peak truncated at %g deg", p->path->ph.cut_deg);
}
