/* atmos render's options: parsed into render_opts, then applied to the scene. The options of
 * the renderers' settings are made from the library's settings tables
 * (atmos_renderer_settings), so they have the scene file's names, ranges and meanings. */
#ifndef ATMOS_CLI_RENDER_OPTS_H
#define ATMOS_CLI_RENDER_OPTS_H

#include "cli.h"

#define RENDER_OPTS_MAX_SETTINGS 48
#define RENDER_OPTS_MAX_DEFINES 64

/* A renderer setting given on the command line. */
typedef struct {
    atmos_renderer_kind renderer;
    const atmos_setting *setting;
    double value;
} render_setting;

typedef struct {
    const char *cmd;        /* "render" or "view": the command the messages name */
    const char *scene_path;
    /* outputs */
    const char *png, *exr, *pfm, *variance, *order, *tau;
    int png_bits, exr_half;
    int exr_layers;         /* --exr-layers: RENDER_LAYER_* (render_layers.h) in the --exr file */
    char *command;          /* the command line, for the outputs' metadata (render_opts_free) */
    char *scene_text;       /* the scene file's text (at most 1 MiB), for the same; NULL: none */
    int exposure_per_frame; /* an animation's automatic exposure chosen per frame, not locked */
    /* scene overrides (0 / NaN / NULL / -1: not given) */
    int width, height, spp, spectral, rgb, cam_type, renderer, tone, exposure_auto, frames, air;
    double altitude, sun_el, sun_az, lat, lon, ev, ev_comp, sun_el_end, sun_az_end, density_scale, thickness;
    const char *time, *time_end, *volume;
    double volume_pos[3];
    int volume_pos_given;
    /* the volume file (NULL / -1 / 0: not given) */
    const char *grids, *particle;
    int time_index, density_unit;
    double voxel_size, volume_scale, subgrid_detail;
    /* the camera (NaN / 0: not given) */
    double fov, view_el, view_az, position[3], look_at[3];
    int position_given, look_at_given;
    /* -D PATH=VALUE: scene keys set before the scene is read */
    const char *defines[RENDER_OPTS_MAX_DEFINES];
    int ndefines;
    render_setting set[RENDER_OPTS_MAX_SETTINGS];
    int nset;
    /* the run */
    int threads, quiet;
    int mpi; /* --mpi: the work shared by the ranks of an MPI job (tools/atmos/dist.h) */
} render_opts;

/* Parses argv; returns CLI_EXIT_OK, CLI_EXIT_USAGE (message printed) or -1 after --help.
 * render_opts_free releases what it allocated (either way). */
int render_opts_parse(int argc, char **argv, render_opts *o);
void render_opts_free(render_opts *o);
void render_opts_help(void);
/* Applies the options to a scene (loaded or the default); returns CLI_EXIT_OK or
 * CLI_EXIT_USAGE (message printed). ctx receives time-parsing errors. */
int render_opts_apply(atmos_context *ctx, const render_opts *o, atmos_scene *scene);
/* atmos render's option (without "--") for the renderer setting a validation message names, or NULL */
const char *render_opts_flag_in(const char *msg);
/* Nonzero when the options place the camera themselves (--position, --look-at, --altitude,
 * --camera): a volume file is then not framed by default. */
int render_opts_camera_given(const render_opts *o);

#endif
