/* Float images: allocation with size limits, and string metadata. */
#include "core/internal.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

atmos_status atmos_image_create(atmos_context *ctx, int width, int height, int channels,
                                atmos_image **out)
{
    if (!out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "atmos_image_create: out is NULL");
    *out = NULL;
    if (width < 1 || height < 1 || channels < 1)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "image size %d x %d x %d channels: every dimension must be at least 1",
                            width, height, channels);
    if (width > ATMOS_IMAGE_MAX_DIM || height > ATMOS_IMAGE_MAX_DIM)
        return atmos__error(ctx, ATMOS_E_LIMIT, "image size %d x %d exceeds the limit of %d pixels per side",
                            width, height, ATMOS_IMAGE_MAX_DIM);
    if (channels > ATMOS_IMAGE_MAX_CHANNELS)
        return atmos__error(ctx, ATMOS_E_LIMIT, "image has %d channels; at most %d are supported", channels,
                            ATMOS_IMAGE_MAX_CHANNELS);
    /* The per-dimension limits keep the product below 2^42 floats, but size_t may be
     * 32 bits: check the multiplication before trusting it. */
    size_t n = (size_t)width;
    if (n > SIZE_MAX / (size_t)height) goto too_big;
    n *= (size_t)height;
    if (n > SIZE_MAX / (size_t)channels) goto too_big;
    n *= (size_t)channels;
    if (n > SIZE_MAX / sizeof(float)) goto too_big;

    atmos_image *img = calloc(1, sizeof *img);
    if (!img) return atmos__error(ctx, ATMOS_E_NOMEM, "image %d x %d: out of memory", width, height);
    /* on 2 MB pages where large (a renderer's first frame then faults a few pages in, not one
     * a 4 KB page), zeroed as calloc's */
    img->pixels = atmos__big_alloc(n * sizeof(float));
    if (img->pixels) memset(img->pixels, 0, n * sizeof(float));
    if (!img->pixels) {
        free(img);
        return atmos__error(ctx, ATMOS_E_NOMEM, "image %d x %d x %d: cannot allocate %zu bytes", width,
                            height, channels, n * sizeof(float));
    }
    img->width = width;
    img->height = height;
    img->channels = channels;
    *out = img;
    return ATMOS_OK;

too_big:
    return atmos__error(ctx, ATMOS_E_LIMIT, "image %d x %d x %d is too large for this platform's address space",
                        width, height, channels);
}

void atmos_image_destroy(atmos_image *img)
{
    if (!img) return;
    for (int i = 0; i < img->meta_count; i++) {
        free(img->meta[i].key);
        free(img->meta[i].value);
    }
    free(img->meta);
    free(img->pixels);
    free(img);
}

/* strdup is POSIX, not C11. */
static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

atmos_status atmos_image_set_meta(atmos_image *img, const char *key, const char *value)
{
    if (!img || !key || !*key || !value) return ATMOS_E_INVALID_ARG;
    char *v = dup_string(value);
    if (!v) return ATMOS_E_NOMEM;
    for (int i = 0; i < img->meta_count; i++) {
        if (strcmp(img->meta[i].key, key) == 0) {
            free(img->meta[i].value);
            img->meta[i].value = v;
            return ATMOS_OK;
        }
    }
    char *k = dup_string(key);
    atmos_image_meta *grown = k ? realloc(img->meta, (size_t)(img->meta_count + 1) * sizeof *grown) : NULL;
    if (!grown) {
        free(k);
        free(v);
        return ATMOS_E_NOMEM;
    }
    img->meta = grown;
    img->meta[img->meta_count].key = k;
    img->meta[img->meta_count].value = v;
    img->meta_count++;
    return ATMOS_OK;
}

const char *atmos_image_get_meta(const atmos_image *img, const char *key)
{
    if (!img || !key) return NULL;
    for (int i = 0; i < img->meta_count; i++)
        if (strcmp(img->meta[i].key, key) == 0) return img->meta[i].value;
    return NULL;
}
