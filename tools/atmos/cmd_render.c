/* atmos render: a scene file (or the built-in default) to PNG / EXR / PFM. The options
 * (render_opts.c) become a scene; the scene becomes one plan; every frame of its animation
 * is rendered from that plan (atmos_plan_render, the same call atmos_render_scene makes). */
#define _POSIX_C_SOURCE 200809L /* access */
#include "outputs.h"
#include "sidecar_inputs.h"
#include "render_opts.h"
#include "dist.h"
#include "render_exposure.h"
#include "render_layers.h"
#include "render_scene.h"
#include "render_timelapse.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The options that name files, in the order of frame_files' names. */
static const char *const out_option[6] = {"-o", "--exr", "--pfm", "--variance", "--order", "--tau"};

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

/* The output files of one frame: the options' names, numbered in an animation (the
 * optical depth image too: each frame's, from that frame's camera). out: -o's file, of the
 * format its extension names. */
typedef struct {
    const char *out, *exr, *pfm, *var, *ord, *tau;
    char buf[6][CLI_OUTPUT_PATH_MAX];
} frame_files;

static int name_frame_files(const render_opts *o, const char *png, int frame, int nframes, frame_files *ff)
{
    const char *base[6] = {png, o->exr, o->pfm, o->variance, o->order, o->tau};
    const char **dst[6] = {&ff->out, &ff->exr, &ff->pfm, &ff->var, &ff->ord, &ff->tau};
    int digits = 4;
    for (int n = nframes; n >= 10000; n /= 10) digits++;
    for (int i = 0; i < 6; i++) {
        *dst[i] = base[i];
        if (!base[i] || nframes < 2) continue;
        if (!frame_name(base[i], frame, digits, ff->buf[i], sizeof ff->buf[i])) return 0;
        *dst[i] = ff->buf[i];
    }
    return 1;
}

/* Every frame's outputs after the first can be written where they are named: not an
 * existing folder, in a folder that exists and takes files or can be made (frame 1's are
 * staged before any work; an animation must not fail at frame 200 for a name). Returns
 * CLI_EXIT_OK or CLI_EXIT_RUNTIME (message printed). */
static int check_frame_names(const render_opts *o, const char *png, int nframes)
{
    frame_files ff;
    for (int frame = 2; frame <= nframes; frame++) {
        if (!name_frame_files(o, png, frame, nframes, &ff)) return CLI_EXIT_RUNTIME;
        const char *names[6] = {ff.out, ff.exr, ff.pfm, ff.var, ff.ord, ff.tau};
        for (int i = 0; i < 6; i++) {
            struct stat st;
            if (!names[i] || stat(names[i], &st) != 0) continue; /* new files: their folder is frame 1's */
            const char *why = S_ISDIR(st.st_mode) ? "is a folder" : access(names[i], W_OK) ? "cannot be written" : NULL;
            if (why) {
                fprintf(stderr, "atmos render: %s: frame %d's output %s\n", names[i], frame, why);
                return CLI_EXIT_RUNTIME;
            }
        }
    }
    return CLI_EXIT_OK;
}

/* The outputs of frame `frame` named (ff), checked and staged (set): w gets the staging
 * names the writers write, renamed onto ff's names when the frame is done. Returns
 * CLI_EXIT_OK or the exit status (message printed). */
static int stage_frame(const render_opts *o, const char *png, int frame, int nframes, frame_files *ff, cli_outputs *set,
                       frame_files *w)
{
    if (!name_frame_files(o, png, frame, nframes, ff)) {
        fprintf(stderr, "atmos render: an output path is too long for numbered frames\n");
        return CLI_EXIT_USAGE;
    }
    const char *names[6] = {ff->out, ff->exr, ff->pfm, ff->var, ff->ord, ff->tau};
    const char **dst[6] = {&w->out, &w->exr, &w->pfm, &w->var, &w->ord, &w->tau};
    int idx[6];
    set->n = 0;
    for (int i = 0; i < 6; i++) idx[i] = cli_outputs_add(set, out_option[i], names[i]);
    if (cli_outputs_prepare("render", set) != 0) return CLI_EXIT_RUNTIME;
    for (int i = 0; i < 6; i++) *dst[i] = idx[i] < 0 ? NULL : cli_outputs_stage(set, idx[i]);
    return CLI_EXIT_OK;
}

/* The volume's optical depth along each pixel's ray at the middle wavelength of the set,
 * as a 1-channel PFM. */
static atmos_status write_tau(atmos_context *ctx, const atmos_scene *scene, const atmos_plan *plan, const char *path)
{
    atmos_image *img = NULL;
    atmos_status st = render_layers_tau(ctx, scene, plan, &img);
    if (st == ATMOS_OK) st = atmos_write_pfm(ctx, img, path);
    atmos_image_destroy(img);
    return st;
}

/* The render's metadata (lin's) on an image of the same frame. */
static void copy_meta(atmos_image *img, const atmos_image *lin)
{
    for (int i = 0; i < lin->meta_count; i++)
        if (strcmp(lin->meta[i].key, "atmos:units")) atmos_image_set_meta(img, lin->meta[i].key, lin->meta[i].value);
}

/* The path tracer's variance (channels variance.<nm>nm, then variance.Y: as the variance
 * layers of --exr-layers) and order images, with the render's metadata (lin's). */
static atmos_status write_path_aux(atmos_context *ctx, const atmos_plan *plan, const frame_files *ff, const atmos_image *lin)
{
    const atmos_wavelengths *wl = atmos_plan_wavelengths(plan);
    atmos_image *img = NULL;
    atmos_status st = ATMOS_OK;
    if (ff->var && (st = atmos_plan_path_variance(plan, &img)) == ATMOS_OK) {
        static char names[ATMOS_MAX_WAVELENGTHS + 1][40];
        const char *np[ATMOS_MAX_WAVELENGTHS + 1];
        render_layers_variance_names(wl, img->channels, names, np);
        atmos_exr_desc ed = {0, np};
        copy_meta(img, lin);
        atmos_image_set_meta(img, "atmos:units", RENDER_VARIANCE_UNITS);
        st = atmos_write_exr(ctx, img, ff->var, &ed);
        atmos_image_destroy(img);
        img = NULL;
    }
    if (st == ATMOS_OK && ff->ord && (st = atmos_plan_path_order(plan, &img)) == ATMOS_OK) {
        st = atmos_write_pfm(ctx, img, ff->ord);
        atmos_image_destroy(img);
    }
    return st;
}

/* The outputs of a rendered frame (w: the files to write): linear sRGB to EXR and PFM,
 * tone-mapped to PNG; -o's file in the format its extension names. */
/* The --exr file: lin, with the --exr-layers appended when asked. */
static atmos_status write_exr_layers(atmos_context *ctx, const atmos_plan *plan, const atmos_scene *fs, const atmos_image *lin,
                                     const char *path, atmos_exr_desc *ed, int layers)
{
    if (!layers) return atmos_write_exr(ctx, lin, path, ed);
    atmos_image *all = NULL;
    atmos_status st = render_layers_build(ctx, plan, fs, lin, layers, &all, &ed->channel_names);
    if (st == ATMOS_OK) st = atmos_write_exr(ctx, all, path, ed);
    ed->channel_names = NULL;
    atmos_image_destroy(all);
    return st;
}

static atmos_status write_outputs(atmos_context *ctx, const atmos_plan *plan, const atmos_scene *fs, const atmos_image *spec,
                                  const frame_files *w, cli_file_kind out_kind, const char *source, const char *frame,
                                  exposure_lock *xl, const render_opts *o)
{
    atmos_image *lin = NULL, *disp = NULL;
    atmos_status st = atmos_image_to_srgb(ctx, spec, atmos_plan_wavelengths(plan), &lin);
    long long mapped = 0;
    if (st == ATMOS_OK) st = atmos_image_gamut_map(ctx, lin, &mapped); /* no negative component written */
    if (st != ATMOS_OK) {
        atmos_image_destroy(lin);
        return st;
    }
    if (mapped > 0) {
        char buf[128];
        snprintf(buf, sizeof buf, "%lld pixels outside sRGB desaturated at constant luminance", mapped);
        atmos_image_set_meta(lin, "atmos:gamut_mapped", buf);
    }
    atmos_image_set_meta(lin, "atmos:source", source);
    if (o->command) atmos_image_set_meta(lin, "atmos:command", o->command);
    if (o->scene_text) atmos_image_set_meta(lin, "atmos:scene_json", o->scene_text);
    if (frame) atmos_image_set_meta(lin, "atmos:frame", frame);
    const atmos_wavelengths *wl = atmos_plan_wavelengths(plan);
    char nm[ATMOS_MAX_WAVELENGTHS * 8 + 8] = "";
    for (int k = 0; k < wl->count; k++) snprintf(nm + strlen(nm), sizeof nm - strlen(nm), "%s%.1f", k ? " " : "", wl->nm[k]);
    atmos_image_set_meta(lin, "atmos:wavelengths_nm", nm);
    atmos_exr_desc ed = {fs->exr_half, NULL};
    if (w->exr) st = write_exr_layers(ctx, plan, fs, lin, w->exr, &ed, o->exr_layers);
    if (st == ATMOS_OK && w->pfm) st = atmos_write_pfm(ctx, lin, w->pfm);
    if (st == ATMOS_OK && w->out && out_kind == CLI_FILE_EXR) /* the layers go in --exr's file if there is one */
        st = write_exr_layers(ctx, plan, fs, lin, w->out, &ed, w->exr ? 0 : o->exr_layers);
    if (st == ATMOS_OK && w->out && out_kind == CLI_FILE_PFM) st = atmos_write_pfm(ctx, lin, w->out);
    if (st == ATMOS_OK && atmos_plan_renderer(plan) == ATMOS_RENDERER_PATH) st = write_path_aux(ctx, plan, w, lin);
    if (st == ATMOS_OK && w->out && out_kind == CLI_FILE_PNG) {
        st = render_exposure_tone_map(ctx, lin, fs, xl, &disp);
        if (st == ATMOS_OK) st = atmos_write_png(ctx, disp, w->out, fs->png_bits ? fs->png_bits : 8);
    }
    atmos_image_destroy(lin);
    atmos_image_destroy(disp);
    return st;
}

/* ranks: 0 rendered here alone; r > 0 by rank r (--mpi); -1 by all ranks together. The path
 * tracer's statistics are those of this process's plan, so only for a frame it rendered alone. */
static void report_frame(const atmos_plan *plan, const atmos_scene *fs, const frame_files *ff, const char *source,
                         const atmos_render_info *info, int frame, int nframes, int ranks)
{
    if (nframes > 1) fprintf(stderr, "atmos render: frame %d/%d: ", frame, nframes);
    else fprintf(stderr, "atmos render: ");
    const atmos_renderer_kind rk = atmos_plan_renderer(plan);
    const int lamps_only = cli_lit_without_sun(fs, rk);
    if (lamps_only) /* the sun lights neither (docs/beams.md, docs/path.md) */
        fprintf(stderr, "%s, %dx%d, lit by its %d light%s and no sun, %.3f s rendering\n", source,
                fs->width, fs->height, fs->light_count, fs->light_count == 1 ? "" : "s", info->seconds);
    else
        fprintf(stderr, "%s, %dx%d, sun at %.2f deg elevation / %.2f deg azimuth, %.3f s rendering\n", source,
                fs->width, fs->height, info->sun_elevation_deg, info->sun_azimuth_deg, info->seconds);
    if (nframes > 1 && !strncmp(fs->volume.source, "simulate:", 9)) /* a time-lapse's frame: its time */
        fprintf(stderr, "  the simulated cloud at %g minutes\n",
                fs->volume.sim_minutes > 0 ? fs->volume.sim_minutes : atmos_sim_preset_minutes(fs->volume.source + 9));
    if (ranks > 0) fprintf(stderr, "  rendered by rank %d\n", ranks);
    if (ranks < 0) fprintf(stderr, "  rendered by all ranks in bands of at most %d rows; the times are rank 0's\n", CLI_DIST_BAND_ROWS);
    const char *files[6] = {ff->out, ff->exr, ff->pfm, ff->var, ff->ord, ff->tau};
    for (int i = 0; i < 6; i++) /* an animation's files go in place when every frame is made */
        if (files[i])
            fprintf(stderr,
                    nframes > 1 ? "  made %s (moved into place with the other frames after the last one; none if "
                                  "interrupted)\n"
                                : "  wrote %s\n",
                    files[i]);
    if (atmos_plan_renderer(plan) == ATMOS_RENDERER_PATH && ranks == 0) {
        atmos_plan_stats ps;
        atmos_plan_get_stats(plan, &ps);
        const atmos_path_stats *q = &ps.path;
        /* --max-depth 1: the single scattering is estimated along each ray (next-event
         * estimation) and no path goes on, so no real event may be sampled at all */
        char ev[96];
        if (q->events == 0 && fs->path.max_depth == 1)
            snprintf(ev, sizeof ev, "single scattering (max depth 1: estimated along each ray, no path goes on)");
        else
            snprintf(ev, sizeof ev, "%lld scattering events", q->events);
        if (q->spp < 2) /* one sample: no spread to estimate an error from */
            fprintf(stderr, "  path: %d spp, %s, relative standard error n/a (1 sample per pixel)\n", q->spp, ev);
        else if (q->volume_pixels > 0)
            fprintf(stderr,
                    "  path: %d spp, %s; relative standard error over the %s's %lld pixels: "
                    "mean %.2f %%, median %.2f %%, 90th percentile %.2f %% (over all pixels: mean %.2f %%)\n",
                    q->spp, ev, atmos_plan_volume(plan, NULL) ? "volume" : "medium", q->volume_pixels, 100.0 * q->volume_rel_error_mean,
                    100.0 * q->volume_rel_error_median, 100.0 * q->volume_rel_error_p90, 100.0 * q->mean_rel_error);
        else
            fprintf(stderr, "  path: %d spp, %s, mean relative standard error %.2f %%\n", q->spp, ev,
                    100.0 * q->mean_rel_error);
        if (ps.path.truncate_deg > 0)
            fprintf(stderr, "  path: forward peak truncated at %g deg: %.3f-%.3f of the scattering counted as unscattered\n",
                    ps.path.truncate_deg, ps.path.truncated_min, ps.path.truncated_max);
    }
}

/* The staged outputs of one frame: what they are named and what the writers write. */
typedef struct {
    frame_files ff, w;
    cli_outputs set;
} frame_outputs;

/* Frame fs's plan: the one plan (*own NULL), or for a time-lapse's frames after the first a
 * plan of its own with the frame's volume (*own, *vol: the caller destroys them). */
static atmos_status frame_plan(atmos_context *ctx, atmos_plan *plan, const atmos_scene *fs, int frame,
                               render_timelapse *tl, atmos_plan **use, atmos_plan **own, atmos_volume **vol)
{
    *use = plan, *own = NULL, *vol = NULL;
    if (!tl || frame == 1) return ATMOS_OK;
    atmos_status st = render_timelapse_volume(ctx, tl, fs, vol);
    if (st == ATMOS_OK) st = atmos_plan_create(ctx, fs, *vol, NULL, own);
    if (st == ATMOS_OK) *use = *own;
    return st;
}

/* What every frame of one render shares. */
typedef struct frames_run {
    atmos_context *ctx;
    const render_opts *o;
    const char *png, *source;
    cli_progress *prog;
    frame_outputs *fo;
    const cli_dist *d;
    int nframes;
    cli_file_kind out_kind;
    exposure_lock xl;
    atmos_image *spec;
    double total;
} frames_run;

/* Frame `frame` (scene fs) rendered from plan by its owner (-1: all ranks) and written by rank
 * 0; ready: the frame's plan's status (a failure is passed to rank 0 as the render's). */
static atmos_status render_frame(frames_run *r, atmos_plan *plan, const atmos_scene *fs, int frame, int owner,
                                 atmos_status ready)
{
    const cli_dist *d = r->d;
    atmos_frame f;
    atmos_render_info info;
    memset(&info, 0, sizeof info);
    char label[64];
    snprintf(label, sizeof label, "%d/%d", frame, r->nframes);
    atmos_status st = ready;
    if (st == ATMOS_OK) st = atmos_frame_from_scene(r->ctx, fs, &f);
    if (st == ATMOS_OK && !r->spec) st = atmos_plan_image_create(plan, &f, &r->spec);
    if (st == ATMOS_OK || owner >= 0) {
        if (st != ATMOS_OK) { /* the owner's failure goes to rank 0 as its render's */
        } else if (owner < 0) st = cli_dist_render(d, plan, &f, r->spec, &info);
        else if (owner == d->rank) st = atmos_plan_render(plan, &f, NULL, r->spec, &info);
        else st = cli_dist_recv(d, owner, r->spec, &info);
    }
    if (d->rank != 0) return owner >= 0 ? cli_dist_send(d, r->spec, st, &info) : st;
    if (st != ATMOS_OK) return st;
    if (r->fo->w.tau && (st = write_tau(r->ctx, fs, plan, r->fo->w.tau)) != ATMOS_OK) return st;
    r->xl.frame = frame;
    st = write_outputs(r->ctx, plan, fs, r->spec, &r->fo->w, r->out_kind, r->source, r->nframes > 1 ? label : NULL, &r->xl, r->o);
    if (st != ATMOS_OK) return st;
    if (cli_outputs_hold("render", &r->fo->set) != 0) return ATMOS_E_IO; /* renamed when all frames are */
    r->total += info.seconds;
    if (!r->o->quiet) {
        if (r->prog->shown) fputc('\n', stderr), r->prog->shown = 0, cli_outputs_line_open(0);
        report_frame(plan, fs, &r->fo->ff, r->source, &info, frame, r->nframes, owner >= 0 ? owner : (d->size > 1 ? -1 : 0));
    }
    return ATMOS_OK;
}

/* Every frame of the scene's animation from the one plan (a time-lapse: a plan a frame, tl);
 * frame 1's outputs are staged already (fo), the others are staged here, and all frames' are
 * renamed into place once every frame is written (a failure removes them all). Returns a status; *failed_frame names the
 * frame that failed. */
static atmos_status render_frames(atmos_context *ctx, atmos_plan *plan0, const atmos_scene *scene, const render_opts *o,
                                  const char *png, const char *source, cli_progress *prog, frame_outputs *fo,
                                  int *failed_frame, const cli_dist *d, render_timelapse *tl)
{
    frames_run r = {ctx, o, png, source, prog, fo, d, scene->animation.frames > 1 ? scene->animation.frames : 1,
                    png ? cli_file_kind_of(png) : CLI_FILE_OTHER, {0}, NULL, 0};
    atmos_status st = ATMOS_OK;
    /* rank 0 tone-maps every frame: the exposure is its own */
    if (d->rank == 0 && png && cli_file_kind_of(png) == CLI_FILE_PNG)
        st = render_exposure_start(ctx, plan0, scene, r.nframes, o->exposure_per_frame || scene->animation.exposure_per_frame,
                                   !tl && !cli_lit_without_sun(scene, scene->renderer), &r.xl);
    if (st != ATMOS_OK) return st;
    if (d->rank == 0 && cli_outputs_hold_reserve(r.nframes, 6) != 0)
        return fprintf(stderr, "atmos render: out of memory for the frames' names\n"), ATMOS_E_IO;
    for (int frame = 1; frame <= r.nframes && st == ATMOS_OK; frame++) {
        *failed_frame = frame;
        /* --mpi: an animation's frame is rendered by its owner and written by rank 0; a single
         * image is rendered by all ranks. */
        const int owner = r.nframes > 1 ? cli_dist_frame_owner(d, frame) : -1;
        if (d->rank != 0 && owner >= 0 && owner != d->rank) continue;
        if (frame > 1 && d->rank == 0 && stage_frame(o, png, frame, r.nframes, &fo->ff, &fo->set, &fo->w) != CLI_EXIT_OK) {
            st = ATMOS_E_IO;
            break;
        }
        atmos_scene fs;
        if ((st = atmos_scene_animation_frame(ctx, scene, frame - 1, &fs)) != ATMOS_OK) break;
        atmos_plan *plan = plan0, *own = NULL;
        atmos_volume *vol = NULL;
        const atmos_status ready = owner < 0 || owner == d->rank ? frame_plan(ctx, plan0, &fs, frame, tl, &plan, &own, &vol)
                                                                  : ATMOS_OK;
        st = render_frame(&r, plan ? plan : plan0, &fs, frame, owner, ready);
        atmos_plan_destroy(own), atmos_volume_destroy(vol);
    }
    cli_outputs_discard(&fo->set);
    /* every frame's files renamed into place together, or none when a frame failed */
    if (d->rank == 0 && st == ATMOS_OK && cli_outputs_held_commit("render") != 0) st = ATMOS_E_IO;
    if (st != ATMOS_OK) cli_outputs_held_discard();
    atmos_image_destroy(r.spec);
    char lock[80] = "";
    if (r.xl.locked)
        snprintf(lock, sizeof lock, "; exposure locked at frame %d's%s", r.xl.key, r.xl.by_sun ? " (the highest sun)" : "");
    if (st == ATMOS_OK && !o->quiet && r.nframes > 1)
        fprintf(stderr, "atmos render: %d frames written, %.3f s rendering (%s)%s\n", r.nframes, r.total,
                tl ? "a time-lapse: the simulation carried from frame to frame, a plan a frame"
                   : "one plan: the volume and its optics made once",
                lock);
    return st;
}

/* Each output's extension names the format written: checked from the options alone, before
 * the scene, its volume or anything else is read. The options that shape the PNG only
 * (the tone curve, its bit depth, the exposure) are said to do nothing when no PNG is
 * written. CLI_EXIT_OK or CLI_EXIT_USAGE. */
static int check_output_names(const render_opts *o)
{
    const char *names[6] = {o->png, o->exr, o->pfm, o->variance, o->order, o->tau};
    static const cli_file_kind want[6] = {CLI_FILE_OTHER, CLI_FILE_EXR, CLI_FILE_PFM, CLI_FILE_EXR, CLI_FILE_PFM, CLI_FILE_PFM};
    static const char *const ext[4] = {"", ".png", ".exr", ".pfm"};
    for (int i = 0; i < 6; i++) {
        if (!names[i]) continue;
        const cli_file_kind k = cli_file_kind_of(names[i]);
        if (i == 0 && k == CLI_FILE_OTHER)
            return cli_usage_error("render", "-o %s: the extension names no format atmos writes (.png, .exr or .pfm)",
                                   names[i]);
        if (i > 0 && k != want[i])
            return cli_usage_error("render", "%s %s: expected a %s file name", out_option[i], names[i], ext[want[i]]);
    }
    /* no -o, --exr nor --pfm: the default PNG is written */
    const int png = o->png ? cli_file_kind_of(o->png) == CLI_FILE_PNG : !o->exr && !o->pfm;
    const char *unused[5] = {o->tone >= 0 ? "--tone" : NULL, o->png_bits ? "--png-bits" : NULL,
                             !isnan(o->ev) || o->exposure_auto ? "--exposure" : NULL,
                             !isnan(o->ev_comp) ? "--exposure-comp" : NULL, o->exposure_per_frame ? "--exposure-per-frame" : NULL};
    char list[96] = "";
    for (int i = 0; i < 5 && !png; i++)
        if (unused[i]) snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", list[0] ? ", " : "", unused[i]);
    if (list[0])
        fprintf(stderr, "atmos render: warning: %s: these shape the PNG only (-o FILE.png), and no PNG is written; the "
                        "EXR and PFM outputs are linear, untouched by them\n", list);
    if (o->exr_half && !o->exr && !(o->png && cli_file_kind_of(o->png) == CLI_FILE_EXR))
        fprintf(stderr, "atmos render: warning: --exr-half: it shapes the EXR image only (--exr FILE or -o FILE.exr), and "
                        "none is written%s\n", o->variance ? " (--variance's EXR is always 32-bit)" : "");
    return CLI_EXIT_OK;
}

/* The outputs the command line names (check_outputs: no two the same file, none an input). */
static void add_outputs(const render_opts *o, const char *png, cli_outputs *set)
{
    const char *names[6] = {png, o->exr, o->pfm, o->variance, o->order, o->tau};
    for (int i = 0; i < 6; i++)
        if (names[i]) cli_outputs_add(set, out_option[i], names[i]);
}

/* The files a scene reads (paths resolved by atmos_scene_load; "" and generated sources
 * NULL): the scene, its volume, the lights' images, the objects' meshes and height maps, the
 * Earth's maps. Returns how many of cap entries it wrote. */
#define SCENE_INPUTS_MAX (2 + ATMOS_SCENE_MAX_LIGHTS + 2 * ATMOS_SCENE_MAX_OBJECTS + 4)
static int scene_inputs(const render_opts *o, const atmos_scene *scene, const char **in)
{
    int n = 0;
    in[n++] = o->scene_path;
    in[n++] = scene->volume.source;
    for (int i = 0; i < scene->light_count; i++) in[n++] = scene->lights[i].image;
    for (int i = 0; i < scene->object_count; i++) in[n++] = scene->objects[i].mesh, in[n++] = scene->objects[i].terrain;
    const atmos_scene_earth *e = &scene->earth;
    in[n++] = e->ground_map, in[n++] = e->night_lights, in[n++] = e->cloud_image, in[n++] = e->cloud_world_file;
    for (int k = 0; k < n; k++)
        if (in[k] && (!in[k][0] || !strncmp(in[k], "generate:", 9) || !strncmp(in[k], "simulate:", 9) ||
                      !strncmp(in[k], "builtin:", 8)))
            in[k] = NULL;
    return n;
}

static int check_outputs(const render_opts *o, const atmos_scene *scene, const char *png)
{
    cli_outputs set = {0};
    add_outputs(o, png, &set);
    const char *inputs[SCENE_INPUTS_MAX + 64];
    static char data[64][CLI_OUTPUT_PATH_MAX]; /* a raw volume's data files, which its sidecar names */
    int n = scene_inputs(o, scene, inputs), ndata = 0;
    if (inputs[1]) cli_sidecar_inputs(inputs[1], data, 64, &ndata, inputs, &n); /* inputs[1]: the volume's file */
    return cli_outputs_check("render", &set, inputs, n);
}

/* The render after the scene is made: outputs checked and staged (rank 0), the plan, the
 * frames. Returns the exit status; *stuck is set when rank 0 stops an animation that other
 * ranks are still rendering (they may be waiting for it: the job must be ended). */
static int render_run(atmos_context *ctx, const render_opts *o, atmos_scene *scene, atmos_volume *volume,
                      cli_progress *prog, const cli_dist *d, double t0, int *stuck)
{
    const char *source = o->scene_path ? o->scene_path : "default scene", *png = o->png;
    char default_png[160];
    if (!o->png && !o->exr && !o->pfm) {
        char stem[128];
        default_png_name(render_scene_output_name(o, scene, stem, sizeof stem), default_png, sizeof default_png);
        png = default_png;
    }
    const int nframes = scene->animation.frames > 1 ? scene->animation.frames : 1;
    /* Every output checked, its folder made and its staging file created before any work. */
    static frame_outputs fo;
    int rc = CLI_EXIT_OK;
    if (d->rank == 0) {
        rc = check_outputs(o, scene, png);
        if (rc == CLI_EXIT_OK) rc = stage_frame(o, png, 1, nframes, &fo.ff, &fo.set, &fo.w);
        if (rc == CLI_EXIT_OK && nframes > 1) rc = check_frame_names(o, png, nframes);
    }
    if ((rc = cli_dist_max(d, rc)) != CLI_EXIT_OK) return cli_outputs_discard(&fo.set), rc;
    /* a moving sun that lights nothing: the lamps alone light the objects and the fog, and the
     * background is a vacuum (no sky to move across) */
    if (d->rank == 0 && nframes > 1 && !render_timelapse_wanted(scene) && cli_lit_without_sun(scene, scene->renderer) &&
        scene->atmosphere.kind == ATMOS_ATMOSPHERE_VACUUM)
        fprintf(stderr, "atmos render: warning: the animation moves the sun, but the sun lights nothing here (lamps "
                        "only%s, a vacuum behind): every frame is the same image\n",
                scene->renderer == ATMOS_RENDERER_BEAMS ? ": no \"beams\": {\"sun\"}" : "");
    if (d->rank == 0 && nframes < 2 && o->exposure_per_frame)
        fprintf(stderr, "atmos render: warning: --exposure-per-frame: changes nothing: the scene is one frame, not an "
                        "animation (\"animation\": {\"frames\": N} makes one)\n");
    atmos_plan *plan = NULL;
    int failed = 0;
    /* a time-lapse: the first frame's volume from the simulation the frames carry on */
    render_timelapse tl = {0}, *tlp = render_timelapse_wanted(scene) ? &tl : NULL;
    atmos_volume *first = NULL;
    atmos_scene fs0;
    atmos_status st = ATMOS_OK;
    if (tlp && (st = atmos_scene_animation_frame(ctx, scene, 0, &fs0)) == ATMOS_OK)
        st = render_timelapse_volume(ctx, tlp, &fs0, &first);
    if (st == ATMOS_OK) st = atmos_plan_create(ctx, scene, first ? first : volume, NULL, &plan);
    if (d->size > 1 && (atmos_status)cli_dist_max(d, (int)st) != ATMOS_OK && st == ATMOS_OK) st = ATMOS_E_CANCELLED;
    const double t_plan = cli_now_s() - t0;
    if (st == ATMOS_OK) {
        st = render_frames(ctx, plan, scene, o, png, source, prog, &fo, &failed, d, tlp);
        *stuck = st != ATMOS_OK && d->rank == 0 && d->size > 1 && nframes > 1;
    }
    cli_outputs_discard(&fo.set);
    if (st == ATMOS_OK && !o->quiet)
        fprintf(stderr, "atmos render: %.3f s in all: %.3f s for the scene, the volume and the optics tables, %.3f s "
                        "rendering and writing\n",
                cli_now_s() - t0, t_plan, cli_now_s() - t0 - t_plan);
    if (st != ATMOS_OK && st != ATMOS_E_CANCELLED) {
        if (prog->shown) fputc('\n', stderr);
        if (d->size > 1) fprintf(stderr, "atmos render: rank %d of %d:\n", d->rank, d->size);
        if (nframes > 1 && failed >= 1) fprintf(stderr, "atmos render: frame %d/%d failed\n", failed, nframes);
        if (st == ATMOS_E_IO && !atmos_context_error(ctx)[0]) rc = CLI_EXIT_RUNTIME; /* an output's message printed */
        else {
            const char *def = o->scene_path ? render_scene_define_in(o, atmos_context_error(ctx)) : NULL;
            rc = st == ATMOS_E_INVALID_ARG && !atmos_context_error(ctx)[0] ? CLI_EXIT_USAGE : cli_runtime_error("render", ctx, st);
            if (def) fprintf(stderr, "  (set by -D %s, not by the scene file)\n", def);
        }
    } else if (st == ATMOS_E_CANCELLED)
        rc = CLI_EXIT_RUNTIME; /* another rank failed and said why */
    atmos_plan_destroy(plan);
    atmos_volume_destroy(first);
    render_timelapse_free(&tl);
    return rc;
}

int cli_cmd_render(int argc, char **argv)
{
    render_opts o;
    int rc = render_opts_parse(argc, argv, &o);
    if (rc != CLI_EXIT_OK) return render_opts_free(&o), rc < 0 ? CLI_EXIT_OK /* --help */ : rc;
    cli_dist d;
    /* the outputs' names first: a wrong one is told before a volume is read */
    if ((rc = check_output_names(&o)) != CLI_EXIT_OK) return render_opts_free(&o), rc;
    if ((rc = cli_dist_start(o.mpi, &d)) != CLI_EXIT_OK) return render_opts_free(&o), rc;
    /* and whether they can be written, before the scene and its volume are read (the default
     * PNG's folder is the current one; the names are checked again, and staged, after) */
    cli_outputs probe = {0};
    if (d.rank == 0) add_outputs(&o, o.png, &probe);
    const char *scene_file[1] = {o.scene_path};
    if (probe.n && (rc = cli_outputs_check("render", &probe, scene_file, 1)) == CLI_EXIT_OK)
        rc = cli_outputs_probe("render", &probe) != 0 ? CLI_EXIT_RUNTIME : CLI_EXIT_OK;
    if ((rc = cli_dist_max(&d, rc)) != CLI_EXIT_OK) return cli_dist_stop(&d), render_opts_free(&o), rc;
    o.scene_text = render_scene_text(o.scene_path);
    if (d.rank != 0) o.quiet = 1; /* rank 0 reports; the others speak only of their failures */
    cli_progress prog;
    cli_progress_init(&prog, o.quiet);
    /* -q hides the progress and the status lines, not the warnings (README); the other ranks of
     * an MPI job keep theirs to themselves (rank 0 gives them). */
    atmos_context *ctx = cli_context_with_progress(o.threads, d.rank != 0, cli_progress_bar, &prog);
    const double t0 = cli_now_s();
    atmos_scene scene;
    atmos_volume *volume = NULL; /* loaded here when framed (render_scene.c), else by the plan */
    rc = ctx ? render_scene_make(ctx, &o, &scene, &volume) : CLI_EXIT_RUNTIME;
    int stuck = 0;
    if ((rc = cli_dist_max(&d, rc)) == CLI_EXIT_OK) rc = render_run(ctx, &o, &scene, volume, &prog, &d, t0, &stuck);
    atmos_volume_destroy(volume);
    atmos_context_destroy(ctx);
    /* Rank 0 stopped with other ranks still rendering frames for it: the whole job ends (its
     * outputs were discarded above). A rank that failed told rank 0, and waits for that. */
    if (stuck) cli_dist_abort(&d, rc);
    cli_dist_stop(&d);
    render_opts_free(&o);
    return rc;
}
