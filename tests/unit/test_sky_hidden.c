/* The sky renderer's hidden pixels (atmos__sky_render_hidden, src/render/sky_render.c; the beam
 * renderer's sky behind its surfaces, docs/beams.md): on the grid of every sky_step pixels, the
 * round planet's low sun in view over the horizon, with the lower half of the image and blocks
 * of the upper half marked hidden:
 *   - every pixel not hidden is the same, bit for bit, as atmos__sky_render's;
 *   - a hidden pixel is finite with alpha 1, and some hidden pixels (in the grid's cells
 *     evaluated pixel by pixel: the horizon, the sun) are read from the grid instead, so differ;
 *   - the same bits on one thread and on two. */
#include "atmos/atmos.h"
#include "render/view.h"
#include "test.h"

#include <stdlib.h>

#define W 256
#define H 160

static atmos_image *render(int threads, const unsigned char *hidden)
{
    atmos_context_desc cd;
    atmos_context_defaults(&cd);
    cd.threads = threads, cd.log = NULL;
    atmos_context *ctx = NULL;
    CHECK_OK(atmos_context_create(&cd, &ctx));
    atmos_atmosphere_desc desc;
    atmos_atmosphere_defaults(&desc);
    desc.kind = ATMOS_ATMOSPHERE_SPHERICAL;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_atmosphere *atm = NULL;
    CHECK_OK(atmos_atmosphere_create(ctx, &desc, &wl, &atm));
    atmos__view v;
    memset(&v, 0, sizeof v);
    atmos_camera_desc cam;
    const double pos[3] = {0, 1500, 0};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &cam);
    double dir[3];
    atmos_direction_from_angles(2, 200, dir);
    for (int a = 0; a < 3; a++) cam.look_at[a] = pos[a] + 1000 * dir[a];
    cam.fov_deg = 50;
    CHECK_OK(atmos_camera_init(ctx, &cam, W, H, &v.cam));
    atmos_direction_from_angles(4, 210, v.sun);
    v.samples_per_pixel = 1, v.sky_step = 4;
    atmos_image *img = NULL;
    CHECK_OK(atmos_image_create(ctx, W, H, wl.count + 1, &img));
    const atmos__rect r = {0, 0, W, H};
    CHECK_OK(atmos__sky_render_hidden(ctx, atm, &v, &r, img, NULL, hidden));
    atmos_atmosphere_destroy(atm);
    atmos_context_destroy(ctx);
    return img;
}

int main(void)
{
    unsigned char *hidden = malloc(W * H);
    CHECK(hidden != NULL);
    if (!hidden) return test_summary("test_sky_hidden");
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) hidden[y * W + x] = y >= H / 2 || ((x / 24 + y / 24) % 2 && (x / 7) % 3);
    atmos_image *ref = render(1, NULL), *one = render(1, hidden), *two = render(2, hidden);
    if (!ref || !one || !two) return test_summary("test_sky_hidden");
    const int C = ref->channels;
    long shown_diff = 0, hidden_n = 0, hidden_diff = 0, bad = 0;
    for (int i = 0; i < W * H; i++) {
        const float *a = ref->pixels + (size_t)i * C, *b = one->pixels + (size_t)i * C;
        const int differ = memcmp(a, b, sizeof(float) * C) != 0;
        if (!hidden[i]) {
            shown_diff += differ;
            continue;
        }
        hidden_n++, hidden_diff += differ;
        for (int k = 0; k < C; k++) bad += !isfinite(b[k]) || b[k] < 0;
        bad += b[C - 1] != 1.0f;
    }
    printf("hidden pixels %ld, read from the grid (differing) %ld; shown pixels differing %ld\n", hidden_n, hidden_diff,
           shown_diff);
    CHECK_MSG(shown_diff == 0, "%ld pixels not hidden differ from the sky renderer's", shown_diff);
    CHECK_MSG(bad == 0, "%ld values of hidden pixels not finite, negative or alpha not 1", bad);
    CHECK_MSG(hidden_diff > 0, "no hidden pixel was read from the grid");
    CHECK_MSG(!memcmp(one->pixels, two->pixels, sizeof(float) * (size_t)W * H * C), "1 and 2 threads differ");
    atmos_image_destroy(ref), atmos_image_destroy(one), atmos_image_destroy(two);
    free(hidden);
    return test_summary("test_sky_hidden");
}
