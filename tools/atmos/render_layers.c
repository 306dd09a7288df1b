/* atmos render --exr-layers (render_layers.h). */
#include "render_layers.h"
#include "cli.h"
#include "exr_names.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

int render_layers_parse(const char *list, int *mask)
{
    static const char *const names[] = {"tau", "transmittance", "order", "variance"};
    *mask = 0;
    for (const char *p = list; *p;) {
        size_t n = strcspn(p, ",");
        int found = 0;
        for (int i = 0; i < 4; i++)
            if (n == strlen(names[i]) && !strncmp(p, names[i], n)) *mask |= 1 << i, found = 1;
        if (!found)
            return cli_usage_error("render", "--exr-layers: unknown layer '%.*s' (tau, transmittance, order, variance)",
                                   (int)n, p), 0;
        p += n + (p[n] == ',');
    }
    if (!*mask) return cli_usage_error("render", "--exr-layers: no layer named"), 0;
    return 1;
}

atmos_status render_layers_tau(atmos_context *ctx, const atmos_scene *scene, const atmos_plan *plan, atmos_image **out)
{
    double offset[3], sigma[ATMOS_VOLUME_MAX_FIELDS] = {0};
    const atmos_volume *vol = atmos_plan_volume(plan, offset);
    const atmos_volume_optics *o = atmos_plan_optics(plan);
    for (int f = 0; o && f < o->count; f++) {
        int k = atmos_phase_table_wavelength_count(o->phase[f]) / 2;
        sigma[f] = atmos_phase_table_sigma_ext(o->phase[f], k) * scene->volume.density_scale;
    }
    return atmos_render_optical_depth(ctx, scene, vol, sigma, offset, out);
}

/* Copies the c channels of src into channels [at, at + c) of dst (same size); with expneg,
 * exp(-value) instead of the value. */
static void put_channels(atmos_image *dst, int at, const atmos_image *src, int expneg)
{
    const size_t n = (size_t)dst->width * dst->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < src->channels; c++) {
            const float v = src->pixels[i * src->channels + c];
            dst->pixels[i * dst->channels + at + c] = expneg ? expf(-v) : v;
        }
}

/* The layers' source images (tau, order, variance; NULL where not asked) and their channel count. */
static atmos_status layer_sources(atmos_context *ctx, const atmos_plan *plan, const atmos_scene *scene, int mask,
                                  atmos_image *src[3], int *extra)
{
    atmos_status st = ATMOS_OK;
    const int path = atmos_plan_renderer(plan) == ATMOS_RENDERER_PATH;
    if ((mask & (RENDER_LAYER_ORDER | RENDER_LAYER_VARIANCE)) && !path) {
        fprintf(stderr, "atmos render: --exr-layers: order and variance are the path tracer's layers\n");
        return ATMOS_E_INVALID_ARG;
    }
    if (mask & (RENDER_LAYER_TAU | RENDER_LAYER_TRANSMITTANCE)) st = render_layers_tau(ctx, scene, plan, &src[0]);
    if (st == ATMOS_OK && (mask & RENDER_LAYER_ORDER)) st = atmos_plan_path_order(plan, &src[1]);
    if (st == ATMOS_OK && (mask & RENDER_LAYER_VARIANCE)) st = atmos_plan_path_variance(plan, &src[2]);
    *extra = (mask & RENDER_LAYER_TAU ? 1 : 0) + (mask & RENDER_LAYER_TRANSMITTANCE ? 1 : 0) +
             (src[1] ? src[1]->channels : 0) + (src[2] ? src[2]->channels : 0);
    return st;
}

/* atmos:units of the layered image: lin's, then each layer's. */
static void layer_units(atmos_image *img, const atmos_image *lin, int mask)
{
    const char *u = atmos_image_get_meta(lin, "atmos:units");
    char buf[512];
    snprintf(buf, sizeof buf, "%s%s%s%s%s", u ? u : "", mask & RENDER_LAYER_TAU ? "; tau.Y: optical depth (1)" : "",
             mask & RENDER_LAYER_TRANSMITTANCE ? "; transmittance.Y: (1)" : "",
             mask & RENDER_LAYER_ORDER ? "; order.Y: mean number of scattering events" : "",
             mask & RENDER_LAYER_VARIANCE ? "; variance.*: " RENDER_VARIANCE_UNITS : "");
    atmos_image_set_meta(img, "atmos:units", buf);
}

void render_layers_variance_names(const atmos_wavelengths *wl, int channels, char (*buf)[40], const char **names)
{
    for (int k = 0; k < channels; k++) {
        if (k < wl->count) cli_exr_wavelength_name(buf[k], sizeof buf[k], "variance", wl->nm[k]);
        else snprintf(buf[k], sizeof buf[k], "variance.Y");
        names[k] = buf[k];
    }
}

atmos_status render_layers_build(atmos_context *ctx, const atmos_plan *plan, const atmos_scene *scene,
                                 const atmos_image *lin, int mask, atmos_image **out, const char *const **names)
{
    static char buf[4 + 3 + ATMOS_MAX_WAVELENGTHS + 2][40];
    static const char *np[4 + 3 + ATMOS_MAX_WAVELENGTHS + 2];
    atmos_image *src[3] = {NULL, NULL, NULL};
    int extra = 0, c = 4;
    *out = NULL;
    atmos_status st = layer_sources(ctx, plan, scene, mask, src, &extra);
    if (st == ATMOS_OK) st = atmos_image_create(ctx, lin->width, lin->height, 4 + extra, out);
    if (st == ATMOS_OK) {
        static const char *const rgba[4] = {"R", "G", "B", "A"};
        for (int i = 0; i < 4; i++) np[i] = rgba[i];
        put_channels(*out, 0, lin, 0);
        for (int i = 0; i < lin->meta_count; i++) atmos_image_set_meta(*out, lin->meta[i].key, lin->meta[i].value);
        if (mask & RENDER_LAYER_TAU) put_channels(*out, c, src[0], 0), np[c++] = "tau.Y";
        if (mask & RENDER_LAYER_TRANSMITTANCE) put_channels(*out, c, src[0], 1), np[c++] = "transmittance.Y";
        if (src[1]) put_channels(*out, c, src[1], 0), np[c++] = "order.Y";
        if (src[2]) {
            const atmos_wavelengths *wl = atmos_plan_wavelengths(plan);
            put_channels(*out, c, src[2], 0);
            render_layers_variance_names(wl, src[2]->channels, buf + c, np + c);
            c += src[2]->channels;
        }
        layer_units(*out, lin, mask);
        *names = np;
    }
    for (int i = 0; i < 3; i++) atmos_image_destroy(src[i]);
    return st;
}
