/* atmos render's options (render_opts.h). The fixed options are listed here; one option per
 * row of the renderers' settings tables is added from atmos_renderer_settings, and --help
 * prints those rows with their ranges and defaults. */
#include "render_opts.h"
#include "render_layers.h"

#include <getopt.h>
#include <stddef.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

enum {
    O_EXR = 256, O_PFM, O_PNGBITS, O_EXRHALF, O_W, O_H, O_CAM, O_ALT, O_SEL, O_SAZ, O_TIME, O_LAT, O_LON, O_SPECTRAL,
    O_RGB, O_EXPOSURE, O_EXPCOMP, O_TONE, O_THREADS, O_RENDERER, O_VOLUME, O_VPOS, O_DSCALE, O_TAU, O_VARIANCE,
    O_FRAMES, O_TIME_END, O_SEL_END, O_SAZ_END, O_ORDER, O_ATMOSPHERE, O_THICKNESS, O_GRIDS, O_PARTICLE, O_TINDEX,
    O_DUNIT, O_VOXEL, O_VSCALE, O_FOV, O_VIEW_EL, O_VIEW_AZ, O_POSITION, O_LOOKAT, O_DETAIL, O_EXP_PER_FRAME, O_MPI, O_LAYERS,
    O_SETTING = 1024 /* + row index over the tables: a renderer setting */
};

static const struct option fixed_opts[] = {
    {"output", required_argument, 0, 'o'}, {"exr", required_argument, 0, O_EXR}, {"pfm", required_argument, 0, O_PFM},
    {"png-bits", required_argument, 0, O_PNGBITS}, {"exr-half", no_argument, 0, O_EXRHALF},
    {"exr-layers", required_argument, 0, O_LAYERS},
    {"width", required_argument, 0, O_W}, {"height", required_argument, 0, O_H},
    {"camera", required_argument, 0, O_CAM}, {"altitude", required_argument, 0, O_ALT},
    {"sun-elevation", required_argument, 0, O_SEL}, {"sun-azimuth", required_argument, 0, O_SAZ},
    {"time", required_argument, 0, O_TIME}, {"lat", required_argument, 0, O_LAT}, {"lon", required_argument, 0, O_LON},
    {"spectral", required_argument, 0, O_SPECTRAL}, {"rgb", no_argument, 0, O_RGB},
    {"exposure", required_argument, 0, O_EXPOSURE}, {"exposure-comp", required_argument, 0, O_EXPCOMP},
    {"tone", required_argument, 0, O_TONE}, {"threads", required_argument, 0, O_THREADS},
    {"quiet", no_argument, 0, 'q'}, {"renderer", required_argument, 0, O_RENDERER}, {"mpi", no_argument, 0, O_MPI},
    {"volume", required_argument, 0, O_VOLUME}, {"volume-position", required_argument, 0, O_VPOS},
    {"density-scale", required_argument, 0, O_DSCALE}, {"tau", required_argument, 0, O_TAU},
    {"variance", required_argument, 0, O_VARIANCE}, {"order", required_argument, 0, O_ORDER},
    {"frames", required_argument, 0, O_FRAMES}, {"time-end", required_argument, 0, O_TIME_END},
    {"sun-elevation-end", required_argument, 0, O_SEL_END}, {"sun-azimuth-end", required_argument, 0, O_SAZ_END},
    {"atmosphere", required_argument, 0, O_ATMOSPHERE}, {"thickness", required_argument, 0, O_THICKNESS},
    {"grids", required_argument, 0, O_GRIDS}, {"particle", required_argument, 0, O_PARTICLE},
    {"time-index", required_argument, 0, O_TINDEX}, {"density-unit", required_argument, 0, O_DUNIT},
    {"voxel-size", required_argument, 0, O_VOXEL}, {"volume-scale", required_argument, 0, O_VSCALE},
    {"fov", required_argument, 0, O_FOV}, {"view-elevation", required_argument, 0, O_VIEW_EL},
    {"view-azimuth", required_argument, 0, O_VIEW_AZ}, {"position", required_argument, 0, O_POSITION},
    {"look-at", required_argument, 0, O_LOOKAT}, {"define", required_argument, 0, 'D'},
    {"subgrid-detail", required_argument, 0, O_DETAIL},
    {"exposure-per-frame", no_argument, 0, O_EXP_PER_FRAME},
    {"help", no_argument, 0, 'h'}};
#define NFIXED ((int)(sizeof fixed_opts / sizeof fixed_opts[0]))

/* Row i of the concatenated settings tables (slice, then path); NULL past the end. */
static const atmos_setting *table_row(int i, atmos_renderer_kind *r)
{
    for (int k = ATMOS_RENDERER_SLICE; k <= ATMOS_RENDERER_LAST; k++) {
        int n;
        const atmos_setting *t = atmos_renderer_settings((atmos_renderer_kind)k, &n);
        if (i < n) {
            *r = (atmos_renderer_kind)k;
            return &t[i];
        }
        i -= n;
    }
    return NULL;
}

/* atmos render's option for a renderer's setting /SECTION/KEY, as a validation message names it
 * ("... /slice/eye_scale: ..."); NULL when the message names none or the setting has no option. */
const char *render_opts_flag_in(const char *msg)
{
    const char *a = msg ? strchr(msg, '/') : NULL;
    const char *b = a ? strchr(a + 1, '/') : NULL, *c = b ? strchr(b + 1, ':') : NULL;
    if (!c) return NULL;
    atmos_renderer_kind r;
    const atmos_setting *t;
    for (int i = 0; (t = table_row(i, &r)) != NULL; i++) {
        const char *name = atmos_renderer_name(r);
        if (t->flag && strlen(name) == (size_t)(b - a - 1) && !strncmp(name, a + 1, (size_t)(b - a - 1)) &&
            strlen(t->key) == (size_t)(c - b - 1) && !strncmp(t->key, b + 1, (size_t)(c - b - 1)))
            return t->flag;
    }
    return NULL;
}

static int takes_value(const atmos_setting *s)
{
    return s->type != ATMOS_SETTING_BOOL && s->type != ATMOS_SETTING_CHOICE;
}

/* The long options: the fixed ones, then one per settings row with a flag. */
static int build_options(struct option *opts, int cap)
{
    int n = 0;
    for (int i = 0; i < NFIXED && n < cap - 1; i++) opts[n++] = fixed_opts[i];
    atmos_renderer_kind r = ATMOS_RENDERER_SLICE;
    const atmos_setting *s;
    for (int i = 0; (s = table_row(i, &r)) && n < cap - 1; i++)
        if (s->flag) opts[n++] = (struct option){s->flag, takes_value(s) ? required_argument : no_argument, 0, O_SETTING + i};
    opts[n] = (struct option){0, 0, 0, 0};
    return n;
}

/* A setting's value from the command line, checked against its row's range. */
static int parse_setting(const char *C, const atmos_setting *s, const char *text, double *out)
{
    char opt[64];
    snprintf(opt, sizeof opt, "--%s", s->flag);
    if (!takes_value(s)) {
        *out = s->flag_sets;
        return 1;
    }
    if (s->type == ATMOS_SETTING_SEED) {
        char *end = NULL;
        unsigned long long v = strtoull(text, &end, 10);
        /* compared as integers: 2^53 + 1 is not 2^53 */
        if (!*text || *end || text[0] == '-' || v > (unsigned long long)s->max) {
            cli_usage_error(C, "%s: expected an integer in [0, %.0f], got '%s'", opt, s->max, text);
            return 0;
        }
        *out = (double)v;
        return 1;
    }
    double v = NAN; /* a word: the range said, as for a number outside it */
    cli_strtod(text, &v);
    const int low = s->min_open ? v <= s->min : v < s->min, high = s->max_open ? v >= s->max : v > s->max;
    if (low || high || isnan(v) || (s->type == ATMOS_SETTING_INT && !(v == floor(v)))) {
        cli_usage_error(C, "%s: expected %s in %c%g, %g%c%s%s, got '%s'", opt,
                        s->type == ATMOS_SETTING_INT ? "an integer" : "a value", s->min_open ? '(' : '[', s->min, s->max,
                        s->max_open ? ')' : ']', s->unit[0] ? " " : "", s->unit, text);
        return 0;
    }
    *out = v;
    return 1;
}

static int parse_choice(const char *C, const char *opt, const char *text, const char *const *names, int n, int *out)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(text, names[i])) return *out = i, 1;
    char list[128] = "";
    for (int i = 0; i < n; i++) snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", names[i]);
    cli_usage_error(C, "%s: expected %s, got '%s'", opt, list, text);
    return 0;
}

static void opts_init(render_opts *o)
{
    memset(o, 0, sizeof *o);
    o->cam_type = o->renderer = o->tone = o->air = -1;
    o->altitude = o->sun_el = o->sun_az = o->lat = o->lon = o->ev = o->ev_comp = NAN;
    o->sun_el_end = o->sun_az_end = NAN;
    o->time_index = o->density_unit = -1;
    o->fov = o->view_el = o->view_az = NAN;
}

/* X,Y,Z in metres. */
static int parse_vec3(const char *C, const char *opt, const char *arg, double v[3], int *given)
{
    char tail;
    if (sscanf(arg, "%lf,%lf,%lf%c", &v[0], &v[1], &v[2], &tail) != 3 || !isfinite(v[0]) || !isfinite(v[1]) ||
        !isfinite(v[2])) {
        cli_usage_error(C, "%s: expected X,Y,Z in metres, got '%s'", opt, arg);
        return 0;
    }
    return *given = 1, 1;
}

/* --lat, --lon: degrees in [-limit, limit], as the scene's latitude_deg/longitude_deg and atmos
 * sun take them (over a round planet they set the atmosphere's place, checked by no scene rule
 * on the way: --lon 200 was taken, --lat 95 failed in the library with exit 1). */
static int parse_place(const char *C, const char *opt, const char *arg, double limit, double *out)
{
    if (!cli_parse_double(C, opt, arg, out)) return 0;
    if (fabs(*out) <= limit) return 1;
    cli_usage_error(C, "%s: expected degrees in [%g, %g], got %s", opt, -limit, limit, arg);
    return 0;
}

/* The options that name files or pick from words. Returns 1, 0 (usage error printed) or -1
 * (not one of these). */
static int parse_named(int c, const char *arg, render_opts *o)
{
    static const char *const cams[] = {"pinhole", "fisheye", "equirect"}, *const tones[] = {"filmic", "reinhard", "clamp"},
                             *const renderers[] = {"sky", "slice", "path", "nishita", "harris", "beams"}, *const airs[] = {"riley", "homogeneous", "dobashi", "spherical"};
    const char *C = o->cmd;
    switch (c) {
    case 'o': o->png = arg; return 1;
    case O_EXR: o->exr = arg; return 1;
    case O_PFM: o->pfm = arg; return 1;
    case O_TAU: o->tau = arg; return 1;
    case O_VARIANCE: o->variance = arg; return 1;
    case O_ORDER: o->order = arg; return 1;
    case O_VOLUME: o->volume = arg; return 1;
    case O_TIME: o->time = arg; return 1;
    case O_TIME_END: o->time_end = arg; return 1;
    case O_EXRHALF: o->exr_half = 1; return 1;
    case O_EXP_PER_FRAME: o->exposure_per_frame = 1; return 1;
    case O_MPI: o->mpi = 1; return 1;
    case O_LAYERS: return render_layers_parse(arg, &o->exr_layers);
    case O_RGB: o->rgb = 1; return 1;
    case O_CAM: return parse_choice(o->cmd, "--camera", arg, cams, 3, &o->cam_type);
    case O_TONE: return parse_choice(o->cmd, "--tone", arg, tones, 3, &o->tone);
    case O_RENDERER: return parse_choice(o->cmd, "--renderer", arg, renderers, 6, &o->renderer);
    case O_ATMOSPHERE: return parse_choice(o->cmd, "--atmosphere", arg, airs, 4, &o->air);
    case O_EXPOSURE:
        if (!strcmp(arg, "auto")) return o->exposure_auto = 1, 1;
        return cli_parse_double(C, "--exposure", arg, &o->ev);
    case O_VPOS: return parse_vec3(o->cmd, "--volume-position", arg, o->volume_pos, &o->volume_pos_given);
    case O_POSITION: return parse_vec3(o->cmd, "--position", arg, o->position, &o->position_given);
    case O_LOOKAT: return parse_vec3(o->cmd, "--look-at", arg, o->look_at, &o->look_at_given);
    case O_GRIDS: o->grids = arg; return 1;
    case O_PARTICLE: o->particle = arg; return 1;
    case O_DUNIT: {
        static const char *const units[] = {"auto", "per_m3", "g_m3", "fraction"};
        return parse_choice(o->cmd, "--density-unit", arg, units, 4, &o->density_unit);
    }
    default: return -1;
    }
}

/* The numeric options. Returns 1, 0 (usage error printed) or -1 (not one of these). */
static int parse_number(int c, const char *arg, render_opts *o)
{
    const char *C = o->cmd;
    switch (c) {
    case O_PNGBITS:
        if (!cli_parse_int(C, "--png-bits", arg, 8, 16, &o->png_bits)) return 0;
        if (o->png_bits != 8 && o->png_bits != 16) return cli_usage_error(C, "--png-bits: must be 8 or 16"), 0;
        return 1;
    case O_W: return cli_parse_int(C, "--width", arg, 1, ATMOS_SCENE_MAX_DIM, &o->width);
    case O_H: return cli_parse_int(C, "--height", arg, 1, ATMOS_SCENE_MAX_DIM, &o->height);
    case O_SPECTRAL: return cli_parse_int(C, "--spectral", arg, 1, ATMOS_MAX_WAVELENGTHS, &o->spectral);
    case O_THREADS: return cli_parse_int(C, "--threads", arg, 1, 1024, &o->threads);
    case O_FRAMES: return cli_parse_int(C, "--frames", arg, 1, ATMOS_SCENE_MAX_FRAMES, &o->frames);
    case O_ALT: return cli_parse_double(C, "--altitude", arg, &o->altitude);
    case O_SEL: return cli_parse_double(C, "--sun-elevation", arg, &o->sun_el);
    case O_SAZ: return cli_parse_azimuth(C, "--sun-azimuth", arg, &o->sun_az);
    case O_LAT: return parse_place(C, "--lat", arg, 90.0, &o->lat);
    case O_LON: return parse_place(C, "--lon", arg, 180.0, &o->lon);
    case O_EXPCOMP: return cli_parse_double(C, "--exposure-comp", arg, &o->ev_comp);
    case O_SEL_END: return cli_parse_double(C, "--sun-elevation-end", arg, &o->sun_el_end);
    case O_SAZ_END: return cli_parse_azimuth(C, "--sun-azimuth-end", arg, &o->sun_az_end);
    case O_THICKNESS:
        if (!cli_parse_double(C, "--thickness", arg, &o->thickness)) return 0; /* its message given */
        if (!(o->thickness >= 1 && o->thickness <= 1e6))
            return cli_usage_error(C, "--thickness: expected metres in [1, 1000000]"), 0;
        return 1;
    case O_TINDEX: return cli_parse_int(C, "--time-index", arg, 0, 1000000, &o->time_index);
    case O_VOXEL:
        if (!cli_parse_double(C, "--voxel-size", arg, &o->voxel_size)) return 0; /* its message given */
        if (!(o->voxel_size > 0 && o->voxel_size <= 1e5))
            return cli_usage_error(C, "--voxel-size: expected metres in (0, 100000]"), 0;
        return 1;
    case O_VSCALE:
        if (!cli_parse_double(C, "--volume-scale", arg, &o->volume_scale)) return 0; /* its message given */
        if (!(o->volume_scale > 0 && o->volume_scale <= 100))
            return cli_usage_error(C, "--volume-scale: expected a factor in (0, 100]"), 0;
        return 1;
    case O_DETAIL:
        if (!cli_parse_double(C, "--subgrid-detail", arg, &o->subgrid_detail)) return 0; /* its message given */
        if (!(o->subgrid_detail > 0 && o->subgrid_detail <= 1))
            return cli_usage_error(C, "--subgrid-detail: expected an amplitude in (0, 1]"), 0;
        return 1;
    case O_FOV:
        if (!cli_parse_double(C, "--fov", arg, &o->fov)) return 0; /* its message given */
        if (!(o->fov > 0 && o->fov <= 360))
            return cli_usage_error(C, "--fov: expected degrees in (0, 360]"), 0;
        return 1;
    case O_VIEW_EL:
        if (!cli_parse_double(C, "--view-elevation", arg, &o->view_el)) return 0; /* its message given */
        if (!(fabs(o->view_el) <= 90))
            return cli_usage_error(C, "--view-elevation: expected degrees in [-90, 90]"), 0;
        return 1;
    case O_VIEW_AZ: return cli_parse_azimuth(C, "--view-azimuth", arg, &o->view_az);
    case O_DSCALE:
        if (!cli_parse_double(C, "--density-scale", arg, &o->density_scale)) return 0; /* its message given */
        if (!(o->density_scale > 0 && o->density_scale <= 1e30))
            return cli_usage_error(C, "--density-scale: expected a factor in (0, 1e30] (volume.density_scale's bound)"), 0;
        return 1;
    default: return -1;
    }
}

/* Rules between options that hold whatever the scene says. */
static int check_options(const render_opts *o)
{
    const char *C = o->cmd;
    if (o->spectral && o->rgb) return cli_usage_error(C, "--spectral and --rgb exclude each other");
    if (o->time && o->time[0] && strspn(o->time, "0123456789") == strlen(o->time)) /* volume's --time N */
        return cli_usage_error(C, "--time %s: --time takes a UTC time (2026-06-21T12:00:00Z); a NetCDF time "
                                  "step is --time-index %s", o->time, o->time);
    const int use_time = o->time || !isnan(o->lat) || !isnan(o->lon);
    if (isnan(o->lat) != isnan(o->lon)) return cli_usage_error(C, "--lat and --lon go together");
    if (use_time && (!isnan(o->sun_el) || !isnan(o->sun_az)))
        return cli_usage_error(C, "--time/--lat/--lon and --sun-elevation/--sun-azimuth exclude each other");
    if (o->exposure_auto && !isnan(o->ev)) return cli_usage_error(C, "--exposure given twice");
    if (o->mpi && (o->variance || o->order || (o->exr_layers & (RENDER_LAYER_ORDER | RENDER_LAYER_VARIANCE))))
        return cli_usage_error(C, "--variance, --order and the order and variance layers are not written with --mpi "
                                  "(each rank holds its own samples)");
    const size_t olen = o->png ? strlen(o->png) : 0; /* -o X.exr takes the layers when there is no --exr */
    const int out_exr = olen > 4 && !strcasecmp(o->png + olen - 4, ".exr");
    if (o->exr_layers && !o->exr && !out_exr)
        return cli_usage_error(C, "--exr-layers: they go in the EXR file (--exr FILE or -o FILE.exr); give one");
    if (o->mpi && o->scene_path && !strcmp(o->scene_path, "-"))
        return cli_usage_error(C, "--mpi: the scene must be a file (standard input reaches rank 0 only)");
    if (o->time_end && (!isnan(o->sun_el_end) || !isnan(o->sun_az_end)))
        return cli_usage_error(C, "--time-end (a sun given by time) and --sun-elevation-end/--sun-azimuth-end "
                                  "(a sun given by angles) exclude each other");
    if (o->volume && strlen(o->volume) >= sizeof(((atmos_scene *)0)->volume.source))
        return cli_usage_error(C, "--volume: the path is too long");
    if (o->grids && strlen(o->grids) >= sizeof(((atmos_scene *)0)->volume.grids))
        return cli_usage_error(C, "--grids: the list is too long");
    if (o->particle && (!o->particle[0] || strlen(o->particle) >= sizeof(((atmos_scene *)0)->volume.particle)))
        return cli_usage_error(C, "--particle: expected a particle type's name");
    if (o->look_at_given && (!isnan(o->view_el) || !isnan(o->view_az)))
        return cli_usage_error(C, "--look-at and --view-elevation/--view-azimuth exclude each other");
    if (o->position_given && !isnan(o->altitude))
        return cli_usage_error(C, "--position (its y is the altitude) and --altitude exclude each other");
    return CLI_EXIT_OK;
}

/* argv as one line, each argument in single quotes when it has more than letters, digits
 * and -_./=,:+ (a line a shell runs again). */
static char *command_line(int argc, char **argv)
{
    size_t cap = 16;
    for (int i = 0; i < argc; i++) cap += 4 * strlen(argv[i]) + 3;
    char *s = malloc(cap), *q = s;
    if (!s) return NULL;
    q += sprintf(q, "atmos");
    for (int i = 0; i < argc; i++) {
        const int plain = argv[i][0] && strspn(argv[i], "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                         "0123456789-_./=,:+") == strlen(argv[i]);
        *q++ = ' ';
        if (!plain) *q++ = '\'';
        for (const char *a = argv[i]; *a; a++) {
            if (!plain && *a == '\'') q += sprintf(q, "'\\''");
            else *q++ = *a;
        }
        if (!plain) *q++ = '\'';
    }
    *q = 0;
    return s;
}

void render_opts_free(render_opts *o)
{
    free(o->command);
    free(o->scene_text);
    o->command = o->scene_text = NULL;
}

int render_opts_parse(int argc, char **argv, render_opts *o)
{
    struct option opts[NFIXED + 2 * RENDER_OPTS_MAX_SETTINGS + 1];
    build_options(opts, (int)(sizeof opts / sizeof opts[0]));
    opts_init(o);
    /* the command whose options these are, for the messages: atmos view passes its own */
    o->cmd = argc > 0 && argv[0] && !strcmp(argv[0], "view") ? "view" : "render";
    const char *C = o->cmd;
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "o:qhD:", opts, NULL)) != -1) {
        if (c == 'h') return render_opts_help(), -1;
        if (c == 'D') {
            if (o->ndefines >= RENDER_OPTS_MAX_DEFINES) return cli_usage_error(C, "too many -D options");
            if (!strchr(optarg, '=')) return cli_usage_error(C, "-D: expected KEY=VALUE, got '%s'", optarg);
            o->defines[o->ndefines++] = optarg;
            continue;
        }
        if (c == 'q') {
            o->quiet = 1;
            continue;
        }
        if (c >= O_SETTING) {
            atmos_renderer_kind r = ATMOS_RENDERER_SLICE;
            const atmos_setting *s = table_row(c - O_SETTING, &r);
            if (o->nset >= RENDER_OPTS_MAX_SETTINGS) return cli_usage_error(C, "too many options");
            render_setting *rs = &o->set[o->nset];
            if (!parse_setting(o->cmd, s, optarg, &rs->value)) return CLI_EXIT_USAGE;
            rs->renderer = r, rs->setting = s, o->nset++;
            continue;
        }
        int done = parse_named(c, optarg, o);
        if (done < 0) done = parse_number(c, optarg, o);
        if (done == 0) return CLI_EXIT_USAGE;
        if (done < 0) return cli_usage_error(C, "unknown or incomplete option '%s'", argv[optind - 1]);
    }
    if (optind < argc) o->scene_path = argv[optind++];
    if (optind < argc) return cli_usage_error(C, "unexpected argument '%s' (one scene file at most)", argv[optind]);
    o->command = command_line(argc, argv);
    return check_options(o);
}

/* --time or --time-end (opt) into *t: a time the sun's position takes (years 1800-2200), or a
 * usage error, whichever part of it is wrong. */
static int parse_sun_time(atmos_context *ctx, const char *C, const char *opt, const char *text, atmos_utc_time *t)
{
    atmos_sun_position sp;
    if (atmos_parse_utc_time(ctx, text, t) != ATMOS_OK || atmos_sun_position_compute(ctx, t, 0, 0, 0, &sp) != ATMOS_OK)
        return cli_usage_error(C, "%s: %s", opt, atmos_context_error(ctx));
    return CLI_EXIT_OK;
}

/* The sun and the animation's end. */
static int apply_sun(atmos_context *ctx, const render_opts *o, atmos_scene *s)
{
    const char *C = o->cmd;
    if (!isnan(o->sun_el) || !isnan(o->sun_az)) {
        if (s->sun.from_time) {
            /* Overriding one angle of a sun placed by time keeps the other one it had. */
            double dir[3], el = 0, az = 0;
            if (atmos_scene_sun_direction(ctx, s, dir, &el, &az) == ATMOS_OK) s->sun.elevation_deg = el, s->sun.azimuth_deg = az;
        }
        s->sun.from_time = 0;
        if (!isnan(o->sun_el)) s->sun.elevation_deg = o->sun_el;
        if (!isnan(o->sun_az)) s->sun.azimuth_deg = o->sun_az;
        s->animation.time_end_set = 0; /* a sun switched to angles drops the end of the old form */
    }
    /* Over a round planet the world frame is the ground's at the atmosphere's latitude_deg and
     * longitude_deg (its maps are placed from there): --lat/--lon move that place (the Earth
     * turns under the camera) and the sun's, so that a sun by time stands where the date and
     * time put it over the map. --time alone keeps the place of a scene's sun by time, else
     * takes the round planet's. Elsewhere --lat/--lon place the sun alone. */
    const atmos_atmosphere_kind kind = s->atmosphere.kind;
    const int round = kind == ATMOS_ATMOSPHERE_DOBASHI || kind == ATMOS_ATMOSPHERE_SPHERICAL;
    const int place = !isnan(o->lat), by_time = o->time || s->sun.from_time;
    if ((o->time && !place && !s->sun.from_time && !round) || (place && !by_time && !round))
        return cli_usage_error(C, "--time, --lat and --lon go together (--time alone keeps the place of a scene's sun "
                                  "by time, or over a round planet, \"model\": \"dobashi\" or \"spherical\", "
                                  "takes its latitude_deg/longitude_deg)");
    if (o->time) {
        if (parse_sun_time(ctx, C, "--time", o->time, &s->sun.time) != CLI_EXIT_OK) return CLI_EXIT_USAGE;
        if (!place && !s->sun.from_time) /* a round planet's place */
            s->sun.latitude_deg = s->atmosphere.latitude_deg, s->sun.longitude_deg = s->atmosphere.longitude_deg;
        s->sun.from_time = 1;
        s->animation.elevation_end_set = s->animation.azimuth_end_set = 0;
    }
    if (place && round) s->atmosphere.latitude_deg = o->lat, s->atmosphere.longitude_deg = o->lon;
    if (place && s->sun.from_time) s->sun.latitude_deg = o->lat, s->sun.longitude_deg = o->lon;
    if (o->frames) s->animation.frames = o->frames;
    if (o->time_end) {
        if (parse_sun_time(ctx, C, "--time-end", o->time_end, &s->animation.time_end) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        s->animation.time_end_set = 1;
    }
    if (!isnan(o->sun_el_end)) s->animation.elevation_end_deg = o->sun_el_end, s->animation.elevation_end_set = 1;
    if (!isnan(o->sun_az_end)) s->animation.azimuth_end_deg = o->sun_az_end, s->animation.azimuth_end_set = 1;
    if (o->time_end && !s->sun.from_time)
        return cli_usage_error(C, "--time-end: needs a sun given by time (--time, or a scene's \"sun\": {\"time\", ...}); "
                                  "a sun given by angles moves with --sun-elevation-end/--sun-azimuth-end");
    if ((!isnan(o->sun_el_end) || !isnan(o->sun_az_end)) && s->sun.from_time)
        return cli_usage_error(C, "--sun-elevation-end/--sun-azimuth-end: need a sun given by angles (--sun-elevation/"
                                  "--sun-azimuth, or a scene's); a sun given by time moves with --time-end");
    if ((o->time_end || !isnan(o->sun_el_end) || !isnan(o->sun_az_end)) && s->animation.frames < 1)
        return cli_usage_error(C, "--time-end, --sun-elevation-end and --sun-azimuth-end need --frames N "
                                         "or a scene with an \"animation\"");
    return CLI_EXIT_OK;
}

/* --position, --look-at, --fov, --view-elevation/--view-azimuth. A new position keeps the
 * view direction unless --look-at is given too; the view angles turn the camera where it is. */
static void apply_camera(const render_opts *o, atmos_camera_desc *c)
{
    double d[3], len = 0;
    for (int a = 0; a < 3; a++) d[a] = c->look_at[a] - c->position[a], len += d[a] * d[a];
    len = sqrt(len);
    if (o->position_given) {
        memcpy(c->position, o->position, sizeof o->position);
        for (int a = 0; a < 3; a++) c->look_at[a] = c->position[a] + d[a];
    }
    if (o->look_at_given) memcpy(c->look_at, o->look_at, sizeof o->look_at);
    if (!isnan(o->view_el) || !isnan(o->view_az)) {
        double el = 0, az = 0;
        if (len > 0) {
            el = asin(fmax(-1.0, fmin(1.0, d[1] / len))) * 57.295779513082321;
            az = atan2(d[0], -d[2]) * 57.295779513082321; /* clockwise from north (-z), east +x */
        }
        if (!isnan(o->view_el)) el = o->view_el;
        if (!isnan(o->view_az)) az = o->view_az;
        double dir[3];
        atmos_direction_from_angles(el, az, dir);
        for (int a = 0; a < 3; a++) c->look_at[a] = c->position[a] + 1000.0 * dir[a];
        /* Near the zenith or the nadir the up vector (0, 1, 0) is no longer one: the image's top
         * is then the azimuth's horizontal direction (the nadir: the way the camera faced before
         * tilting down; the zenith: behind it), as the view tends to it from lower elevations. */
        const int def_up = c->up[0] == 0 && c->up[2] == 0;
        if (fabs(el) > 89.9 && def_up) {
            double h[3];
            atmos_direction_from_angles(0, az, h);
            for (int a = 0; a < 3; a++) c->up[a] = (el > 0 ? -1.0 : 1.0) * h[a];
        }
    }
    if (!isnan(o->fov)) c->fov_deg = o->fov;
}

int render_opts_camera_given(const render_opts *o)
{
    return o->position_given || o->look_at_given || !isnan(o->altitude) || o->cam_type > 0;
}

/* The volume file's options: refused with a generated volume, which has none of them. */
static int apply_volume_file(const render_opts *o, atmos_scene *s)
{
    const char *C = o->cmd;
    const int given = o->grids || o->particle || o->time_index >= 0 || o->density_unit >= 0 || o->subgrid_detail > 0;
    if (!given && !(o->voxel_size > 0) && !(o->volume_scale > 0)) return CLI_EXIT_OK;
    if (!s->volume.source[0])
        return cli_usage_error(C, "--grids, --particle, --time-index, --density-unit, --voxel-size and --volume-scale "
                                  "need a volume (--volume or a scene with one)");
    const int file_only = o->grids || o->time_index >= 0 || o->density_unit >= 0 || o->subgrid_detail > 0;
    const int generated = !strncmp(s->volume.source, "generate:", 9), simulated = !strncmp(s->volume.source, "simulate:", 9);
    if ((file_only && generated) || (given && simulated))
        return cli_usage_error(C, "--grids, --time-index, --density-unit and --subgrid-detail apply to a volume file, "
                                  "not to a generated volume; --particle (its cloud droplets' type) not to a "
                                  "simulated one");
    if (generated && o->volume_scale > 0 &&
        !(o->volume_scale >= ATMOS_GENERATE_SCALE_MIN && o->volume_scale <= ATMOS_GENERATE_SCALE_MAX))
        return cli_usage_error(C, "--volume-scale: expected a factor in [%g, %g] for a generated volume, got %g",
                               ATMOS_GENERATE_SCALE_MIN, ATMOS_GENERATE_SCALE_MAX, o->volume_scale);
    if (o->grids) snprintf(s->volume.grids, sizeof s->volume.grids, "%s", o->grids);
    if (o->particle) snprintf(s->volume.particle, sizeof s->volume.particle, "%s", o->particle);
    if (o->time_index >= 0) s->volume.time_index = o->time_index;
    if (o->density_unit >= 0) s->volume.density_unit = (atmos_density_unit)o->density_unit;
    if (o->voxel_size > 0) s->volume.voxel_size_m = o->voxel_size;
    if (o->volume_scale > 0) s->volume.scale = o->volume_scale;
    if (o->subgrid_detail > 0) s->volume.subgrid_detail = o->subgrid_detail;
    return CLI_EXIT_OK;
}

/* The image, camera, wavelengths and exposure. */
static int apply_view(const render_opts *o, atmos_scene *s)
{
    const char *C = o->cmd;
    if (o->width) s->width = o->width;
    if (o->height) s->height = o->height;
    if (o->png_bits) s->png_bits = o->png_bits;
    if (o->exr_half) s->exr_half = 1;
    if (o->cam_type >= 0 && o->cam_type != (int)s->camera.type) {
        /* A new camera type starts from that type's defaults, keeping the position. */
        double pos[3] = {s->camera.position[0], s->camera.position[1], s->camera.position[2]};
        atmos_camera_defaults((atmos_camera_type)o->cam_type, pos, &s->camera);
    }
    if (!isnan(o->altitude)) {
        double dy = o->altitude - s->camera.position[1];
        s->camera.position[1] = o->altitude;
        s->camera.look_at[1] += dy; /* keep the view direction */
    }
    apply_camera(o, &s->camera);
    if (o->spectral) s->wavelengths = ATMOS_WAVELENGTHS_SPECTRAL, s->spectral_samples = o->spectral;
    if (o->rgb) s->wavelengths = ATMOS_WAVELENGTHS_RGB;
    if (o->exposure_auto && s->tonemap.manual_exposure) /* the scene's EV is no compensation */
        s->tonemap.manual_exposure = 0, s->tonemap.exposure_ev = 0;
    if (!isnan(o->ev)) s->tonemap.manual_exposure = 1, s->tonemap.exposure_ev = o->ev;
    if (!isnan(o->ev_comp)) {
        if (s->tonemap.manual_exposure) return cli_usage_error(C, "--exposure-comp applies to automatic exposure only");
        s->tonemap.exposure_ev = o->ev_comp;
    }
    if (o->tone >= 0) s->tonemap.curve = (atmos_tone_curve)o->tone;
    /* the kind of air (a vacuum background stays a vacuum) */
    static const atmos_atmosphere_kind kinds[] = {ATMOS_ATMOSPHERE_RILEY, ATMOS_ATMOSPHERE_HOMOGENEOUS,
                                                  ATMOS_ATMOSPHERE_DOBASHI, ATMOS_ATMOSPHERE_SPHERICAL};
    if (o->air >= 0 && s->atmosphere.kind != ATMOS_ATMOSPHERE_VACUUM) s->atmosphere.kind = kinds[o->air];
    if (o->thickness > 0 && s->atmosphere.kind != ATMOS_ATMOSPHERE_HOMOGENEOUS)
        return cli_usage_error(C, "--thickness goes with the homogeneous atmosphere (the model here is %s)",
                               cli_sky_model_name(s->atmosphere.kind));
    if (o->thickness > 0) s->atmosphere.thickness_m = o->thickness;
    return CLI_EXIT_OK;
}

/* A volume source's kind: 0 a file, 1 generated, 2 simulated. */
static int source_kind(const char *src)
{
    return !strncmp(src, "generate:", 9) ? 1 : !strncmp(src, "simulate:", 9) ? 2 : 0;
}

/* The renderer, the volume and the renderers' settings. */
static int apply_renderer(const render_opts *o, atmos_scene *s)
{
    const char *C = o->cmd;
    if (o->volume) {
        /* a file's "particle" is its one field's type, not a generated cloud's droplets: it goes
         * with the source it was given for (--particle sets it again) */
        if (source_kind(o->volume) != source_kind(s->volume.source)) s->volume.particle[0] = '\0';
        snprintf(s->volume.source, sizeof s->volume.source, "%s", o->volume);
        if (s->renderer == ATMOS_RENDERER_SKY) s->renderer = ATMOS_RENDERER_SLICE;
    }
    if (o->renderer >= 0) s->renderer = (atmos_renderer_kind)o->renderer;
    const atmos_renderer_kind r = s->renderer;
    if (r == ATMOS_RENDERER_SKY && (o->volume || o->density_scale > 0 || o->volume_pos_given || o->tau || o->grids ||
                                    o->particle || o->time_index >= 0 || o->density_unit >= 0 || o->voxel_size > 0 ||
                                    o->volume_scale > 0 || o->subgrid_detail > 0))
        return cli_usage_error(C, "--volume, --volume-position, --density-scale, --tau and the volume file's options "
                                  "go with a volume renderer, not --renderer sky");
    if (r != ATMOS_RENDERER_PATH && (o->variance || o->order))
        return cli_usage_error(C, "--variance and --order go with --renderer path");
    for (int i = 0; i < o->nset; i++) {
        const render_setting *rs = &o->set[i];
        if (rs->renderer == r) {
            atmos_scene_setting_set(s, rs->setting, rs->value);
        } else if (rs->setting->offset == offsetof(atmos_scene, path.spp)) {
            if (rs->value > 256)
                return cli_usage_error(C, "--spp: must be in [1, 256] for this renderer (1..1000000 with --renderer path)");
            s->samples_per_pixel = (int)rs->value;
        } else {
            return cli_usage_error(C, "--%s goes with --renderer %s", rs->setting->flag, atmos_renderer_name(rs->renderer));
        }
    }
    if (apply_volume_file(o, s) != CLI_EXIT_OK) return CLI_EXIT_USAGE;
    if (o->volume_pos_given) s->volume.placed = 1, memcpy(s->volume.position_m, o->volume_pos, sizeof o->volume_pos);
    /* A factor on the scene's (or -D volume.density_scale's) value, as --help says. */
    if (o->density_scale > 0)
        s->volume.density_scale = (s->volume.density_scale > 0 ? s->volume.density_scale : 1.0) * o->density_scale;
    if (o->tau && !s->volume.source[0]) return cli_usage_error(C, "--tau needs a volume (--volume or a scene with one)");
    const int vl = o->exr_layers & (RENDER_LAYER_TAU | RENDER_LAYER_TRANSMITTANCE);
    if (vl && !s->volume.source[0])
        return cli_usage_error(C, "--exr-layers %s: %s a volume (--volume or a scene with one)",
                               vl == RENDER_LAYER_TAU ? "tau" : vl == RENDER_LAYER_TRANSMITTANCE ? "transmittance" : "tau, transmittance",
                               vl == (RENDER_LAYER_TAU | RENDER_LAYER_TRANSMITTANCE) ? "they need" : "it needs");
    const int pl = o->exr_layers & (RENDER_LAYER_ORDER | RENDER_LAYER_VARIANCE);
    if (pl && s->renderer != ATMOS_RENDERER_PATH)
        return cli_usage_error(C, "--exr-layers %s: %s the path tracer's (--renderer path)",
                               pl == RENDER_LAYER_ORDER ? "order" : pl == RENDER_LAYER_VARIANCE ? "variance" : "order, variance",
                               pl == (RENDER_LAYER_ORDER | RENDER_LAYER_VARIANCE) ? "they are" : "it is");
    if (!o->scene_path && (r == ATMOS_RENDERER_SLICE || r == ATMOS_RENDERER_NISHITA || r == ATMOS_RENDERER_HARRIS) &&
        !s->volume.source[0])
        return cli_usage_error(C, "--renderer %s needs --volume SOURCE (a file, generate:NAME or simulate:PRESET)",
                                atmos_renderer_name(r));
    return CLI_EXIT_OK;
}

int render_opts_apply(atmos_context *ctx, const render_opts *o, atmos_scene *scene)
{
    int rc = apply_view(o, scene);
    if (rc == CLI_EXIT_OK) rc = apply_sun(ctx, o, scene);
    if (rc == CLI_EXIT_OK) rc = apply_renderer(o, scene);
    return rc;
}

/* A number for --help: integers in full (2^53, not 9.0072e+15), others as %g. */
static const char *num(char *buf, size_t cap, double v)
{
    if (v == floor(v) && fabs(v) < 1e17) snprintf(buf, cap, "%.0f", v);
    else snprintf(buf, cap, "%g", v);
    return buf;
}

#define NBSP '\x1f' /* a space --help's wrapping does not break at */

/* An option and its text in --help's two columns, the text wrapped at 100 characters on
 * word boundaries (a word longer than the column runs on). */
static void help_wrapped(const char *opt, const char *text)
{
    enum { LEFT = 30, WIDTH = 100 };
    int col = printf("      %-24s", opt);
    const char *w = text;
    while (*w) {
        size_t n = strcspn(w, " ");
        if (col > LEFT && col + 1 + (int)n > WIDTH) printf("\n%*s", LEFT, ""), col = LEFT;
        col += printf(" ");
        for (size_t k = 0; k < n; k++) putchar(w[k] == NBSP ? ' ' : w[k]); /* a range stays on one line */
        col += (int)n;
        w += n;
        while (*w == ' ') w++;
    }
    printf("\n");
}

/* One --help line per settings row: flag, argument, doc, range and default; a flag that
 * turns a setting off says so. */
static void help_settings(atmos_renderer_kind r, const char *title)
{
    int n;
    const atmos_setting *t = atmos_renderer_settings(r, &n);
    const int len = (int)strlen(title) + (int)strlen(atmos_renderer_name(r)) + 45;
    printf("%s%s(the scene's \"%s\" section; docs/scene-format.md):\n", title, len > 100 ? "\n  " : " ",
           atmos_renderer_name(r));
    for (int i = 0; i < n; i++) {
        const atmos_setting *s = &t[i];
        if (!s->flag) continue;
        char opt[64], range[128] = "", a[32], b[32], c[32];
        snprintf(opt, sizeof opt, "--%s%s", s->flag, !takes_value(s) ? "" : s->type == ATMOS_SETTING_REAL ? " X" : " N");
        if (takes_value(s) && strstr(s->doc, ", in (")) /* the doc states an irregular range itself */
            snprintf(range, sizeof range, ", default %s", num(c, sizeof c, s->def));
        else if (takes_value(s))
            snprintf(range, sizeof range, " [%s%s, %s%s%s%s], default %s", s->min_open ? "> " : "", num(a, sizeof a, s->min),
                     num(b, sizeof b, s->max), s->max_open ? ")" : "", s->unit[0] ? " " : "", s->unit,
                     num(c, sizeof c, s->def));
        int inside = 0; /* " [min, max unit], default d": the bracket and "default d" unbroken */
        for (char *q = range + 1; *q; q++) {
            inside = *q == '[' ? 1 : *q == ']' ? 0 : inside;
            if (*q == ' ' && (inside || q[-1] == 't')) *q = NBSP;
        }
        char text[1024];
        snprintf(text, sizeof text, "%s%s%s", strncmp(s->flag, "no-", 3) ? "" : "turns off (on by default): ", s->doc,
                 range);
        help_wrapped(opt, text);
    }
    printf("\n");
}

/* Words into --help's right column, wrapped at 100 characters: "a, b, c" then tail. */
static void help_list(int *col, const char *const *names, const char *tail)
{
    for (const char *const *n = names; *n; n++) {
        const int w = (int)strlen(*n) + (n[1] ? 2 : (int)strlen(tail));
        if (*col + 1 + w > 100) printf("\n%31s", ""), *col = 31;
        *col += printf(" %s%s", *n, n[1] ? "," : tail);
    }
}

/* The --volume paragraph: the generators and the simulation's presets from the library's own
 * lists, so that --help names every source a scene's "volume" takes. */
static void help_volume(void)
{
    printf("      --volume SOURCE           a cloud volume: a file (.vdb OpenVDB, .nvdb NanoVDB, .nc WRF or CM1\n"
           "                                NetCDF, .json raw float32 + sidecar; docs/volumes.md),\n"
           "                                generate:NAME, a generated one (docs/volumes.md, harris_*: Harris's\n"
           "                                particle clouds, docs/particles.md):");
    int col = 100;
    help_list(&col, atmos_scene_generator_names(), ";");
    printf("\n                                or simulate:PRESET, grown by the cloud simulation (docs/clouds.md):");
    col = 100;
    help_list(&col, atmos_sim_preset_names(), "\n");
}

/* The usage line, what the command does and the options up to --volume. */
static void help_head(void)
{
    printf("Usage: atmos render [SCENE.json|-] [-o OUT.png] [--exr OUT.exr] [--pfm OUT.pfm] [options]\n\n"
           "Renders a scene file ('-': read from standard input), or the built-in default scene when none\n"
           "is given. With no output option, writes NAME.png in the current directory (NAME = the scene\n"
           "file's name without its extension; the scene's \"name\" for the default scene or standard input).\n"
           "A volume file is rendered with --volume FILE (not as the scene). The files a scene names\n"
           "(its volume, the lights' images, the objects' meshes and terrains) are relative to the scene\n"
           "file's folder; those of a scene from standard input are relative to the current folder, as\n"
           "are files given on the command line (--volume FILE, -D lights.0.image=FILE).\n\n"
           "Outputs (the format is the extension's; folders are created; every output is checked\n"
           "before rendering and all are written or none: two options naming the same file, or\n"
           "an output that is an input, are refused):\n"
           "  -o, --output FILE       .png: tone-mapped sRGB PNG (8 or 16 bit, see --png-bits);\n"
           "                          .exr or .pfm: the HDR image, as --exr / --pfm write it\n"
           "      --exr FILE.exr      HDR OpenEXR: linear sRGB + alpha, Y in cd/m^2, scene metadata\n"
           "                          (numbers as numbers) and the chromaticities (Rec. 709, D65)\n"
           "      --pfm FILE.pfm      HDR portable float map (linear sRGB, 3 channels)\n"
           "      --png-bits 8|16     PNG bit depth (default: scene, 8)\n"
           "      --exr-half          write EXR as 16-bit half floats (default: 32-bit float); values\n"
           "                          beyond the largest half (65504, e.g. the sun's disc) are clamped\n"
           "                          to 65504 with a warning\n"
           "      --exr-layers LIST   more layers in the EXR file (--exr, else -o X.exr) beside R,G,B,A,\n"
           "                          comma-separated: tau (tau.Y, the volume's optical depth along the\n"
           "                          pixel's ray), transmittance (transmittance.Y = exp(-tau)), and with\n"
           "                          the path tracer order (order.Y) and variance (variance.<nm>nm,\n"
           "                          variance.Y)\n"
           "      --tau FILE.pfm      also write the volume's optical depth along each pixel's ray\n"
           "                          (middle wavelength of the set; a key for atmos compare --by)\n"
           "      --variance FILE.exr path: per-pixel variance of the mean (channels variance.<nm>nm per\n"
           "                          wavelength, then variance.Y of the luminance)\n"
           "      --order FILE.pfm    path: per-pixel mean number of volume scattering events of the light\n"
           "                          reaching the pixel, weighted by luminance (a key for atmos compare --by)\n\n"
           "Overrides of the scene's settings:\n"
           "      --width W --height H      image size in pixels\n"
           "      --spp N                   sky and slice renderers: stratified samples of the sky per pixel\n"
           "                                (1..256); path tracer: its samples per pixel (below); beams:\n"
           "                                n x n rays a pixel, n = round(sqrt(N)) (antialiasing; 1 default)\n"
           "      --camera TYPE             pinhole | fisheye (180 deg, looking up) | equirect (360x180 map);\n"
           "                                the slice and beams renderers take pinhole only, the others all\n"
           "      --altitude M              camera altitude above sea level, metres (not with --position)\n"
           "      --position X,Y,Z          camera position, metres (x east, y up, z south); keeps the view\n"
           "                                direction unless --look-at is given\n"
           "      --look-at X,Y,Z           the point the camera looks at, metres\n"
           "      --view-elevation E        the view direction's elevation, degrees in [-90, 90] (negative:\n"
           "                                down; at -90 the image's top faces the view azimuth)\n"
           "      --view-azimuth A          the view direction's azimuth, degrees in [0, 360) clockwise from\n"
           "                                north\n"
           "      --fov DEG                 field of view: pinhole vertical, fisheye across the circle\n"
           "                                (a volume file with no camera given is framed: placed, and the\n"
           "                                camera pointed at it from where the whole box shows)\n"
           "      --sun-elevation E         sun elevation, degrees in [-90, 90]\n"
           "      --sun-azimuth A           sun azimuth, degrees in [0, 360) clockwise from north\n"
           "      --time T --lat L --lon L  sun from a time (2026-06-21T12:00:00Z, or an offset +HH:MM/-HH:MM;\n"
           "                                years 1800-2200) and a place: L in degrees north and degrees\n"
           "                                east (south and west negative); --time alone keeps a scene's\n"
           "                                place. Over a round planet (\"dobashi\", \"spherical\") the\n"
           "                                place is the atmosphere's origin's too: --lat and --lon\n"
           "                                turn the Earth's map under the camera, and the sun stands\n"
           "                                over the map where the date and time put it\n"
           "      --spectral N              N spectral samples in 380-780 nm (default: the paper's rgb)\n"
           "      --rgb                     the paper's three channels (680, 550, 440 nm)\n"
           "      --exposure EV|auto        manual exposure (EV100, daylight ~15) or automatic\n"
           "      --exposure-comp STOPS     compensation added to automatic exposure\n"
           "      --exposure-per-frame      animations: automatic exposure chosen for each frame; by\n"
           "                                default the frame with the highest sun's is kept for all (a\n"
           "                                locked exposure; the scene's animation.exposure: locked |\n"
           "                                per_frame). Either way at most that of EV100 -2 (a camera's\n"
           "                                30 s at f/2.8: night stays dark; animation.exposure_limit_ev)\n"
           "      --tone filmic|reinhard|clamp   tone curve for the PNG\n"
           "      --threads N               worker threads (default: all cores)\n"
           "      --mpi                     share the work between the ranks of an MPI job (mpirun -np N\n"
           "                                atmos render ... --mpi): an animation's frames go round the\n"
           "                                ranks, a single image's bands of rows are split between them;\n"
           "                                rank 0 writes every output, the same bytes as one process\n"
           "                                (docs/cluster.md; not with --variance or --order)\n"
           "      --renderer sky|slice|path|nishita|harris|beams   the atmosphere alone (default), Riley et\n"
           "                                al.'s half-angle slicing over a volume (default when a volume is\n"
           "                                given), spectral Monte Carlo path tracing (the reference,\n"
           "                                docs/path.md), Nishita et al. 1996's ray marching with orders 2-3\n"
           "                                and sky light from a light field (docs/lightfield.md), or\n"
           "                                Harris's particle clouds (the volume as particles,\n"
           "                                docs/particles.md), or Dobashi et al. 2002's light beams of the\n"
           "                                scene's \"lights\" in its \"fog\" with the shadows of its \"objects\"\n"
           "                                (docs/beams.md)\n"
           );
}

void render_opts_help(void)
{
    help_head();
    help_volume();
    printf(
           "      --volume-position X,Y,Z   where the centre of the volume box's bottom face goes, metres\n"
           "                                (default: 3 widths, at least 4 km, in front of the camera; a\n"
           "                                VDB/NanoVDB file's base at 1500 m, a cloud's)\n"
           "      --density-scale S         multiplies the volume's densities (a factor on the scene's\n"
           "                                volume.density_scale; -D volume.density_scale=S sets it)\n"
           "      --density-unit U          what a volume file's values are: per_m3 (particles per m^3), g_m3\n"
           "                                (water content, by the particle's mean mass), fraction (0..1, 1 =\n"
           "                                1e8 m^-3, a cumulus), auto (default: VDB fraction, raw per_m3,\n"
           "                                NetCDF its mixing ratios)\n"
           "      --voxel-size M            NetCDF: the resampling voxel (default: the model's mean layer depth,\n"
           "                                or DX if finer); VDB/raw: the voxel edge replacing the file's\n"
           "      --volume-scale S          generators: extent factor in [0.05, 20]; VDB/raw files: multiplies\n"
           "                                their lengths, (0, 100] (0.01: a file in centimetres)\n"
           "      --grids LIST              VDB grids or NetCDF variables to load (comma-separated)\n"
           "      --particle NAME           particle type of a single-grid VDB/raw file or of a generated\n"
           "                                volume's cloud droplets (default cloud)\n"
           "      --time-index N            NetCDF time step (default 0)\n"
           "      --subgrid-detail A        NetCDF, for artists: a fractal texture below the model's grid,\n"
           "                                amplitude A in (0, 1] (not model data; default off)\n"
           "  -D, --define PATH=VALUE      sets a scene key before the scene is read, as if in the file:\n"
           "                                PATH dotted (camera.fov_deg) or a JSON pointer (/camera/fov_deg),\n"
           "                                VALUE JSON (35, [0, 900, 0]) or a bare word (a string); repeatable;\n"
           "                                with --volume, -D volume.KEY applies to that volume; a -D setting\n"
           "                                volume.file, .generate or .simulate replaces the scene's source\n"
           "      --atmosphere MODEL        the air, in place of the scene's: riley (Riley et al.'s\n"
           "                                exponential atmosphere over a flat earth), homogeneous (a uniform\n"
           "                                layer up to --thickness; docs/models.md), dobashi or spherical (a\n"
           "                                spherical earth with aerosols and ozone; docs/sky.md); a scene in\n"
           "                                a vacuum (\"background\") keeps its vacuum\n"
           "      --thickness M             the homogeneous layer's top, metres (default 8000); goes with\n"
           "                                the homogeneous atmosphere (with another, a usage error)\n\n");
    printf("One rule for every renderer: an option of another renderer than the one rendering is refused\n"
           "(exit 2, naming the renderer it goes with); --spp is the one option all renderers share. A scene\n"
           "file may keep a section for each renderer (\"slice\", \"path\", \"nishita\", \"harris\", \"beams\":\n"
           "--renderer switches between them); only the rendering renderer's is used.\n\n");
    help_settings(ATMOS_RENDERER_SLICE, "Slice renderer");
    help_settings(ATMOS_RENDERER_PATH, "Path tracer");
    help_settings(ATMOS_RENDERER_NISHITA, "Nishita renderer (Nishita et al. 1996: orders 2-3 and sky light by a light field)");
    help_settings(ATMOS_RENDERER_HARRIS, "Harris's particle renderer");
    help_settings(ATMOS_RENDERER_BEAMS, "Beam renderer (Dobashi et al. 2002 §4: sampling planes, sub-planes, shadow maps)");
    printf("Animation (the sun moves; the volume, its optics and the renderer's plan are made once; a\n"
           "simulated volume with \"animation\": {\"minutes_end\": M} grows instead, a volume and a plan a\n"
           "frame from one simulation carried through the frames, docs/clouds.md):\n"
           "      --frames N                render N frames (default: the scene's \"animation\", else 1);\n"
           "                                more than one frame numbers every output (--tau too): -o\n"
           "                                out/sky.png writes out/sky_0001.png ...; --frames 1: the first\n"
           "                                frame, as named\n"
           "                                (automatic exposure: the highest sun's frame's for all\n"
           "                                frames, see --exposure-per-frame)\n"
           "      --time-end T              the last frame's UTC time (a sun given by time); frames are\n"
           "                                spaced evenly in time from the scene's (or --time's) time\n"
           "      --sun-elevation-end E     the last frame's sun elevation (a sun given by angles)\n"
           "      --sun-azimuth-end A       the last frame's sun azimuth, [0, 360) (the shorter way round)\n"
           "  -q, --quiet                   no progress bar or status lines (warnings and errors are\n"
           "                                still printed)\n"
           "  -h, --help                    show this help\n\n"
           "Examples:\n"
           "  atmos render -o sky.png --exr sky.exr\n"
           "  atmos render scenes/sunset_fisheye.json --spectral 32 -o sunset.png\n"
           "  atmos render --camera equirect --width 2048 --height 1024 --exr env.exr\n"
           "  atmos render --volume wdas_cloud_sixteenth.vdb --renderer path --spp 64\n"
           "  atmos render --volume wrfout_d01.nc --time-index 6 --grids QCLOUD,QICE --view-elevation -45\n"
           "  atmos render scenes/fig06_halo_cirrus.json -D camera.fov_deg=30 -D renderer=path\n"
           "  atmos render scenes/fig01_cirrus_sunrise.json --frames 8 --time-end 2026-06-21T12:30:00Z \\\n"
           "      -o out/cirrus.png\n");
    fputs(CLI_HELP_EXIT, stdout);
}
