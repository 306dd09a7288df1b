/* Image comparison: error statistics between an image and a reference, the worst
 * region, and a heat map of the difference (for `atmos compare` and accuracy reports). */
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define COMPARE_TILE 16

/* The old positional rule: the colour channels in order, a 4th channel of an RGBA
 * image being coverage, not light. */
static atmos_status positional_match(atmos_context *ctx, const atmos_image *a, const atmos_image *ref,
                                     atmos_channel_match *m)
{
    int ca = a->channels == 4 ? 3 : a->channels, cr = ref->channels == 4 ? 3 : ref->channels;
    if (ca != cr)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: channel counts differ: %d vs %d", a->channels,
                            ref->channels);
    if (ca > ATMOS_IMAGE_DIFF_MAX_CHANNELS)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "compare: at most %d colour channels, got %d",
                            ATMOS_IMAGE_DIFF_MAX_CHANNELS, ca);
    memset(m, 0, sizeof *m);
    m->count = ca;
    for (int c = 0; c < ca; c++) m->image[c] = m->reference[c] = c;
    return ATMOS_OK;
}

/* Whether the pixel (pa of the image, pr of the reference) is left out of every figure: a
 * compared channel of either is finite and above m->exclude_above (when that is > 0). Its
 * NaN or infinite samples still count as nonfinite (an infinity is a broken image, not a
 * bright sun): see count_nonfinite. */
static int excluded(const atmos_channel_match *m, const float *pa, const float *pr)
{
    if (!(m->exclude_above > 0)) return 0;
    for (int c = 0; c < m->count; c++) {
        const float v[2] = {pa[m->image[c]], pr[m->reference[c]]};
        for (int i = 0; i < 2; i++)
            if (isfinite(v[i]) && v[i] > m->exclude_above) return 1;
    }
    return 0;
}

/* The non-finite samples of an excluded pixel, counted in out as those of a compared one. */
static void count_nonfinite(const atmos_channel_match *m, const float *pa, const float *pr, atmos_image_diff *out)
{
    for (int c = 0; c < m->count; c++) {
        const int a = !isfinite(pa[m->image[c]]), r = !isfinite(pr[m->reference[c]]);
        out->nonfinite += a || r;
        out->nonfinite_excluded += a || r;
        out->nonfinite_image += a;
        out->nonfinite_reference += r;
    }
}

static atmos_status check_match(atmos_context *ctx, const atmos_image *a, const atmos_image *ref,
                                const atmos_channel_match *m)
{
    if (!m || m->count < 1 || m->count > ATMOS_IMAGE_DIFF_MAX_CHANNELS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: 1..%d channels to compare", ATMOS_IMAGE_DIFF_MAX_CHANNELS);
    for (int c = 0; c < m->count; c++)
        if (m->image[c] < 0 || m->image[c] >= a->channels || m->reference[c] < 0 || m->reference[c] >= ref->channels)
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: channel pair %d is out of range", c);
    return ATMOS_OK;
}

atmos_status atmos_image_compare(atmos_context *ctx, const atmos_image *a, const atmos_image *ref,
                                 atmos_image_diff *out, atmos_image **heatmap)
{
    if (heatmap) *heatmap = NULL;
    if (!a || !ref || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing image");
    atmos_channel_match m;
    atmos_status st = positional_match(ctx, a, ref, &m);
    if (st != ATMOS_OK) return st;
    return atmos_image_compare_matched(ctx, a, ref, &m, out, heatmap);
}

/* The q-quantile of the heat map's values (every third float of h, npx pixels), by selection
 * (the same element a sort would put at floor(q (npx - 1))); 0 when there is no memory for
 * the copy (the caller keeps the largest). */
static double heat_percentile(const atmos_image *h, size_t npx, double q)
{
    float *v = malloc(sizeof(float) * (npx ? npx : 1));
    if (!v) return 0;
    for (size_t p = 0; p < npx; p++) v[p] = h->pixels[p * 3];
    const double r = npx ? atmos__select_float(v, npx, (size_t)floor(q * (double)(npx - 1))) : 0;
    free(v);
    return r;
}

atmos_status atmos_image_compare_matched(atmos_context *ctx, const atmos_image *a, const atmos_image *ref,
                                         const atmos_channel_match *m, atmos_image_diff *out, atmos_image **heatmap)
{
    if (heatmap) *heatmap = NULL;
    if (!a || !ref || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing image");
    if (a->width != ref->width || a->height != ref->height)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: sizes differ: %dx%d vs %dx%d", a->width, a->height,
                            ref->width, ref->height);
    atmos_status st = check_match(ctx, a, ref, m);
    if (st != ATMOS_OK) return st;
    const int ca = m->count;
    const int *ia = m->image, *ir = m->reference;
    memset(out, 0, sizeof *out);
    out->channels = ca;
    const size_t npx = (size_t)a->width * a->height;
    double se[ATMOS_IMAGE_DIFF_MAX_CHANNELS] = {0}, sd[ATMOS_IMAGE_DIFF_MAX_CHANNELS] = {0},
           sr[ATMOS_IMAGE_DIFF_MAX_CHANNELS] = {0};
    size_t cnt[ATMOS_IMAGE_DIFF_MAX_CHANNELS] = {0}; /* finite samples per channel */
    size_t bad = 0, bad_a = 0, bad_r = 0;
    for (size_t p = 0; p < npx; p++) {
        const float *pa = a->pixels + p * a->channels, *pr = ref->pixels + p * ref->channels;
        if (excluded(m, pa, pr)) {
            out->excluded++;
            count_nonfinite(m, pa, pr, out);
            continue;
        }
        for (int c = 0; c < ca; c++) {
            double va = pa[ia[c]], vr = pr[ir[c]];
            if (!isfinite(va) || !isfinite(vr)) {
                bad++;
                bad_a += !isfinite(va);
                bad_r += !isfinite(vr);
                continue;
            }
            double d = va - vr;
            se[c] += d * d;
            sd[c] += d;
            sr[c] += fabs(vr);
            cnt[c]++;
        }
    }
    /* Means over the finite samples only: a NaN must not count as a perfect match, and a
     * channel with no finite sample has NaN statistics, not zeros. */
    double se_all = 0, sr_all = 0, n_all = 0;
    for (int c = 0; c < ca; c++) {
        double n = cnt[c] ? (double)cnt[c] : NAN;
        out->rmse[c] = sqrt(se[c] / n);
        out->bias[c] = sd[c] / n;
        double mean_ref = sr[c] / n;
        out->rel_rmse[c] = !cnt[c] ? NAN : mean_ref > 0 ? out->rmse[c] / mean_ref : (out->rmse[c] > 0 ? INFINITY : 0.0);
        se_all += se[c];
        sr_all += sr[c];
        n_all += (double)cnt[c];
    }
    if (n_all < 1) n_all = NAN;
    out->rmse_all = sqrt(se_all / n_all);
    double mean_all = sr_all / n_all;
    out->rel_rmse_all = !(n_all >= 1) ? NAN : mean_all > 0 ? out->rmse_all / mean_all : (out->rmse_all > 0 ? INFINITY : 0.0);
    out->nonfinite += bad;
    out->nonfinite_image += bad_a;
    out->nonfinite_reference += bad_r;
    /* The worst region: the COMPARE_TILE^2 tile with the largest RMSE, of those with a compared
     * sample (none: worst_w = worst_h = 0, worst_rmse NaN). */
    out->worst_rmse = -1;
    for (int ty = 0; ty < a->height; ty += COMPARE_TILE)
        for (int tx = 0; tx < a->width; tx += COMPARE_TILE) {
            double s = 0;
            int n = 0;
            for (int y = ty; y < ty + COMPARE_TILE && y < a->height; y++)
                for (int x = tx; x < tx + COMPARE_TILE && x < a->width; x++) {
                    const float *pa = a->pixels + ((size_t)y * a->width + x) * a->channels,
                                *pr = ref->pixels + ((size_t)y * ref->width + x) * ref->channels;
                    for (int c = 0; c < ca && !excluded(m, pa, pr); c++) {
                        double d = (double)pa[ia[c]] - pr[ir[c]];
                        if (isfinite(d)) s += d * d, n++;
                    }
                }
            double r = n ? sqrt(s / n) : -1;
            if (r > out->worst_rmse) {
                out->worst_rmse = r;
                out->worst_x = tx, out->worst_y = ty;
                out->worst_w = tx + COMPARE_TILE <= a->width ? COMPARE_TILE : a->width - tx;
                out->worst_h = ty + COMPARE_TILE <= a->height ? COMPARE_TILE : a->height - ty;
            }
        }
    if (out->worst_rmse < 0) out->worst_rmse = NAN;
    if (!heatmap) return ATMOS_OK;
    /* Heat map: per pixel the mean absolute difference over the channels relative to the
     * reference's mean value, 0 black -> red -> yellow -> white at out->heat_scale. */
    atmos_image *h = NULL;
    st = atmos_image_create(ctx, a->width, a->height, 3, &h);
    if (st != ATMOS_OK) return st;
    double scale = 0;
    for (size_t p = 0; p < npx; p++) {
        const float *pa = a->pixels + p * a->channels, *pr = ref->pixels + p * ref->channels;
        double d = 0;
        for (int c = 0; c < ca && !excluded(m, pa, pr); c++) d += fabs((double)pa[ia[c]] - pr[ir[c]]);
        d = mean_all > 0 ? d / ca / mean_all : 0;
        if (!isfinite(d)) d = 0;
        h->pixels[p * 3] = (float)d;
        if (d > scale) scale = d;
    }
    /* white at the largest difference, but at most 10 times the 99th percentile of the
     * pixels' differences: one pixel far off (a lamp, the sun's disc) would leave the rest
     * black; the few above the scale saturate. The largest when the percentile is 0 (a few
     * pixels differ at all). */
    const double p99 = heat_percentile(h, npx, 0.99);
    if (p99 > 0 && scale > 10 * p99) scale = 10 * p99;
    out->heat_scale = scale;
    for (size_t p = 0; p < npx; p++) {
        double t = scale > 0 ? h->pixels[p * 3] / scale : 0;
        h->pixels[p * 3] = (float)fmin(1.0, 3 * t);
        h->pixels[p * 3 + 1] = (float)fmin(1.0, fmax(0.0, 3 * t - 1));
        h->pixels[p * 3 + 2] = (float)fmin(1.0, fmax(0.0, 3 * t - 2));
    }
    char buf[64];
    snprintf(buf, sizeof buf, "%.6g", scale);
    atmos_image_set_meta(h, "atmos:heat_scale_relative", buf);
    *heatmap = h;
    return ATMOS_OK;
}

atmos_status atmos_image_compare_binned(atmos_context *ctx, const atmos_image *a, const atmos_image *ref,
                                        const atmos_image *key, const double *edges, int n_edges, atmos_image_bins *out)
{
    if (!a || !ref || !key || !edges || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing argument");
    atmos_channel_match m;
    atmos_status st = positional_match(ctx, a, ref, &m);
    if (st != ATMOS_OK) return st;
    return atmos_image_compare_binned_matched(ctx, a, ref, &m, key, edges, n_edges, out);
}

atmos_status atmos_image_compare_binned_matched(atmos_context *ctx, const atmos_image *a, const atmos_image *ref,
                                                const atmos_channel_match *m, const atmos_image *key,
                                                const double *edges, int n_edges, atmos_image_bins *out)
{
    if (!a || !ref || !key || !edges || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing argument");
    if (a->width != ref->width || a->height != ref->height || key->width != a->width || key->height != a->height)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: image, reference and key sizes differ (%dx%d, %dx%d, %dx%d)",
                            a->width, a->height, ref->width, ref->height, key->width, key->height);
    atmos_status st = check_match(ctx, a, ref, m);
    if (st != ATMOS_OK) return st;
    const int ca = m->count;
    const int *ia = m->image, *ir = m->reference;
    if (n_edges < 2 || n_edges > ATMOS_IMAGE_BINS_MAX + 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: 2..%d bin edges, got %d", ATMOS_IMAGE_BINS_MAX + 1,
                            n_edges);
    for (int i = 0; i < n_edges; i++)
        if (isnan(edges[i]) || (i && !(edges[i] > edges[i - 1])))
            return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: bin edges must ascend strictly");
    memset(out, 0, sizeof *out);
    out->bins = n_edges - 1;
    memcpy(out->edges, edges, sizeof(double) * (size_t)n_edges);
    double se[ATMOS_IMAGE_BINS_MAX] = {0}, sd[ATMOS_IMAGE_BINS_MAX] = {0}, sr[ATMOS_IMAGE_BINS_MAX] = {0};
    size_t ns[ATMOS_IMAGE_BINS_MAX] = {0};
    const size_t npx = (size_t)a->width * a->height;
    for (size_t p = 0; p < npx; p++) {
        double k = key->pixels[p * key->channels];
        if (!(k >= edges[0]) || !(k < edges[n_edges - 1])) continue;
        int b = 0;
        while (b + 1 < out->bins && k >= edges[b + 1]) b++;
        const float *pa = a->pixels + p * a->channels, *pr = ref->pixels + p * ref->channels;
        if (excluded(m, pa, pr)) continue;
        int counted = 0;
        for (int c = 0; c < ca; c++) {
            double va = pa[ia[c]], vr = pr[ir[c]];
            if (!isfinite(va) || !isfinite(vr)) continue;
            se[b] += (va - vr) * (va - vr);
            sd[b] += va - vr;
            sr[b] += fabs(vr);
            ns[b]++;
            counted = 1;
        }
        out->count[b] += (size_t)counted;
    }
    for (int b = 0; b < out->bins; b++) {
        double mr = ns[b] ? sr[b] / ns[b] : NAN;
        out->mean_reference[b] = mr;
        out->rel_rmse[b] = ns[b] && mr > 0 ? sqrt(se[b] / ns[b]) / mr : NAN;
        out->rel_bias[b] = ns[b] && mr > 0 ? sd[b] / ns[b] / mr : NAN;
    }
    return ATMOS_OK;
}
