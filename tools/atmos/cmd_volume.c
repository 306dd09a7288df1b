/* atmos volume: inspect, generate and slice volumes. No physics here. */
#include "cli.h"
#include "outputs.h"
#include "sidecar_inputs.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *C = "volume";

void cli_volume_help(void)
{
    printf("Usage: atmos volume info FILE [--json] [reading options]\n"
           "       atmos volume generate PRESET -o NAME.json [--seed N] [--voxel-size M] [--scale S]\n"
           "                 [--threads T] [-q]\n"
           "       atmos volume slice FILE --axis x|y|z [--at F] [--field NAME] -o SLICE.png [reading options]\n"
           "       atmos volume clouds SCENE.json -o NAME.json [--centre X,Z] [--half-width M] [--voxel-size M]\n");
    cli_volume_stats_usage();
    printf("\n"
           "  info      fields, dimensions, world-space bounds (metres, after the grid transform), value\n"
           "            ranges (number densities, m^-3), active voxels and memory of a volume file\n"
           "            (.json raw sidecar, .vdb, .nvdb, .nc). --json prints\n"
           "            {\"fields\": [{\"name\", \"particle\", \"active_voxels\", \"nonzero_voxels\", \"min\", \"max\",\n"
           "             \"bounds_m\"}], \"dims\", \"voxel_size_m\", \"origin_m\", \"grid_bounds_m\", \"memory_bytes\",\n"
           "             \"periodic\"}.\n"
           "            active_voxels is the file's own count where it has one (OpenVDB, NanoVDB: active\n"
           "            tiles count as the voxels they cover, active zeros included), else the voxels > 0.\n"
           "  generate  builds a preset cloud volume and writes it as raw float32 files plus a JSON\n"
           "            sidecar. Presets: ");
    int col = 30; /* "            sidecar. Presets: " */
    for (const char *const *n = atmos_scene_generator_names(); *n; n++) {
        if (col + (int)strlen(*n) + 2 > 100) printf("\n            "), col = 12;
        col += printf("%s%s", *n, n[1] ? "," : "\n");
        if (n[1] && col + (int)strlen(n[1]) + 3 <= 100) col += printf(" ");
    }
    printf("            --seed (default 1) picks the random shape; --voxel-size overrides the preset's\n"
           "            voxel edge in metres; --scale S, in [0.05, 20] (or atmos render's --volume-scale),\n"
           "            multiplies its extent (default 1).\n"
           "  slice     writes a grey PNG of one field's density in the plane at fraction F (default 0.5)\n"
           "            of the grid along AXIS, normalised by the slice's maximum; y is up in the image (a\n"
           "            missing folder is made).\n"
           "  clouds    the cloud layer of SCENE's spherical atmosphere (\"clouds\" from a satellite image) as\n"
           "            a raw + JSON volume of \"cloud\" particles with the same optical depths, in the\n"
           "            world frame (x east, y up, z south at the scene's latitude/longitude): a box\n"
           "            2 M wide around (X, Z) (default 0,0; half width 20000 m) from the layer's base to\n"
           "            its top, voxels of --voxel-size metres (default 500; at most 8192 across the box).\n");
    cli_volume_stats_help();
    printf("\n"
           "Reading options (info, slice, stats):\n"
           "  --grids LIST      VDB/NanoVDB grids or NetCDF variables to read (comma-separated)\n"
           "  --as NAME         field name for a single-grid file (default cloud)\n"
           "  --scale S         multiplies the file's values (after the density unit's conversion)\n"
           "  --density-unit U  what a VDB/raw file's values are: per_m3, g_m3 (water content, by the\n"
           "                    particle's mean mass), fraction (0..1, 1 = 1e8 m^-3) or auto (default:\n"
           "                    VDB fraction, raw per_m3; NetCDF: its mixing ratios, auto only)\n"
           "  --length-scale F  multiplies a VDB/raw file's lengths (0.01: a file in centimetres)\n"
           "  --time-index N    NetCDF time step (default 0; as atmos render's --time-index;\n"
           "                    --time N is the same)\n"
           "  --voxel-size M    NetCDF: resampling voxel edge in metres (default: the model's mean layer\n"
           "                    depth or DX if finer, at most 8.4 M voxels, at least 8 over the depth);\n"
           "                    VDB/raw: the voxel edge replacing the file's (its origin scaled with it)\n"
           "  --max-memory MB   refuse volumes that would need more memory\n"
           "atmos render's names of the same options are taken too: --particle NAME (--as), --density-scale S\n"
           "(--scale) and --volume-scale F (--length-scale; generate: --scale, the extent).\n" CLI_HELP_EXIT);
}

static int load(const char *path, atmos_context *ctx, const atmos_volume_load_desc *d, atmos_volume **v)
{
    atmos_status st = atmos_volume_load(ctx, path, d, v);
    return st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
}

static cJSON *vec3(const double *v) { return cJSON_CreateDoubleArray(v, 3); }

static int cmd_info(int argc, char **argv)
{
    const char *file = NULL;
    int json = 0, r;
    atmos_volume_load_desc ld;
    memset(&ld, 0, sizeof ld);
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            cli_volume_help();
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "--json")) {
            json = 1;
        } else if ((r = cli_volume_load_option(argc, argv, &i, &ld)) != 0) {
            if (r < 0) return CLI_EXIT_USAGE;
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "info: unknown or incomplete option '%s'", argv[i]);
        } else if (!file) {
            file = argv[i];
        } else {
            return cli_usage_error(C, "info: unexpected argument '%s'", argv[i]);
        }
    }
    if (!file) return cli_usage_error(C, "info: which file?");
    atmos_context *ctx = cli_context(0, 0); /* warnings (e.g. a coarse NetCDF voxel) reach the user */
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_volume *v = NULL;
    int rc = load(file, ctx, &ld, &v);
    if (rc != CLI_EXIT_OK) {
        atmos_context_destroy(ctx);
        return rc;
    }
    const atmos_volume_desc *d = atmos_volume_get_desc(v);
    double lo[3], hi[3];
    atmos_volume_bounds(v, lo, hi);
    if (json) {
        cJSON *root = cJSON_CreateObject(), *fields = cJSON_CreateArray();
        cJSON_AddItemToObject(root, "fields", fields);
        for (int f = 0; f < atmos_volume_field_count(v); f++) {
            atmos_volume_field_stats s;
            atmos_volume_field_stats_get(ctx, v, f, &s);
            cJSON *o = cJSON_CreateObject(), *b = cJSON_CreateArray();
            cJSON_AddStringToObject(o, "name", atmos_volume_field_name(v, f));
            cJSON_AddStringToObject(o, "particle", atmos_volume_field_particle(v, f));
            /* "active" as the file counts it when it has its own count (OpenVDB/NanoVDB:
             * tiles as the voxels they cover, active zeros included), else voxels > 0 */
            cJSON_AddNumberToObject(o, "active_voxels",
                                    (double)(s.file_active_voxels ? s.file_active_voxels : s.active_voxels));
            cJSON_AddNumberToObject(o, "nonzero_voxels", (double)s.active_voxels);
            cJSON_AddNumberToObject(o, "min", s.min);
            cJSON_AddNumberToObject(o, "max", s.max);
            if (!s.active_voxels) memset(s.bounds_m, 0, sizeof s.bounds_m);
            cJSON_AddItemToArray(b, vec3(s.bounds_m[0]));
            cJSON_AddItemToArray(b, vec3(s.bounds_m[1]));
            cJSON_AddItemToObject(o, "bounds_m", b);
            cJSON_AddItemToArray(fields, o);
        }
        double dims[3] = {d->dims[0], d->dims[1], d->dims[2]};
        cJSON_AddItemToObject(root, "dims", cJSON_CreateDoubleArray(dims, 3));
        cJSON_AddNumberToObject(root, "voxel_size_m", d->voxel_size_m);
        cJSON_AddItemToObject(root, "origin_m", vec3(d->origin_m));
        cJSON *gb = cJSON_CreateArray();
        cJSON_AddItemToArray(gb, vec3(lo));
        cJSON_AddItemToArray(gb, vec3(hi));
        cJSON_AddItemToObject(root, "grid_bounds_m", gb);
        cJSON_AddNumberToObject(root, "memory_bytes", (double)atmos_volume_memory(v));
        cJSON_AddBoolToObject(root, "periodic", d->periodic);
        char *text = cJSON_Print(root);
        if (text) printf("%s\n", text);
        free(text);
        cJSON_Delete(root);
    } else {
        printf("%s\n  grid %d x %d x %d voxels of %g m, origin (%g, %g, %g) m\n", file, d->dims[0], d->dims[1],
               d->dims[2], d->voxel_size_m, d->origin_m[0], d->origin_m[1], d->origin_m[2]);
        printf("  grid bounds (%g, %g, %g) .. (%g, %g, %g) m\n", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
        printf("  memory %.3f MB\n", atmos_volume_memory(v) / 1048576.0);
        if (d->periodic) printf("  periodic: the grid wraps round along x and z (a simulation's sides)\n");
        for (int f = 0; f < atmos_volume_field_count(v); f++) {
            atmos_volume_field_stats s;
            atmos_volume_field_stats_get(ctx, v, f, &s);
            printf("  field %-8s particle %-8s ", atmos_volume_field_name(v, f), atmos_volume_field_particle(v, f));
            if (s.file_active_voxels)
                printf("active voxels %llu in the file (tiles counted in full), %llu > 0", (unsigned long long)s.file_active_voxels,
                       (unsigned long long)s.active_voxels);
            else
                printf("active voxels %llu", (unsigned long long)s.active_voxels);
            printf(", density %g .. %g m^-3", s.min, s.max);
            if (s.active_voxels)
                printf(", bounds (%g, %g, %g) .. (%g, %g, %g) m", s.bounds_m[0][0], s.bounds_m[0][1], s.bounds_m[0][2],
                       s.bounds_m[1][0], s.bounds_m[1][1], s.bounds_m[1][2]);
            printf("\n");
        }
    }
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return CLI_EXIT_OK;
}

/* The files atmos_volume_write_raw(v, out) will write, checked before it writes any
 * (cli_raw_outputs, as atmos simulate checks its own). */
static int raw_outputs(const char *out, const atmos_volume *v, cli_outputs *set)
{
    static char raw[CLI_OUTPUTS_MAX][CLI_OUTPUT_PATH_MAX];
    const char *fields[CLI_OUTPUTS_MAX];
    int n = 0;
    for (; n < atmos_volume_field_count(v) && n + 1 < CLI_OUTPUTS_MAX; n++) fields[n] = atmos_volume_field_name(v, n);
    return cli_raw_outputs(C, out, fields, n, raw, set);
}

static int cmd_generate(int argc, char **argv)
{
    const char *preset = NULL, *out = NULL;
    atmos_volume_generate_desc g;
    memset(&g, 0, sizeof g);
    g.seed = 1;
    int threads = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            cli_volume_help();
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "-o") && i + 1 < argc) {
            out = argv[++i];
            if (!*out) return cli_usage_error(C, "-o: expected a file name");
        } else if (!strcmp(argv[i], "-q") || !strcmp(argv[i], "--quiet")) {
            /* as every command takes it: generate prints nothing but errors anyway */
        } else if (!strcmp(argv[i], "--seed") && i + 1 < argc) {
            unsigned long long s = 0;
            if (!cli_parse_seed(C, argv[++i], &s)) return CLI_EXIT_USAGE;
            g.seed = s;
        } else if (!strcmp(argv[i], "--voxel-size") && i + 1 < argc) {
            if (!cli_parse_double(C, "--voxel-size", argv[++i], &g.voxel_size_m)) return CLI_EXIT_USAGE;
            if (g.voxel_size_m <= 0) return cli_usage_error(C, "--voxel-size: must be > 0");
        } else if ((!strcmp(argv[i], "--scale") || !strcmp(argv[i], "--volume-scale")) && i + 1 < argc) {
            if (!cli_parse_double(C, argv[i], argv[i + 1], &g.scale)) return CLI_EXIT_USAGE; /* render's name too */
            i++;
            if (!(g.scale >= ATMOS_GENERATE_SCALE_MIN && g.scale <= ATMOS_GENERATE_SCALE_MAX))
                return cli_usage_error(C, "%s: expected a factor in [%g, %g], got %s", argv[i - 1],
                                       ATMOS_GENERATE_SCALE_MIN, ATMOS_GENERATE_SCALE_MAX, argv[i]);
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            if (!cli_parse_int(C, "--threads", argv[++i], 1, 1024, &threads)) return CLI_EXIT_USAGE;
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "generate: unknown or incomplete option '%s'", argv[i]);
        } else if (!preset) {
            preset = argv[i];
        } else {
            return cli_usage_error(C, "generate: unexpected argument '%s'", argv[i]);
        }
    }
    if (!preset) return cli_usage_error(C, "generate: which preset?");
    if (!out) return cli_usage_error(C, "generate: missing -o NAME.json");
    char list[512];
    if (!atmos_scene_generator_known(preset, list, sizeof list))
        return cli_usage_error(C, "generate: unknown preset '%s' (known: %s)", preset, list);
    if (cli_volume_output(C, "-o", out)) return CLI_EXIT_USAGE;
    if (cli_output_folder(C, "-o", out)) return CLI_EXIT_RUNTIME;
    atmos_context *ctx = cli_context(threads, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_volume *v = NULL;
    atmos_status st = atmos_scene_generate_volume(ctx, preset, &g, &v);
    cli_outputs set = {0};
    int rc = st == ATMOS_OK ? raw_outputs(out, v, &set) : CLI_EXIT_OK;
    if (st == ATMOS_OK && rc == CLI_EXIT_OK) st = atmos_volume_write_raw(ctx, v, out);
    if (rc == CLI_EXIT_OK) rc = st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
    cli_outputs_discard(&set); /* the staging files; the library wrote the files themselves */
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return rc;
}

/* A slice with no density is written black, and said so: the whole field is empty (all zero),
 * or only this plane is. */
static void warn_empty_slice(atmos_context *ctx, const atmos_volume *v, int fi, int axis, double at)
{
    atmos_volume_field_stats s;
    const char *name = atmos_volume_field_name(v, fi);
    if (atmos_volume_field_stats_get(ctx, v, fi, &s) != ATMOS_OK || s.active_voxels == 0) {
        fprintf(stderr, "atmos volume: warning: field '%s' is empty (every voxel zero): the slice is black\n", name);
        return;
    }
    fprintf(stderr,
            "atmos volume: warning: the slice at %g along %c holds none of field '%s' (its %llu voxels > 0 lie "
            "elsewhere): the slice is black; another --at or --axis shows them\n",
            at, 'x' + axis, name, (unsigned long long)s.active_voxels);
}

static int cmd_slice(int argc, char **argv)
{
    const char *file = NULL, *out = NULL, *field = NULL;
    int axis = -1, lo;
    double at = 0.5;
    atmos_volume_load_desc ld;
    memset(&ld, 0, sizeof ld);
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            cli_volume_help();
            return CLI_EXIT_OK;
        } else if ((lo = cli_volume_load_option(argc, argv, &i, &ld)) != 0) {
            if (lo < 0) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "-o") && i + 1 < argc) {
            out = argv[++i];
            if (!*out) return cli_usage_error(C, "-o: expected a file name");
        } else if (!strcmp(argv[i], "--field") && i + 1 < argc) {
            field = argv[++i];
        } else if (!strcmp(argv[i], "--axis") && i + 1 < argc) {
            const char *a = argv[++i];
            if (strlen(a) != 1 || !strchr("xyz", a[0])) return cli_usage_error(C, "--axis: expected x, y or z, got '%s'", a);
            axis = a[0] - 'x';
        } else if (!strcmp(argv[i], "--at") && i + 1 < argc) {
            if (!cli_parse_double(C, "--at", argv[++i], &at)) return CLI_EXIT_USAGE;
            if (at < 0 || at > 1) return cli_usage_error(C, "--at: expected a fraction in [0, 1], got %g", at);
            at += 0.0; /* -0 is 0: said so ("the slice at 0") */
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "slice: unknown or incomplete option '%s'", argv[i]);
        } else if (!file) {
            file = argv[i];
        } else {
            return cli_usage_error(C, "slice: unexpected argument '%s'", argv[i]);
        }
    }
    if (!file) return cli_usage_error(C, "slice: which file?");
    if (axis < 0) return cli_usage_error(C, "slice: missing --axis x|y|z");
    if (!out) return cli_usage_error(C, "slice: missing -o SLICE.png");
    if (cli_png_output(C, "-o", out)) return CLI_EXIT_USAGE;
    cli_outputs set = {0};
    cli_outputs_add(&set, "-o", out);
    static char data[64][CLI_OUTPUT_PATH_MAX]; /* a raw volume's data files */
    const char *inputs[1 + 64] = {file};
    int ninputs = 1, ndata = 0;
    cli_sidecar_inputs(file, data, 64, &ndata, inputs, &ninputs);
    if (cli_outputs_check(C, &set, inputs, ninputs)) return CLI_EXIT_USAGE;
    if (cli_output_folder(C, "-o", out)) return CLI_EXIT_RUNTIME;
    atmos_context *ctx = cli_context(0, 0); /* warnings (e.g. a coarse NetCDF voxel) reach the user */
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_volume *v = NULL;
    int rc = load(file, ctx, &ld, &v);
    if (rc != CLI_EXIT_OK) {
        atmos_context_destroy(ctx);
        return rc;
    }
    int fi = 0;
    if (field) {
        fi = -1;
        for (int f = 0; f < atmos_volume_field_count(v); f++)
            if (!strcmp(atmos_volume_field_name(v, f), field)) fi = f;
        if (fi < 0) {
            fprintf(stderr, "atmos volume: %s: no field '%s'; fields:", file, field);
            for (int f = 0; f < atmos_volume_field_count(v); f++) fprintf(stderr, " %s", atmos_volume_field_name(v, f));
            fprintf(stderr, "\n");
            atmos_volume_destroy(v);
            atmos_context_destroy(ctx);
            return CLI_EXIT_RUNTIME;
        }
    }
    const atmos_volume_desc *d = atmos_volume_get_desc(v);
    /* Image axes: (u right, w up) = (x, y) for a z slice, (x, z) for y, (z, y) for x. */
    int ua = axis == 0 ? 2 : 0, wa = axis == 1 ? 2 : 1;
    int width = d->dims[ua], height = d->dims[wa];
    atmos_image *img = NULL;
    atmos_status st = atmos_image_create(ctx, width, height, 1, &img);
    if (st == ATMOS_OK) {
        double q[3], mx = 0;
        q[axis] = at * d->dims[axis];
        if (q[axis] >= d->dims[axis]) q[axis] = d->dims[axis] - 0.5;
        for (int r = 0; r < height; r++)
            for (int c = 0; c < width; c++) {
                q[ua] = c + 0.5;
                q[wa] = height - 1 - r + 0.5;
                double p[3];
                for (int a = 0; a < 3; a++)
                    p[a] = d->origin_m[a] + d->voxel_size_m * (d->rotation[3 * a] * q[0] + d->rotation[3 * a + 1] * q[1] +
                                                               d->rotation[3 * a + 2] * q[2]);
                double val = atmos_volume_sample(v, fi, p);
                img->pixels[(size_t)r * width + c] = (float)val;
                if (val > mx) mx = val;
            }
        for (size_t n = 0; n < (size_t)width * height; n++) img->pixels[n] = mx > 0 ? (float)(img->pixels[n] / mx) : 0;
        if (!(mx > 0)) warn_empty_slice(ctx, v, fi, axis, at);
        char buf[64];
        snprintf(buf, sizeof buf, "%g", mx);
        atmos_image_set_meta(img, "atmos:slice_max_m-3", buf);
        st = atmos_write_png(ctx, img, out, 8);
    }
    rc = st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
    atmos_image_destroy(img);
    atmos_volume_destroy(v);
    atmos_context_destroy(ctx);
    return rc;
}

static int cmd_clouds(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL;
    double centre[2] = {0, 0}, half = 20000, voxel = 500;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            cli_volume_help();
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "-o") && i + 1 < argc) {
            out = argv[++i];
            if (!*out) return cli_usage_error(C, "-o: expected a file name");
        } else if (!strcmp(argv[i], "--centre") && i + 1 < argc) {
            char *end = NULL;
            const char *t = argv[++i];
            centre[0] = strtod(t, &end);
            if (end == t || *end != ',') return cli_usage_error(C, "--centre: expected X,Z in metres, got '%s'", t);
            const char *t2 = end + 1;
            centre[1] = strtod(t2, &end);
            if (end == t2 || *end || !isfinite(centre[0]) || !isfinite(centre[1]))
                return cli_usage_error(C, "--centre: expected X,Z in metres, got '%s'", t);
        } else if (!strcmp(argv[i], "--half-width") && i + 1 < argc) {
            if (!cli_parse_double(C, "--half-width", argv[++i], &half)) return CLI_EXIT_USAGE;
        } else if (!strcmp(argv[i], "--voxel-size") && i + 1 < argc) {
            if (!cli_parse_double(C, "--voxel-size", argv[++i], &voxel)) return CLI_EXIT_USAGE;
        } else if (argv[i][0] == '-') {
            return cli_usage_error(C, "clouds: unknown or incomplete option '%s'", argv[i]);
        } else if (!scene_path) {
            scene_path = argv[i];
        } else {
            return cli_usage_error(C, "clouds: unexpected argument '%s'", argv[i]);
        }
    }
    if (!scene_path) return cli_usage_error(C, "clouds: which scene?");
    if (!out) return cli_usage_error(C, "clouds: missing -o NAME.json");
    if (!(half > 0 && voxel > 0)) return cli_usage_error(C, "clouds: --half-width and --voxel-size must be > 0");
    const double across = atmos_scene_cloud_volume_across(half, voxel);
    if (!(across <= ATMOS_CLOUD_VOLUME_MAX_ACROSS))
        return cli_usage_error(C, "clouds: --half-width %g m in voxels of --voxel-size %g m gives %.*g voxels across (allowed 1..%d)",
                               half, voxel, across < 1e9 ? 10 : 3, across, ATMOS_CLOUD_VOLUME_MAX_ACROSS);
    if (cli_volume_output(C, "-o", out)) return CLI_EXIT_USAGE;
    cli_outputs set = {0};
    cli_outputs_add(&set, "-o", out);
    const char *inputs[1] = {scene_path};
    if (cli_outputs_check(C, &set, inputs, 1)) return CLI_EXIT_USAGE; /* -o naming the scene: refused */
    if (cli_output_folder(C, "-o", out)) return CLI_EXIT_RUNTIME;
    atmos_context *ctx = cli_context(0, 1);
    if (!ctx) return CLI_EXIT_RUNTIME;
    atmos_scene *sc = malloc(sizeof *sc);
    atmos_volume *v = NULL;
    atmos_status st = sc ? atmos_scene_load(ctx, scene_path, sc) : ATMOS_E_NOMEM;
    if (st == ATMOS_OK) st = atmos_scene_cloud_volume(ctx, sc, centre, half, voxel, &v);
    if (st == ATMOS_OK) st = atmos_volume_write_raw(ctx, v, out);
    int rc = st == ATMOS_OK ? CLI_EXIT_OK : cli_runtime_error(C, ctx, st);
    atmos_volume_destroy(v);
    free(sc);
    atmos_context_destroy(ctx);
    return rc;
}

int cli_cmd_volume(int argc, char **argv)
{
    if (argc < 2) return cli_usage_error(C, "expected a subcommand: info, generate, slice, clouds or stats");
    const char *sub = argv[1];
    if (!strcmp(sub, "--help") || !strcmp(sub, "-h")) {
        cli_volume_help();
        return CLI_EXIT_OK;
    }
    if (!strcmp(sub, "info")) return cmd_info(argc - 1, argv + 1);
    if (!strcmp(sub, "generate")) return cmd_generate(argc - 1, argv + 1);
    if (!strcmp(sub, "slice")) return cmd_slice(argc - 1, argv + 1);
    if (!strcmp(sub, "clouds")) return cmd_clouds(argc - 1, argv + 1);
    if (!strcmp(sub, "stats")) return cli_cmd_volume_stats(argc - 1, argv + 1);
    return cli_usage_error(C, "unknown subcommand '%s' (info, generate, slice, clouds, stats)", sub);
}
