/* Which channels of two images to compare, paired by name (atmos_image_match_channels):
 * a comparison must never pair B with R because one file lists its channels in another
 * order, nor compare different quantities because two images have as many channels. */
#include "core/internal.h"
#include "image/channel_names.h"

#include <stdio.h>
#include <string.h>

static int find(const char *const *names, int count, const char *name)
{
    for (int i = 0; i < count; i++)
        if (names[i] && strcmp(names[i], name) == 0) return i;
    return -1;
}

/* The non-alpha channels: their indices, and how many. */
static int light_channels(const char *const *names, int count, int *idx)
{
    int n = 0;
    for (int i = 0; i < count; i++)
        if (!atmos__is_alpha_channel(names[i])) idx[n++] = i;
    return n;
}

static void list_names(const char *const *names, int count, char *buf, size_t cap)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int i = 0; i < count && used + 1 < cap; i++) {
        int n = snprintf(buf + used, cap - used, "%s%s", i ? "," : "", names[i]);
        if (n < 0) break;
        used += (size_t)n;
    }
    if (used >= cap && cap > 4) memcpy(buf + cap - 4, "...", 4);
}

static atmos_status mismatch(atmos_context *ctx, const char *const *na, int ca, const char *const *nr, int cr)
{
    char la[160], lr[160];
    list_names(na, ca, la, sizeof la);
    list_names(nr, cr, lr, sizeof lr);
    return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                        "compare: the channels do not pair by name: the image has %s, the reference has %s", la, lr);
}

atmos_status atmos_image_match_channels(atmos_context *ctx, const char *const *na, int ca, const char *const *nr,
                                        int cr, atmos_channel_match *out)
{
    if (!na || !nr || !out || ca < 1 || cr < 1 || ca > ATMOS_IMAGE_MAX_CHANNELS || cr > ATMOS_IMAGE_MAX_CHANNELS)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing channel names");
    for (int i = 0; i < ca; i++)
        if (!na[i]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing channel names");
    for (int i = 0; i < cr; i++)
        if (!nr[i]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "compare: missing channel names");
    memset(out, 0, sizeof *out);
    int rgb_a[4], rgb_r[4];
    if (atmos__rgb_channels(na, ca, rgb_a) && atmos__rgb_channels(nr, cr, rgb_r)) {
        out->count = 3;
        for (int c = 0; c < 3; c++) out->image[c] = rgb_a[c], out->reference[c] = rgb_r[c];
        return ATMOS_OK;
    }
    int la[ATMOS_IMAGE_MAX_CHANNELS], lr[ATMOS_IMAGE_MAX_CHANNELS];
    int n = light_channels(na, ca, la), m = light_channels(nr, cr, lr);
    if (n < 1 || n != m) return mismatch(ctx, na, ca, nr, cr);
    int same = 1;
    for (int i = 0; i < n && same; i++) {
        int j = find(nr, cr, na[la[i]]);
        same = j >= 0 && !atmos__is_alpha_channel(nr[j]);
        if (same && i < ATMOS_IMAGE_DIFF_MAX_CHANNELS) out->image[i] = la[i], out->reference[i] = j;
    }
    if (!same) {
        if (n == 1) goto pair;
        return mismatch(ctx, na, ca, nr, cr);
    }
    if (n > ATMOS_IMAGE_DIFF_MAX_CHANNELS)
        return atmos__error(ctx, ATMOS_E_UNSUPPORTED, "compare: at most %d channels, got %d", ATMOS_IMAGE_DIFF_MAX_CHANNELS, n);
    out->count = n;
    return ATMOS_OK;
pair: /* one channel each, named differently (a grey PFM's "Y" and an EXR's "C0") */
    out->count = 1;
    out->image[0] = la[0];
    out->reference[0] = lr[0];
    return ATMOS_OK;
}
