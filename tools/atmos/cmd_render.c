/* atmos render: a scene file (or the built-in default) to PNG / EXR / PFM. The options
 * (render_opts.c) become a scene; the scene becomes one plan; every frame of its animation
 * is rendered from that plan (atmos_plan_render, the same call atmos_render_scene makes). */
#define _POSIX_C_SOURCE 200809L /* getpid */
#include "render_opts.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Temporary names of the outputs (atmos__write_atomic writes PATH.tmpPID): on SIGINT or
 * SIGTERM they are removed before exiting, so an interrupted run leaves nothing behind. */
static char tmp_names[3][4200];
static void on_signal(int sig)
{
    for (int i = 0; i < 3; i++)
        if (tmp_names[i][0]) unlink(tmp_names[i]); /* async-signal-safe */
    signal(sig, SIG_DFL);
    raise(sig);
}

static void protect_outputs(const char *png, const char *exr, const char *pfm)
{
    const char *outs[3] = {png, exr, pfm};
    for (int i = 0; i < 3; i++) {
        tmp_names[i][0] = '\0';
        if (outs[i]) snprintf(tmp_names[i], sizeof tmp_names[i], "%s.tmp%ld", outs[i], (long)getpid());
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
}

/* The name of frame `frame` (1-based) of an animation: "_0001" before the extension of
 * the file name (out/sky.png -> out/sky_0001.png; no extension: appended). digits >= 4. */
static int frame_name(const char *base, int frame, int digits, char *buf, size_t cap)
{
    const char *slash = strrchr(base, '/'), *dot = strrchr(base, '.');
    size_t stem = dot && dot > (slash ? slash : base) && dot[1] ? (size_t)(dot - base) : strlen(base);
    int n = snprintf(buf, cap, "%.*s_%0*d%s", (int)stem, base, digits, frame, base + stem);
    return n > 0 && (size_t)n < cap;
}

static void default_png_name(const char *scene_name, char *buf, size_t cap)
{
    size_t j = 0;
    for (size_t i = 0; scene_name[i] && j + 5 < cap; i++) {
        char c = scene_name[i];
        buf[j++] = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ? c : '_';
    }
    if (j == 0) buf[j++] = 'a', buf[j++] = 't', buf[j++] = 'm', buf[j++] = 'o', buf[j++] = 's';
    snprintf(buf + j, cap - j, ".png");
}

/* The output files of one frame: the option's names, numbered in an animation. */
typedef struct {
    const char *png, *exr, *pfm, *var, *ord;
    char buf[5][4200];
} frame_files;

static int name_frame_files(const render_opts *o, const char *png, int frame, int nframes, frame_files *ff)
{
    const char *base[5] = {png, o->exr, o->pfm, o->variance, o->order};
    const char **dst[5] = {&ff->png, &ff->exr, &ff->pfm, &ff->var, &ff->ord};
    int digits = 4;
    for (int n = nframes; n >= 10000; n /= 10) digits++;
    for (int i = 0; i < 5; i++) {
        *dst[i] = base[i];
        if (!base[i] || nframes < 2) continue;
        if (!frame_name(base[i], frame, digits, ff->buf[i], sizeof ff->buf[i])) return 0;
        *dst[i] = ff->buf[i];
    }
    return 1;
}

/* The volume's optical depth along each pixel's ray at the middle wavelength of the set,
 * as a 1-channel PFM. */
static atmos_status write_tau(atmos_context *ctx, const atmos_scene *scene, const atmos_plan *plan, const char *path)
{
    double offset[3], sigma[ATMOS_VOLUME_MAX_FIELDS] = {0};
    const atmos_volume *vol = atmos_plan_volume(plan, offset);
    const atmos_volume_optics *o = atmos_plan_optics(plan);
    for (int f = 0; o && f < o->count; f++) {
        int k = atmos_phase_table_wavelength_count(o->phase[f]) / 2;
        sigma[f] = atmos_phase_table_sigma_ext(o->phase[f], k) * scene->volume.density_scale;
    }
    atmos_image *img = NULL;
    atmos_status st = atmos_render_optical_depth(ctx, scene, vol, sigma, offset, &img);
    if (st == ATMOS_OK) st = atmos_write_pfm(ctx, img, path);
    atmos_image_destroy(img);
    return st;
}

/* The path tracer's variance (channels var_<nm>nm, then var_Y) and order images. */
static atmos_status write_path_aux(atmos_context *ctx, const atmos_plan *plan, const frame_files *ff, const char *source)
{
    const atmos_wavelengths *wl = atmos_plan_wavelengths(plan);
    atmos_image *img = NULL;
    atmos_status st = ATMOS_OK;
    if (ff->var && (st = atmos_plan_path_variance(plan, &img)) == ATMOS_OK) {
        static char names[ATMOS_MAX_WAVELENGTHS + 1][24];
        const char *np[ATMOS_MAX_WAVELENGTHS + 1];
        for (int k = 0; k < wl->count; k++) {
            snprintf(names[k], sizeof names[k], "var_%.1fnm", wl->nm[k]);
            np[k] = names[k];
        }
        np[wl->count] = "var_Y";
        atmos_exr_desc ed = {0, np};
        atmos_image_set_meta(img, "atmos:source", source);
        st = atmos_write_exr(ctx, img, ff->var, &ed);
        atmos_image_destroy(img);
        img = NULL;
    }
    if (st == ATMOS_OK && ff->ord && (st = atmos_plan_path_order(plan, &img)) == ATMOS_OK) {
        atmos_image_set_meta(img, "atmos:source", source);
        st = atmos_write_pfm(ctx, img, ff->ord);
        atmos_image_destroy(img);
    }
    return st;
}

/* The outputs of a rendered frame: linear sRGB to EXR and PFM, tone-mapped to PNG. */
static atmos_status write_outputs(atmos_context *ctx, const atmos_plan *plan, const atmos_scene *fs,
                                  const atmos_image *spec, const frame_files *ff, const char *source, const char *frame)
{
    atmos_image *lin = NULL, *disp = NULL;
    atmos_status st = atmos_image_to_srgb(ctx, spec, atmos_plan_wavelengths(plan), &lin);
    if (st != ATMOS_OK) return st;
    atmos_image_set_meta(lin, "atmos:source", source);
    if (frame) atmos_image_set_meta(lin, "atmos:frame", frame);
    if (ff->exr) {
        atmos_exr_desc ed = {fs->exr_half, NULL};
        st = atmos_write_exr(ctx, lin, ff->exr, &ed);
    }
    if (st == ATMOS_OK && ff->pfm) st = atmos_write_pfm(ctx, lin, ff->pfm);
    if (st == ATMOS_OK && atmos_plan_renderer(plan) == ATMOS_RENDERER_PATH) st = write_path_aux(ctx, plan, ff, source);
    if (st == ATMOS_OK && ff->png) {
        char buf[64];
        snprintf(buf, sizeof buf, "%.6g", atmos_tonemap_scale(lin, &fs->tonemap));
        atmos_image_set_meta(lin, "atmos:exposure_scale", buf);
        st = atmos_tonemap(ctx, lin, &fs->tonemap, &disp);
        if (st == ATMOS_OK) st = atmos_write_png(ctx, disp, ff->png, fs->png_bits ? fs->png_bits : 8);
    }
    atmos_image_destroy(lin);
    atmos_image_destroy(disp);
    return st;
}

static void report_frame(const atmos_plan *plan, const atmos_scene *fs, const frame_files *ff, const char *source,
                         const atmos_render_info *info, int frame, int nframes, const char *tau)
{
    if (nframes > 1) fprintf(stderr, "atmos render: frame %d/%d: ", frame, nframes);
    else fprintf(stderr, "atmos render: ");
    fprintf(stderr, "%s, %dx%d, sun at %.2f deg elevation / %.2f deg azimuth, %.3f s\n", source, fs->width, fs->height,
            info->sun_elevation_deg, info->sun_azimuth_deg, info->seconds);
    const char *files[5] = {ff->png, ff->exr, ff->pfm, ff->var, ff->ord};
    for (int i = 0; i < 5; i++)
        if (files[i]) fprintf(stderr, "  wrote %s\n", files[i]);
    if (atmos_plan_renderer(plan) == ATMOS_RENDERER_PATH) {
        atmos_plan_stats ps;
        atmos_plan_get_stats(plan, &ps);
        const atmos_path_stats *q = &ps.path;
        if (q->volume_pixels > 0)
            fprintf(stderr,
                    "  path: %d spp, %lld scattering events; relative standard error over the volume's %lld pixels: "
                    "mean %.2f %%, median %.2f %%, 90th percentile %.2f %% (over all pixels: mean %.2f %%)\n",
                    q->spp, q->events, q->volume_pixels, 100.0 * q->volume_rel_error_mean,
                    100.0 * q->volume_rel_error_median, 100.0 * q->volume_rel_error_p90, 100.0 * q->mean_rel_error);
        else
            fprintf(stderr, "  path: %d spp, %lld scattering events, mean relative standard error %.2f %%\n", q->spp,
                    q->events, 100.0 * q->mean_rel_error);
        if (ps.path.truncate_deg > 0)
            fprintf(stderr, "  path: forward peak truncated at %g deg: %.3f-%.3f of the scattering counted as unscattered\n",
                    ps.path.truncate_deg, ps.path.truncated_min, ps.path.truncated_max);
    }
    if (frame == 1 && tau) fprintf(stderr, "  wrote %s\n", tau);
}

/* Every frame of the scene's animation from the one plan. Returns a status; *failed_frame
 * names the frame that failed (0: before any). */
static atmos_status render_frames(atmos_context *ctx, atmos_plan *plan, const atmos_scene *scene, const render_opts *o,
                                  const char *png, const char *source, cli_progress *prog, int *failed_frame)
{
    const int nframes = scene->animation.frames > 1 ? scene->animation.frames : 1;
    atmos_image *spec = NULL;
    atmos_status st = ATMOS_OK;
    double total = 0;
    for (int frame = 1; frame <= nframes && st == ATMOS_OK; frame++) {
        *failed_frame = frame;
        static frame_files ff;
        atmos_scene fs;
        atmos_frame f;
        atmos_render_info info;
        char label[64];
        snprintf(label, sizeof label, "%d/%d", frame, nframes);
        if ((st = atmos_scene_animation_frame(ctx, scene, frame - 1, &fs)) != ATMOS_OK) break;
        if (!name_frame_files(o, png, frame, nframes, &ff)) {
            fprintf(stderr, "atmos render: an output path is too long for numbered frames\n");
            return ATMOS_E_INVALID_ARG;
        }
        protect_outputs(ff.png, ff.exr, ff.pfm);
        if ((st = atmos_frame_from_scene(ctx, &fs, &f)) != ATMOS_OK) break;
        if (!spec && (st = atmos_plan_image_create(plan, &f, &spec)) != ATMOS_OK) break;
        if ((st = atmos_plan_render(plan, &f, NULL, spec, &info)) != ATMOS_OK) break;
        if ((st = write_outputs(ctx, plan, &fs, spec, &ff, source, nframes > 1 ? label : NULL)) != ATMOS_OK) break;
        total += info.seconds;
        if (!o->quiet) {
            if (prog->shown) fputc('\n', stderr), prog->shown = 0;
            report_frame(plan, &fs, &ff, source, &info, frame, nframes, o->tau);
        }
    }
    atmos_image_destroy(spec);
    if (st == ATMOS_OK && !o->quiet && nframes > 1)
        fprintf(stderr, "atmos render: %d frames, %.3f s rendering (one plan: the volume and its optics made once)\n",
                nframes, total);
    return st;
}

/* The scene: the file or the default, the options applied, validated. Returns CLI_EXIT_OK
 * or the exit status of the failure (message printed). */
static int make_scene(atmos_context *ctx, const render_opts *o, atmos_scene *scene)
{
    atmos_status st;
    if (o->scene_path) {
        if ((st = atmos_scene_load(ctx, o->scene_path, scene)) != ATMOS_OK) return cli_runtime_error("render", ctx, st);
    } else {
        atmos_scene_defaults(scene);
    }
    int rc = render_opts_apply(ctx, o, scene);
    if (rc != CLI_EXIT_OK) return rc;
    if ((st = atmos_scene_validate(ctx, scene, o->scene_path ? o->scene_path : "options")) != ATMOS_OK) {
        fprintf(stderr, "atmos render: %s\n", atmos_context_error(ctx));
        return o->scene_path ? CLI_EXIT_RUNTIME : CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

int cli_cmd_render(int argc, char **argv)
{
    render_opts o;
    int rc = render_opts_parse(argc, argv, &o);
    if (rc < 0) return CLI_EXIT_OK; /* --help */
    if (rc != CLI_EXIT_OK) return rc;
    cli_progress prog;
    cli_progress_init(&prog, o.quiet);
    atmos_context *ctx = cli_context_with_progress(o.threads, o.quiet, cli_progress_bar, &prog);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_scene scene;
    if ((rc = make_scene(ctx, &o, &scene)) != CLI_EXIT_OK) {
        atmos_context_destroy(ctx);
        return rc;
    }
    const char *source = o.scene_path ? o.scene_path : "default scene", *png = o.png;
    char default_png[160];
    if (!o.png && !o.exr && !o.pfm) {
        default_png_name(scene.name, default_png, sizeof default_png);
        png = default_png;
    }
    atmos_plan *plan = NULL;
    int failed = 0;
    atmos_status st = atmos_plan_create(ctx, &scene, NULL, NULL, &plan);
    if (st == ATMOS_OK && o.tau) st = write_tau(ctx, &scene, plan, o.tau);
    if (st == ATMOS_OK) st = render_frames(ctx, plan, &scene, &o, png, source, &prog, &failed);
    if (st != ATMOS_OK) {
        if (prog.shown) fputc('\n', stderr);
        const int nframes = scene.animation.frames > 1 ? scene.animation.frames : 1;
        if (nframes > 1 && failed >= 1) fprintf(stderr, "atmos render: frame %d/%d failed\n", failed, nframes);
        rc = st == ATMOS_E_INVALID_ARG && !atmos_context_error(ctx)[0] ? CLI_EXIT_USAGE : cli_runtime_error("render", ctx, st);
    }
    atmos_plan_destroy(plan);
    atmos_context_destroy(ctx);
    return rc;
}
