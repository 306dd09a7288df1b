/* atmos bench slice and atmos bench path: the volume renderers measured as an interactive
 * session uses them, one plan kept for many frames, and per frame end to end (the sky and
 * the composite included): the camera moved every frame, the sun moved every frame, and
 * nothing moved. One machine-readable line (or JSON object) per case. */
#define _POSIX_C_SOURCE 200809L
#include "bench_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The volume benchmarks' view: the volume's base at 1500 m centred above the origin
 * (offset returned), seen from 1.6 times its size, sun 35° high behind-left. */
static void bench_view(atmos_scene *scene, const atmos_volume *v, int size, double offset[3])
{
    atmos_scene_defaults(scene);
    scene->width = scene->height = size;
    scene->samples_per_pixel = 1;
    double lo[3], hi[3];
    atmos_volume_bounds(v, lo, hi);
    double ext = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
    offset[0] = -0.5 * (lo[0] + hi[0]);
    offset[1] = 1500 - lo[1];
    offset[2] = -0.5 * (lo[2] + hi[2]);
    double cy = 1500 + 0.5 * (hi[1] - lo[1]);
    double pos[3] = {0, 1500 + 0.3 * (hi[1] - lo[1]), 1.6 * ext};
    atmos_camera_defaults(ATMOS_CAMERA_PINHOLE, pos, &scene->camera);
    scene->camera.look_at[0] = 0, scene->camera.look_at[1] = cy, scene->camera.look_at[2] = 0;
    scene->camera.fov_deg = 45;
    scene->sun.from_time = 0;
    scene->sun.elevation_deg = 35;
    scene->sun.azimuth_deg = 200;
}

enum { MOVE_CAMERA, MOVE_SUN, MOVE_NOTHING };

/* Frame i of a run: the camera orbits 3° a frame, or the sun turns 3° in azimuth. */
static void step_frame(const atmos_plan *plan, const atmos_frame *start, int mode, int i, atmos_frame *f)
{
    *f = *start;
    if (mode == MOVE_CAMERA) atmos_frame_orbit(f, plan, 3.0 * i);
    if (mode == MOVE_SUN) atmos_direction_from_angles(35.0, 200.0 + 3.0 * i, f->sun_dir);
}

/* Mean seconds per frame over n frames of a mode (after one frame that is not timed), and
 * the process's CPU seconds per frame (*cpu; with OMP_WAIT_POLICY=passive the work done,
 * steadier than the wall time on a shared machine), with the timing of the last frame. */
static atmos_status run_mode(atmos_plan *plan, const atmos_frame *start, int mode, int n, atmos_image *img,
                             double *seconds, double *cpu, atmos_plan_stats *last)
{
    atmos_frame f;
    step_frame(plan, start, mode, 0, &f);
    atmos_status st = atmos_plan_render(plan, &f, NULL, img, NULL);
    const double t0 = cli_now_s();
    const clock_t c0 = clock();
    for (int i = 1; i <= n && st == ATMOS_OK; i++) {
        step_frame(plan, start, mode, i, &f); /* the start's warm_field kept */
        if (mode == MOVE_NOTHING) f.spp = start->spp + i; /* the path tracer adds a sample a frame */
        st = atmos_plan_render(plan, &f, NULL, img, NULL);
    }
    *seconds = (cli_now_s() - t0) / n;
    *cpu = (double)(clock() - c0) / CLOCKS_PER_SEC / n;
    atmos_plan_get_stats(plan, last);
    return st;
}

/* A plan for a scene of the bench view of v (bench_view); its creation time in *prepare_s. */
static atmos_status bench_plan(atmos_context *ctx, atmos_volume *v, const atmos_scene *scene, atmos_plan **plan,
                               double *prepare_s)
{
    atmos_plan_desc d;
    memset(&d, 0, sizeof d);
    d.offset_given = 1;
    atmos_scene s;
    bench_view(&s, v, scene->width, d.offset_m);
    const double t0 = cli_now_s();
    atmos_status st = atmos_plan_create(ctx, scene, v, &d, plan);
    *prepare_s = cli_now_s() - t0;
    return st;
}

static void print_slice(const char *name, const bench_slice_opts *o, double density_scale, int threads,
                        const double fps[3], const double cpu[3], const atmos_plan_stats *s,
                        const atmos_slice_timing *first, double prepare_s, const char *field)
{
    const int size = o->size, air_shadows = o->air_shadows, json = o->json;
    const atmos_slice_timing *t = &s->slice;
    const long long samples = t->eye_samples + t->light_samples;
    const double ns = samples > 0 ? 1e9 * (t->light + t->eye) / (double)samples : 0;
    const char *fmt = json ? "{\"bench\":\"slice\",\"case\":\"%s\",\"size\":%d,\"threads\":%d,\"eye\":[%d,%d],"
                             "\"fps_camera_moving\":%.3f,\"fps_sun_moving\":%.3f,\"fps_static\":%.3f,"
                             "\"ms_per_frame\":%.2f,\"ns_per_sample\":%.2f,\"setup_ms\":%.2f,\"light_ms\":%.2f,"
                             "\"eye_ms\":%.2f,\"sky_ms\":%.2f,\"prepare_ms\":%.2f,\"eye_samples\":%lld,"
                             "\"light_samples\":%lld,\"grid\":[%d,%d,%d],\"field\":\"%s\",\"field_ms\":%.2f,"
                             "\"field_sweeps\":%d,\"field_cold_ms\":%.2f,\"field_cold_sweeps\":%d,\"cpu_ms_camera_moving\":%.2f,"
                             "\"cpu_ms_sun_moving\":%.2f,\"air_shadows\":%d,\"air_shadow_ms\":%.2f,"
                             "\"density_scale\":%g,\"warm_field\":%d}\n"
                           : "bench=slice case=%s size=%d threads=%d eye=%dx%d fps_camera_moving=%.3f fps_sun_moving=%.3f "
                             "fps_static=%.3f ms_per_frame=%.2f ns_per_sample=%.2f setup_ms=%.2f light_ms=%.2f eye_ms=%.2f "
                             "sky_ms=%.2f prepare_ms=%.2f eye_samples=%lld light_samples=%lld grid=%dx%dx%d field=%s "
                             "field_ms=%.2f field_sweeps=%d field_cold_ms=%.2f field_cold_sweeps=%d cpu_ms_camera_moving=%.2f cpu_ms_sun_moving=%.2f "
                             "air_shadows=%d air_shadow_ms=%.2f density_scale=%g warm_field=%d\n";
    printf(fmt, name, size, threads, t->eye_dims[0], t->eye_dims[1], fps[MOVE_CAMERA], fps[MOVE_SUN], fps[MOVE_NOTHING],
           1e3 / fps[MOVE_SUN], ns, 1e3 * t->setup, 1e3 * t->light, 1e3 * t->eye, 1e3 * t->sky, 1e3 * prepare_s,
           t->eye_samples, t->light_samples, t->grid_dims[0], t->grid_dims[1], t->grid_dims[2], field, 1e3 * t->field,
           t->field_sweeps, 1e3 * first->field, first->field_sweeps, 1e3 * cpu[MOVE_CAMERA], 1e3 * cpu[MOVE_SUN],
           air_shadows, 1e3 * t->air_shadow, density_scale, !o->cold_field);
    fflush(stdout);
}

/* The bench view's scene of v for the slice renderer with o's settings. */
static void slice_scene(atmos_scene *scene, atmos_volume *v, double density_scale, const bench_slice_opts *o)
{
    double offset[3];
    bench_view(scene, v, o->size, offset);
    scene->renderer = ATMOS_RENDERER_SLICE;
    scene->slice.field = o->field; /* atmos_slice_field: auto (the default, do), p1 or none */
    scene->slice.air_shadows = o->air_shadows;
    scene->volume.density_scale = density_scale;
}

int bench_slice_case(atmos_context *ctx, const char *name, atmos_volume *v, double density_scale,
                     const bench_slice_opts *o)
{
    atmos_scene scene;
    atmos_plan *plan = NULL;
    atmos_image *img = NULL;
    double prepare = 0, sec[3] = {0, 0, 0}, cpu[3] = {0, 0, 0}, fps[3];
    atmos_plan_stats stats[3];
    atmos_frame start;
    slice_scene(&scene, v, density_scale, o);
    atmos_status st = bench_plan(ctx, v, &scene, &plan, &prepare);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &scene, &start);
    if (o->eye_scale > 0) start.eye_scale = o->eye_scale;
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &start, &img);
    /* the plan's first frame: the field's cold build (no warm start) */
    atmos_plan_stats first;
    memset(&first, 0, sizeof first);
    if (st == ATMOS_OK) st = atmos_plan_render(plan, &start, NULL, img, NULL);
    if (st == ATMOS_OK) atmos_plan_get_stats(plan, &first);
    start.warm_field = !o->cold_field; /* a sun move's field from the last sun's, as in the viewer */
    for (int m = 0; m < 3 && st == ATMOS_OK; m++)
        st = run_mode(plan, &start, m, o->frames, img, &sec[m], &cpu[m], &stats[m]);
    atmos_image_destroy(img);
    atmos_plan_destroy(plan);
    if (st != ATMOS_OK) return cli_runtime_error("bench", ctx, st);
    for (int m = 0; m < 3; m++) fps[m] = sec[m] > 0 ? 1.0 / sec[m] : 0;
    print_slice(name, o, density_scale, atmos_context_threads(ctx), fps, cpu, &stats[MOVE_SUN], &first.slice, prepare,
                atmos_slice_field_name(atmos_scene_slice_field(&scene.slice)));
    return CLI_EXIT_OK;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Frame i of the sun-moving run of both plans (the field's first on even i, none's on odd: neither
 * always follows the other), each frame's CPU seconds added to cpu[p]; the frame's ratio in *r. */
static atmos_status ratio_frame(atmos_plan *const plan[2], const atmos_frame *start, int i, atmos_image *img,
                                double cpu[2], double *r)
{
    double c[2] = {0, 0};
    atmos_status st = ATMOS_OK;
    for (int t = 0; t < 2 && st == ATMOS_OK; t++) {
        const int p = (i + t) % 2;
        atmos_frame f;
        step_frame(plan[p], start, MOVE_SUN, i, &f);
        const clock_t c0 = clock();
        st = atmos_plan_render(plan[p], &f, NULL, img, NULL);
        c[p] = (double)(clock() - c0) / CLOCKS_PER_SEC;
        cpu[p] += c[p];
    }
    *r = c[1] > 0 ? c[0] / c[1] : 0;
    return st;
}

int bench_slice_ratio(atmos_context *ctx, const char *name, atmos_volume *v, double density_scale,
                      const bench_slice_opts *o)
{
    atmos_scene scene;
    atmos_plan *plan[2] = {NULL, NULL};
    atmos_image *img = NULL;
    atmos_frame start;
    double prepare = 0, cpu[2] = {0, 0};
    double *r = malloc(sizeof(double) * (size_t)o->frames);
    slice_scene(&scene, v, density_scale, o);
    atmos_status st = r ? ATMOS_OK : ATMOS_E_NOMEM;
    const char *field = atmos_slice_field_name(atmos_scene_slice_field(&scene.slice));
    for (int p = 0; p < 2 && st == ATMOS_OK; p++) {
        scene.slice.field = p == 0 ? o->field : ATMOS_SLICE_FIELD_NONE;
        st = bench_plan(ctx, v, &scene, &plan[p], &prepare);
    }
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &scene, &start);
    if (o->eye_scale > 0) start.eye_scale = o->eye_scale;
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan[0], &start, &img);
    for (int p = 0; p < 2 && st == ATMOS_OK; p++) st = atmos_plan_render(plan[p], &start, NULL, img, NULL); /* untimed */
    start.warm_field = !o->cold_field;
    for (int i = 1; i <= o->frames && st == ATMOS_OK; i++) st = ratio_frame(plan, &start, i, img, cpu, &r[i - 1]);
    atmos_image_destroy(img);
    for (int p = 0; p < 2; p++) atmos_plan_destroy(plan[p]);
    if (st != ATMOS_OK) {
        free(r);
        return cli_runtime_error("bench", ctx, st);
    }
    qsort(r, (size_t)o->frames, sizeof *r, cmp_double);
    const double med = o->frames % 2 ? r[o->frames / 2] : 0.5 * (r[o->frames / 2 - 1] + r[o->frames / 2]);
    const double mf = 1e3 * cpu[0] / o->frames, mn = 1e3 * cpu[1] / o->frames;
    free(r);
    printf(o->json ? "{\"bench\":\"slice_field_ratio\",\"case\":\"%s\",\"size\":%d,\"threads\":%d,\"frames\":%d,"
                     "\"field\":\"%s\",\"cpu_ms_field\":%.2f,\"cpu_ms_none\":%.2f,\"ratio\":%.4f,"
                     "\"ratio_median\":%.4f,\"density_scale\":%g,\"warm_field\":%d}\n"
                   : "bench=slice_field_ratio case=%s size=%d threads=%d frames=%d field=%s cpu_ms_field=%.2f "
                     "cpu_ms_none=%.2f ratio=%.4f ratio_median=%.4f density_scale=%g warm_field=%d\n",
           name, o->size, atmos_context_threads(ctx), o->frames, field, mf, mn,
           mn > 0 ? mf / mn : 0, med, density_scale, !o->cold_field);
    fflush(stdout);
    return CLI_EXIT_OK;
}

/* The aerial-perspective case (atmos bench slice --aerial): the bench view of v (densities
 * times density_scale, so that the cloud is seen) rendered by slicing under each atmosphere
 * model of the list, 1 + frames frames of one plan (the first
 * not timed), the camera orbiting 3 degrees a frame (motion=camera) or the sun turning 3
 * degrees a frame (motion=sun). Per frame on average: the whole frame, the sky image, the air
 * in front of the volume (the composite's aerial perspective, its table included) and the
 * sunlight entering the light buffer; aerial_share = (aerial + sunlight) / frame,
 * atmosphere_share = (sky + aerial + sunlight) / frame; and the first frame against the
 * reference passes' (frame_difference). */
static const struct {
    const char *name;
    atmos_atmosphere_kind kind;
} aerial_models[] = {{"riley", ATMOS_ATMOSPHERE_RILEY}, {"dobashi", ATMOS_ATMOSPHERE_DOBASHI},
                     {"spherical", ATMOS_ATMOSPHERE_SPHERICAL}};

static atmos_status aerial_run(atmos_plan *plan, const atmos_frame *start, int mode, int frames, atmos_image *img,
                               double ms[4])
{
    atmos_frame f;
    atmos_plan_stats s;
    step_frame(plan, start, mode, 0, &f);
    atmos_status st = atmos_plan_render(plan, &f, NULL, img, NULL);
    for (int k = 0; k < 4; k++) ms[k] = 0;
    for (int i = 1; i <= frames && st == ATMOS_OK; i++) {
        step_frame(plan, start, mode, i, &f);
        const double t0 = cli_now_s();
        st = atmos_plan_render(plan, &f, NULL, img, NULL);
        ms[0] += 1e3 * (cli_now_s() - t0) / frames;
        atmos_plan_get_stats(plan, &s);
        ms[1] += 1e3 * (s.slice.sky - s.slice.aerial) / frames;
        ms[2] += 1e3 * s.slice.aerial / frames;
        ms[3] += 1e3 * s.slice.sunlight / frames;
    }
    return st;
}

/* The frame f of the scene's plan (fast) against a plan with the reference passes, which ask
 * the atmosphere per pixel for the air in front of the volume: over the pixel values the
 * volume changes (those that differ from the sky renderer's image), the RMS and the largest
 * relative difference. */
static atmos_status frame_difference(atmos_context *ctx, atmos_volume *v, const atmos_scene *scene,
                                     const atmos_frame *f, double *rms, double *worst)
{
    atmos_plan_desc d;
    memset(&d, 0, sizeof d);
    d.offset_given = 1;
    atmos_scene tmp;
    bench_view(&tmp, v, scene->width, d.offset_m);
    atmos_image *img[3] = {NULL, NULL, NULL};
    atmos_status st = ATMOS_OK;
    for (int r = 0; r < 3 && st == ATMOS_OK; r++) {
        atmos_scene s = *scene;
        if (r == 2) s.renderer = ATMOS_RENDERER_SKY;
        atmos_plan *p = NULL;
        d.reference = r == 1;
        st = atmos_plan_create(ctx, &s, r == 2 ? NULL : v, &d, &p);
        if (st == ATMOS_OK) st = atmos_plan_image_create(p, f, &img[r]);
        if (st == ATMOS_OK) st = atmos_plan_render(p, f, NULL, img[r], NULL);
        atmos_plan_destroy(p);
    }
    double sum2 = 0;
    long cnt = 0;
    *worst = 0;
    for (size_t i = 0; st == ATMOS_OK && i < (size_t)img[0]->width * img[0]->height * img[0]->channels; i++) {
        if ((int)(i % img[0]->channels) == img[0]->channels - 1) continue; /* alpha */
        const double a = img[0]->pixels[i], b = img[1]->pixels[i], k = img[2]->pixels[i];
        if (!(fabs(b - k) > 1e-6 * k) || !(b > 0)) continue;
        const double e = fabs(a - b) / b;
        sum2 += e * e, cnt++;
        *worst = fmax(*worst, e);
    }
    *rms = cnt ? sqrt(sum2 / cnt) : 0;
    for (int r = 0; r < 3; r++) atmos_image_destroy(img[r]);
    return st;
}

int bench_slice_aerial(atmos_context *ctx, const char *name, atmos_volume *v, int size, int frames, const char *models,
                       double density_scale, int json)
{
    for (size_t m = 0; m < sizeof aerial_models / sizeof aerial_models[0]; m++) {
        if (!cli_list_has(models ? models : "riley,spherical", aerial_models[m].name)) continue;
        atmos_scene scene;
        atmos_plan *plan = NULL;
        atmos_image *img = NULL;
        atmos_frame start;
        double offset[3], prepare = 0, ms[2][4];
        bench_view(&scene, v, size, offset);
        scene.renderer = ATMOS_RENDERER_SLICE;
        scene.atmosphere.kind = aerial_models[m].kind;
        scene.volume.density_scale = density_scale;
        atmos_status st = bench_plan(ctx, v, &scene, &plan, &prepare);
        if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &scene, &start);
        if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &start, &img);
        for (int mode = 0; mode < 2 && st == ATMOS_OK; mode++)
            st = aerial_run(plan, &start, mode == 0 ? MOVE_CAMERA : MOVE_SUN, frames, img, ms[mode]);
        atmos_image_destroy(img);
        atmos_plan_destroy(plan);
        double rms = 0, worst = 0;
        if (st == ATMOS_OK) st = frame_difference(ctx, v, &scene, &start, &rms, &worst);
        if (st != ATMOS_OK) return cli_runtime_error("bench", ctx, st);
        for (int mode = 0; mode < 2; mode++) {
            const double *t = ms[mode];
            const char *fmt =
                json ? "{\"bench\":\"slice\",\"case\":\"aerial\",\"volume\":\"%s\",\"model\":\"%s\","
                       "\"motion\":\"%s\",\"size\":%d,\"threads\":%d,\"frames\":%d,\"ms_per_frame\":%.2f,"
                       "\"sky_ms\":%.2f,\"aerial_ms\":%.2f,\"sunlight_ms\":%.2f,\"aerial_share\":%.4f,"
                       "\"atmosphere_share\":%.4f,\"frame_rms_rel\":%.2e,\"frame_max_rel\":%.2e}\n"
                     : "bench=slice case=aerial volume=%s model=%s motion=%s size=%d threads=%d frames=%d "
                       "ms_per_frame=%.2f sky_ms=%.2f aerial_ms=%.2f sunlight_ms=%.2f aerial_share=%.4f "
                       "atmosphere_share=%.4f frame_rms_rel=%.2e frame_max_rel=%.2e\n";
            printf(fmt, name, aerial_models[m].name, mode == 0 ? "camera" : "sun", size, atmos_context_threads(ctx),
                   frames, t[0], t[1], t[2], t[3], (t[2] + t[3]) / t[0], (t[1] + t[2] + t[3]) / t[0], rms, worst);
        }
        fflush(stdout);
    }
    return CLI_EXIT_OK;
}

/* The volume's pixels and their noise: in vacuum the nonzero ones; in the sky those that
 * differ from the atmosphere alone (bg) by more than 3 standard errors. rel: the mean
 * per-pixel relative standard error of the luminance; relm: that of the volume's mean. */
static long long noise(const atmos_image *img, const atmos_image *var, const atmos_image *bg, const atmos_wavelengths *wl,
                       double *rel, double *relm)
{
    const int n = wl->count, C = n + 1;
    double r = 0, sumY = 0, sumV = 0;
    long long cnt = 0;
    for (size_t p = 0; p < (size_t)img->width * img->height; p++) {
        double Y = 0, Yb = 0;
        for (int k = 0; k < n; k++) {
            Y += wl->to_xyz[k][1] * img->pixels[p * C + k];
            if (bg) Yb += wl->to_xyz[k][1] * bg->pixels[p * C + k];
        }
        const double vY = var->pixels[p * C + n];
        const int covered = bg ? fabs(Y - Yb) > 3 * sqrt(vY) + 1e-3 * Yb : Y > 0;
        if (!covered || !(Y > 0)) continue;
        r += sqrt(vY) / Y;
        sumY += Y, sumV += vY;
        cnt++;
    }
    *rel = cnt ? r / cnt : 0;
    *relm = sumY > 0 ? sqrt(sumV) / sumY : 0;
    return cnt;
}

/* The atmosphere alone for the path case's scene (the background the volume is told from). */
static atmos_status path_background(atmos_context *ctx, const atmos_scene *scene, atmos_image **bg)
{
    atmos_scene s = *scene;
    s.volume.source[0] = '\0';
    return atmos_render_scene(ctx, &s, NULL, bg, NULL);
}

/* A path case's figures: text (key=value) or one JSON object. prepare_s: making the plan
 * (medium, phase tables, optics). */
static void print_path(const char *name, int vacuum, const atmos_scene *s, int threads, const atmos_path_stats *st,
                       double prepare_s, long long cnt, double rel, double relm, const double fps[3], int json)
{
    const double t = st->trace_s;
    const char *fmt =
        json ? "{\"bench\":\"path\",\"case\":\"%s\",\"background\":\"%s\",\"size\":[%d,%d],\"spp\":%d,\"threads\":%d,"
               "\"density_scale\":%g,\"forced\":%d,\"sky_nee\":%d,\"aureole\":%d,\"paths_per_s\":%.4g,\"events_per_s\":%.4g,"
               "\"tentative_per_s\":%.4g,\"shadow_rays_per_s\":%.4g,\"events_per_path\":%.2f,\"trace_s\":%.3f,"
               "\"prepare_s\":%.3f,\"covered_pixels\":%lld,\"pixel_rel_se\":%.4f,\"t_1pct_pixel_s\":%.4g,"
               "\"mean_rel_se\":%.3g,\"t_1pct_mean_s\":%.3g,\"fps_camera_moving\":%.3f,\"fps_sun_moving\":%.3f,"
               "\"fps_static\":%.3f,\"volume_pixels\":%lld,\"volume_rel_se_mean\":%.4f,\"volume_rel_se_median\":%.4f,"
               "\"volume_rel_se_p90\":%.4f,\"cut_paths\":%lld}\n"
             : "bench=path case=%s background=%s size=%dx%d spp=%d threads=%d density_scale=%g forced=%d sky_nee=%d "
               "aureole=%d paths_per_s=%.4g events_per_s=%.4g tentative_per_s=%.4g shadow_rays_per_s=%.4g "
               "events_per_path=%.2f trace_s=%.3f prepare_s=%.3f covered_pixels=%lld pixel_rel_se=%.4f "
               "t_1pct_pixel_s=%.4g mean_rel_se=%.3g t_1pct_mean_s=%.3g fps_camera_moving=%.3f fps_sun_moving=%.3f "
               "fps_static=%.3f volume_pixels=%lld volume_rel_se_mean=%.4f volume_rel_se_median=%.4f "
               "volume_rel_se_p90=%.4f cut_paths=%lld\n";
    printf(fmt, name, vacuum ? "vacuum" : "sky", s->width, s->height, st->spp, threads, s->volume.density_scale,
           s->path.forced, s->path.sky_nee, s->path.aureole, st->paths / t, st->events / t, st->tentative / t,
           st->shadow_rays / t, (double)st->events / (double)st->paths, t, prepare_s, cnt, rel,
           t * (rel / 0.01) * (rel / 0.01), relm, t * (relm / 0.01) * (relm / 0.01), fps[MOVE_CAMERA], fps[MOVE_SUN],
           fps[MOVE_NOTHING], st->volume_pixels, st->volume_rel_error_mean, st->volume_rel_error_median,
           st->volume_rel_error_p90, st->cut_paths);
    fflush(stdout);
}

int bench_path_case(atmos_context *ctx, const char *name, atmos_volume *v, const bench_path_opts *o, int vacuum)
{
    atmos_scene scene;
    atmos_plan *plan = NULL;
    atmos_image *img = NULL, *var = NULL, *bg = NULL;
    double prepare = 0, sec[3] = {0, 0, 0}, fps[3], rel = 0, relm = 0;
    atmos_plan_stats stats, ms;
    atmos_frame f;
    long long cnt = 0;
    double offset[3];
    bench_view(&scene, v, o->size, offset);
    scene.renderer = ATMOS_RENDERER_PATH;
    scene.atmosphere.kind = vacuum ? ATMOS_ATMOSPHERE_VACUUM : ATMOS_ATMOSPHERE_RILEY;
    scene.volume.density_scale = o->density_scale;
    scene.path.spp = o->spp;
    scene.path.forced = !o->no_forced, scene.path.sky_nee = !o->no_sky_nee, scene.path.aureole = !o->no_aureole;
    atmos_status st = bench_plan(ctx, v, &scene, &plan, &prepare);
    if (st == ATMOS_OK) st = atmos_frame_from_scene(ctx, &scene, &f);
    if (st == ATMOS_OK) st = atmos_plan_image_create(plan, &f, &img);
    if (st == ATMOS_OK) st = atmos_plan_render(plan, &f, NULL, img, NULL);
    if (st == ATMOS_OK) atmos_plan_get_stats(plan, &stats), st = atmos_plan_path_variance(plan, &var);
    if (st == ATMOS_OK && !vacuum) st = path_background(ctx, &scene, &bg);
    if (st == ATMOS_OK) cnt = noise(img, var, bg, atmos_plan_wavelengths(plan), &rel, &relm);
    f.spp = 1; /* interactive frames: one sample per pixel, the static ones adding one each */
    double cpu_path[3];
    for (int m = 0; m < 3 && st == ATMOS_OK; m++) st = run_mode(plan, &f, m, 4, img, &sec[m], &cpu_path[m], &ms);
    atmos_image_destroy(img), atmos_image_destroy(var), atmos_image_destroy(bg);
    atmos_plan_destroy(plan);
    if (st != ATMOS_OK) return cli_runtime_error("bench", ctx, st);
    for (int m = 0; m < 3; m++) fps[m] = sec[m] > 0 ? 1.0 / sec[m] : 0;
    print_path(name, vacuum, &scene, atmos_context_threads(ctx), &stats.path, prepare, cnt, rel, relm, fps, o->json);
    return CLI_EXIT_OK;
}
