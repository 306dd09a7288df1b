/* atmos bench beams: the beam renderer's frame rate (Dobashi et al. 2002 §4, docs/beams.md)
 * on the Fig. 4 scene (a sphere under a spotlight, 300x450) and on variants of it: without
 * sub-planes (at the scene's plane spacing, 0.3 m and 0.1 m), with a coarser epsilon, with
 * interleaved sampling instead of sub-planes (Keller and Heidrich 2001: 2x2 and 3x3), with two
 * and four lights (the spot copied around the first), and at twice the size; then the studio
 * of Fig. 9(a), the stained glass of Fig. 9(b), the searchlights and the mountains of Fig. 10(a) at Table 1's 720x480. Each case makes one plan (objects, shadow maps, the scattering table) and renders
 * frames with the camera moving round the sphere (a degree a frame): what interactive use
 * pays per frame. */
#include "bench_beams.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

typedef struct beams_case {
    const char *name;
    int lights, scale, subplanes;
    double spacing_m, epsilon; /* 0: the scene's */
    int interleave;            /* 0: the scene's */
} beams_case;

static int run_case(atmos_context *ctx, const atmos_scene *base, const beams_case *c, int frames, int threads)
{
    atmos_scene s = *base;
    s.width *= c->scale, s.height *= c->scale;
    if (!c->subplanes) s.beams.max_subplanes = 1;
    if (c->spacing_m > 0) s.beams.plane_spacing_m = c->spacing_m;
    if (c->epsilon > 0) s.beams.epsilon = c->epsilon;
    if (c->interleave > 0) s.beams.interleave = c->interleave;
    for (int i = 1; base->light_count > 0 && i < c->lights && i < ATMOS_SCENE_MAX_LIGHTS; i++) { /* copies of the first */
        s.lights[i] = s.lights[0];
        s.lights[i].position_m[0] += 6 * cos(2 * 3.14159265358979 * i / c->lights);
        s.lights[i].position_m[2] += 6 * sin(2 * 3.14159265358979 * i / c->lights);
    }
    if (base->light_count > 0 && c->lights > s.light_count) s.light_count = c->lights; /* a sun-only scene: as it is */
    atmos_plan *plan = NULL;
    atmos_frame f;
    atmos_image *img = NULL;
    double t0 = cli_now_s();
    atmos_status st = atmos_plan_create(ctx, &s, NULL, NULL, &plan);
    const double plan_s = cli_now_s() - t0;
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &s, &f);
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &f, &img);
    double total = 0, best = 1e30, cpu = 0;
    for (int i = 0; st == ATMOS_OK && i < frames; i++) {
        atmos_frame_orbit(&f, plan, 1.0);
        t0 = cli_now_s();
        const clock_t c0 = clock();
        st = atmos_plan_render(plan, &f, NULL, img, NULL);
        const double t = cli_now_s() - t0;
        cpu += (double)(clock() - c0) / CLOCKS_PER_SEC;
        total += t, best = t < best ? t : best;
    }
    int rc = CLI_EXIT_OK;
    if (st != ATMOS_OK) rc = cli_runtime_error("bench", ctx, st);
    else
        printf("bench=beams scene=%s size=%dx%d lights=%d subplanes=%s plane_spacing_m=%g epsilon=%g interleave=%d threads=%d frames=%d "
               "plan_seconds=%.3f frame_ms=%.1f best_ms=%.1f cpu_ms=%.1f fps=%.1f\n",
               c->name, s.width, s.height, s.light_count, c->subplanes ? "on" : "off", s.beams.plane_spacing_m,
               s.beams.epsilon, s.beams.interleave, threads, frames, plan_s, 1e3 * total / frames, 1e3 * best, 1e3 * cpu / frames,
               frames / total);
    fflush(stdout);
    atmos_image_destroy(img);
    atmos_plan_destroy(plan);
    return rc;
}

/* A scene of the source tree not found (no --file): where they are read from, and the way out. */
static int scene_error(atmos_context *ctx, atmos_status st, const char *file)
{
    const int rc = cli_runtime_error("bench", ctx, st);
    if (!file && st == ATMOS_E_IO)
        fprintf(stderr, "  (atmos bench beams reads the source tree's scenes/ folder: run it from the source tree, "
                        "or pass --file SCENE)\n");
    return rc;
}

int bench_beams(const char *file, int frames, int threads, const char *only)
{
    const char *path = file ? file : "scenes/dobashi_fig04_spotlight.json";
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_scene s;
    atmos_status st = atmos_scene_load(ctx, path, &s);
    if (st == ATMOS_OK && s.renderer != ATMOS_RENDERER_BEAMS)
        st = ATMOS_E_INVALID_ARG, fprintf(stderr, "atmos bench: %s: not a beams scene\n", path);
    int rc = st == ATMOS_OK ? CLI_EXIT_OK : scene_error(ctx, st, file);
    static const beams_case cases[] = {
        {"dobashi_fig04", 1, 1, 1, 0, 0, 0},
        {"dobashi_fig04_no_subplanes", 1, 1, 0, 0, 0, 0},
        {"dobashi_fig04_no_subplanes_0.3m", 1, 1, 0, 0.3, 0, 0},
        {"dobashi_fig04_no_subplanes_0.1m", 1, 1, 0, 0.1, 0, 0},
        {"dobashi_fig04_epsilon_0.03", 1, 1, 1, 0, 0.03, 0},
        {"dobashi_fig04_interleaved_2", 1, 1, 0, 0, 0, 2},
        {"dobashi_fig04_interleaved_3", 1, 1, 0, 0, 0, 3},
        {"dobashi_fig04_interleaved_3_0.3m", 1, 1, 0, 0.3, 0, 3},
        {"dobashi_fig04_2_lights", 2, 1, 1, 0, 0, 0},
        {"dobashi_fig04_4_lights", 4, 1, 1, 0, 0, 0},
        {"dobashi_fig04_double_size", 1, 2, 1, 0, 0, 0},
    };
    const int used = atmos_context_threads(ctx);
    int ran = 0;
    for (size_t i = 0; rc == CLI_EXIT_OK && i < sizeof cases / sizeof *cases; i++)
        if (!only || !strcmp(only, cases[i].name)) rc = run_case(ctx, &s, &cases[i], frames, used), ran++;
    /* without a file: the other scenes as they are (Table 1's size, 720x480) */
    static const char *const table1[][2] = {{"dobashi_fig09a_studio", "scenes/dobashi_fig09a_studio.json"},
                                            {"dobashi_fig09b_stained_glass", "scenes/dobashi_fig09b_stained_glass.json"},
                                            {"searchlights_fog", "scenes/searchlights_fog.json"},
                                            {"dobashi_fig10a_mountain_shafts", "scenes/dobashi_fig10a_mountain_shafts.json"}};
    for (size_t i = 0; !file && rc == CLI_EXIT_OK && i < sizeof table1 / sizeof *table1; i++) {
        const beams_case c = {table1[i][0], 0, 1, 1, 0, 0, 0};
        if (only && strcmp(only, c.name)) continue;
        ran++;
        if ((st = atmos_scene_load(ctx, table1[i][1], &s)) != ATMOS_OK) rc = scene_error(ctx, st, file);
        else rc = run_case(ctx, &s, &c, frames, used);
    }
    atmos_context_destroy(ctx);
    if (rc == CLI_EXIT_OK && only && !ran) {
        fprintf(stderr, "atmos bench: no beams case is named '%s'%s\n", only, file ? " (with --file: the dobashi_fig04 cases)" : "");
        return CLI_EXIT_USAGE;
    }
    return rc;
}
