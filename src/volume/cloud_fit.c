/* The laws fitted to a list of clouds (include/atmos/cloudstats.h): the perimeter-area
 * dimension by least squares in log-log (Lovejoy 1982: P ~ A^(D/2)), the size distribution's
 * power-law exponent by maximum likelihood for a power law truncated to the fit range and by
 * least squares on the log-binned histogram, and the flatness of the bases. */
#include "atmos/cloudstats.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double n, sx, sy, sxx, sxy, syy;
} lsq;

static void lsq_add(lsq *s, double x, double y)
{
    s->n += 1, s->sx += x, s->sy += y, s->sxx += x * x, s->sxy += x * y, s->syy += y * y;
}

/* Slope and its standard error (NAN with fewer than 3 points or no spread in x). */
static void lsq_slope(const lsq *s, double *slope, double *se)
{
    *slope = *se = NAN;
    double sxx = s->sxx - s->sx * s->sx / s->n, sxy = s->sxy - s->sx * s->sy / s->n, syy = s->syy - s->sy * s->sy / s->n;
    if (s->n < 3 || !(sxx > 0)) return;
    *slope = sxy / sxx;
    double sse = syy - *slope * sxy;
    *se = sqrt(fmax(sse, 0) / (s->n - 2) / sxx);
}

/* Log-likelihood per cloud of a power law d^-b truncated to [1, r] (sizes in units of the
 * lower bound), up to b's constant: ln((b - 1) / (1 - r^(1-b))) - b mean(ln u). */
static double loglik(double b, double ln_r, double mean_ln_u)
{
    double t = 1 - b, norm = fabs(t) < 1e-9 ? 1 / ln_r : t / expm1(t * ln_r);
    return log(norm) - b * mean_ln_u;
}

static void size_mle(const double *ln_u, int n, double ln_r, double *b, double *se)
{
    *b = *se = NAN;
    if (n < 3 || !(ln_r > 0)) return;
    double m = 0;
    for (int i = 0; i < n; i++) m += ln_u[i];
    m /= n;
    double lo = -3, hi = 10; /* golden section: the likelihood is concave in b */
    const double g = 0.6180339887498949;
    for (int it = 0; it < 200; it++) {
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        if (loglik(x1, ln_r, m) < loglik(x2, ln_r, m)) lo = x1;
        else hi = x2;
    }
    *b = 0.5 * (lo + hi);
    double h = 1e-3, d2 = (loglik(*b + h, ln_r, m) - 2 * loglik(*b, ln_r, m) + loglik(*b - h, ln_r, m)) / (h * h);
    if (d2 < 0) *se = 1 / sqrt(-d2 * n);
}

/* Least squares on ln(count / bin width) against ln(bin centre), bins a factor sqrt 2 wide
 * from lo; bins without clouds are left out. */
static void size_hist(const double *d, int n, double lo, double hi, double *b, double *se)
{
    enum { NB = 64 };
    int count[NB] = {0}, nb = 0;
    while (nb < NB && lo * pow(2, 0.5 * nb) < hi * (1 + 1e-12)) nb++;
    for (int i = 0; i < n; i++) {
        int k = (int)floor(2 * log2(d[i] / lo));
        if (k >= nb) k = nb - 1;
        if (k >= 0) count[k]++;
    }
    lsq s = {0};
    for (int k = 0; k < nb; k++)
        if (count[k] > 0) {
            double e0 = lo * pow(2, 0.5 * k), e1 = e0 * sqrt(2.0);
            lsq_add(&s, log(sqrt(e0 * e1)), log(count[k] / (e1 - e0)));
        }
    lsq_slope(&s, b, se);
    *b = -*b;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void flatness(const atmos_cloud *cl, int n, double min_px, atmos_cloud_fit *o)
{
    double *f = malloc((size_t)(n ? n : 1) * sizeof *f), wsum = 0, fw = 0;
    int m = 0;
    for (int i = 0; i < n && f; i++) {
        const atmos_cloud *c = &cl[i];
        if (c->edge || c->pixels < min_px || !(c->depth_m > 0) || !isfinite(c->base_sd_m)) continue;
        f[m++] = c->base_sd_m / c->depth_m;
        fw += c->area_m2 * c->base_sd_m / c->depth_m;
        wsum += c->area_m2;
    }
    o->flatness_n = m;
    o->flatness_median = o->flatness_mean = NAN;
    if (m > 0) {
        qsort(f, (size_t)m, sizeof *f, cmp_double);
        o->flatness_median = m % 2 ? f[m / 2] : 0.5 * (f[m / 2 - 1] + f[m / 2]);
        o->flatness_mean = fw / wsum;
    }
    free(f);
}

void atmos_cloud_stats_fit(const atmos_cloud *clouds, int n, long cloudy_pixels, long pixels, double dx_m,
                           const atmos_cloud_stats_desc *desc, atmos_cloud_fit *o)
{
    memset(o, 0, sizeof *o);
    double min_px = desc && desc->fit_min_pixels > 0 ? desc->fit_min_pixels : 10;
    o->clouds = n;
    o->cloud_fraction = pixels > 0 ? (double)cloudy_pixels / pixels : NAN;
    lsq ms = {0}, cr = {0};
    double amin = INFINITY, amax = 0, dmin = INFINITY, dmax = 0;
    for (int i = 0; i < n; i++) {
        const atmos_cloud *c = &clouds[i];
        o->edge_clouds += c->edge != 0;
        if (c->edge) continue;
        if (c->diameter_m > dmax) dmax = c->diameter_m;
        if (c->pixels < min_px) continue;
        o->fitted++;
        lsq_add(&ms, log(c->area_m2), log(c->perimeter_m));
        lsq_add(&cr, log(c->area_m2), log(c->crack_perimeter_m));
        amin = fmin(amin, c->area_m2), amax = fmax(amax, c->area_m2);
        dmin = fmin(dmin, c->diameter_m);
    }
    lsq_slope(&ms, &o->d, &o->d_se);
    lsq_slope(&cr, &o->d_crack, &o->d_crack_se);
    o->d *= 2, o->d_se *= 2, o->d_crack *= 2, o->d_crack_se *= 2;
    o->fit_area_min_m2 = o->fitted ? amin : NAN;
    o->fit_area_max_m2 = o->fitted ? amax : NAN;
    o->size_min_m = desc && desc->size_min_m > 0 ? desc->size_min_m : (o->fitted ? dmin : sqrt(4 * min_px / ATMOS_PI) * dx_m);
    o->size_max_m = desc && desc->size_max_m > 0 ? desc->size_max_m : dmax;
    const int range_given = desc && desc->size_min_m > 0 && desc->size_max_m > 0;
    if (!range_given && !(o->fitted > 0 && o->size_max_m > o->size_min_m)) o->size_min_m = o->size_max_m = NAN; /* no range */
    double *ln_u = malloc((size_t)(n ? n : 1) * sizeof *ln_u), *dd = malloc((size_t)(n ? n : 1) * sizeof *dd);
    int m = 0;
    for (int i = 0; i < n && ln_u && dd && o->size_max_m > o->size_min_m; i++) {
        const atmos_cloud *c = &clouds[i];
        if (c->edge || c->diameter_m < o->size_min_m * (1 - 1e-12) || c->diameter_m > o->size_max_m * (1 + 1e-12)) continue;
        dd[m] = c->diameter_m;
        ln_u[m++] = log(c->diameter_m / o->size_min_m);
    }
    o->size_n = m;
    o->size_slope = o->size_slope_se = o->size_slope_hist = o->size_slope_hist_se = NAN;
    if (ln_u && dd && o->size_max_m > o->size_min_m) {
        size_mle(ln_u, m, log(o->size_max_m / o->size_min_m), &o->size_slope, &o->size_slope_se);
        size_hist(dd, m, o->size_min_m, o->size_max_m, &o->size_slope_hist, &o->size_slope_hist_se);
    }
    free(ln_u);
    free(dd);
    flatness(clouds, n, min_px, o);
}
