/* The Nishita renderer's discrete-ordinates field after a sun move (docs/lightfield.md, "A
 * discrete-ordinates field"): one plan of SCENE (--renderer nishita, --nishita-orders 1,
 * --no-nishita-sky, --nishita-mc-lmax 3, --nishita-mc-delta-m, --nishita-do, a black background),
 * a frame with the scene's sun, then MOVES frames each with the sun DEG degrees further in azimuth
 * and the field warm-started from the last sun's (atmos_frame.warm_field), then one more such
 * frame built afresh; per frame the field's line of the image's atmos:nishita metadata (GMRES
 * iterations, sweeps, wall and CPU seconds of the solve).
 *
 *   atmos_do_sunmove SCENE.json [THREADS [DEG [MOVES]]]   (defaults 2, 2, 2) */
#include "atmos/atmos.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int frame(atmos_context *ctx, atmos_plan *p, const atmos_scene *s, double az, int warm)
{
    atmos_scene t = *s;
    t.sun.from_time = 0, t.sun.azimuth_deg = az;
    atmos_frame f;
    atmos_image *img = NULL;
    if (atmos_frame_from_scene(ctx, &t, &f) != ATMOS_OK) return 0;
    f.warm_field = warm;
    if (atmos_plan_image_create(p, &f, &img) != ATMOS_OK) return 0;
    const int ok = atmos_plan_render(p, &f, NULL, img, NULL) == ATMOS_OK;
    const char *m = ok ? atmos_image_get_meta(img, "atmos:nishita") : NULL, *at = m ? strstr(m, "discrete") : NULL;
    if (ok) printf("sun azimuth %.2f deg, %s: %s\n", az, warm ? "warm" : "afresh", at ? at : "(no field)");
    atmos_image_destroy(img);
    return ok;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: atmos_do_sunmove SCENE.json [THREADS [DEG [MOVES]]]\n");
        return 2;
    }
    const int threads = argc > 2 ? atoi(argv[2]) : 2, moves = argc > 4 ? atoi(argv[4]) : 2;
    const double deg = argc > 3 ? atof(argv[3]) : 2;
    atmos_context *ctx = NULL;
    atmos_context_desc d;
    atmos_context_defaults(&d);
    d.threads = threads;
    if (atmos_context_create(&d, &ctx) != ATMOS_OK) return 1;
    const char *ov[] = {"background=\"black\"", "renderer=\"nishita\"", "nishita.orders=1", "nishita.sky=false",
                        "nishita.mc_lmax=3",    "nishita.mc_delta_m=true", "nishita.do=true"};
    atmos_scene s;
    atmos_volume *v = NULL;
    atmos_plan *p = NULL;
    atmos_plan_desc pd;
    memset(&pd, 0, sizeof pd);
    pd.offset_given = 1;
    int ok = atmos_scene_load_with(ctx, argv[1], ov, 7, &s) == ATMOS_OK &&
             atmos_scene_load_volume(ctx, &s, &v, pd.offset_m) == ATMOS_OK &&
             atmos_plan_create(ctx, &s, v, &pd, &p) == ATMOS_OK;
    const double az0 = s.sun.azimuth_deg;
    ok = ok && frame(ctx, p, &s, az0, 0);
    for (int i = 1; i <= moves && ok; i++) ok = frame(ctx, p, &s, az0 + i * deg, 1);
    ok = ok && frame(ctx, p, &s, az0 + (moves + 1) * deg, 0);
    if (!ok) fprintf(stderr, "atmos_do_sunmove: %s\n", atmos_context_error(ctx));
    atmos_plan_destroy(p);
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return ok ? 0 : 1;
}
