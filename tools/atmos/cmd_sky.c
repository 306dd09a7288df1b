/* atmos sky: the atmosphere (Riley et al. 2004 §4.1 by default) along one view. */
#include "cli.h"
#include "outputs.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static void help(void)
{
    printf("Usage: atmos sky --sun-elevation E [--sun-azimuth A] --view-elevation e --view-azimuth a\n"
           "                 [--altitude h] [--distance K] [--spectral N] [--albedo R]\n"
           "                 [--model riley|homogeneous|dobashi|spherical] [--thickness M] [--json]\n"
           "       atmos sky --table NAME|list [--model NAME] [--spectral N] [--albedo R] [-o FILE]\n\n"
           "Prints, per wavelength, the radiance the air scatters toward the observer along one view,\n"
           "the transmittance along it and the sun's attenuated radiance at the observer (over the\n"
           "disk's solid angle). riley: single scattering in closed form (Riley et al. 2004 Eq. 15,\n"
           "corrected; Eq. 11, 12); homogeneous: closed forms too; dobashi: single scattering by\n"
           "Dobashi et al. 2002's tables; spherical: every order of scattering (docs/sky.md).\n\n"
           "  --sun-elevation E    sun elevation, degrees above the horizon [-90, 90]\n"
           "  --sun-azimuth A      sun azimuth, degrees [0, 360) clockwise from north (default 180)\n"
           "  --view-elevation e   view elevation, degrees [-90, 90]\n"
           "  --view-azimuth a     view azimuth, degrees [0, 360) clockwise from north\n"
           "  --altitude h         observer altitude, metres in [0, 1e8] (default 0)\n"
           "  --distance K         path length, metres > 0 (default: to the ground or to space)\n"
           "  --spectral N         N spectral samples in 380-780 nm (default: rgb = 680, 550, 440 nm)\n"
           "  --albedo R           ground albedo [0, 1] (default 0.1; used when the view hits the ground)\n"
           "  --model NAME         riley (the flat exponential atmosphere, default), homogeneous (a uniform\n"
           "                       layer from the ground to --thickness; docs/models.md), dobashi or\n"
           "                       spherical (the Earth's atmosphere over a spherical planet; docs/sky.md)\n"
           "  --atmosphere NAME    the same as --model\n"
           "  --thickness M        the homogeneous layer's top, metres (default 8000); goes with\n"
           "                       --model homogeneous (a usage error with the other models)\n"
           "  --table NAME -o FILE instead of a view: write the model's look-up table NAME as FILE.exr\n"
           "                       (every wavelength), .pfm (the first three) or .png (a plot, each\n"
           "                       channel scaled to its maximum; a missing folder is made). Only\n"
           "                       dobashi and spherical keep tables: --model spherical --table list\n"
           "                       prints that model's names, one a line; --table list with a model\n"
           "                       that keeps none (riley, the default, or homogeneous) prints every\n"
           "                       model's. The view options (--sun-*, --view-*, --altitude,\n"
           "                       --distance, --json) do not go with --table, nor -o without it\n"
           "  --json               one JSON object: {\"wavelengths_nm\", \"inscatter\", \"transmittance\",\n"
           "                       \"sun\", \"ground\", \"distance_m\", \"hits_ground\"}\n"
           "  -h, --help           show this help\n\n"
           "Units: radiance W m^-2 sr^-1 nm^-1. \"inscatter\" is the air's in-scattered radiance only;\n"
           "\"ground\" is the lit ground's radiance after the air (0 unless the view ends on the\n"
           "ground); \"sun\" is the radiance of the sun's 0.5 degree disk seen from the observer.\n"
           "distance_m is null when the path reaches space.\n");
    fputs(CLI_HELP_EXIT, stdout);
}

/* The context and the atmosphere of the options; on failure the exit code in *rc and
 * nothing to free. */
static atmos_atmosphere *make_sky(const char *C, atmos_atmosphere_kind kind, int spectral, double albedo, double top,
                                  atmos_context **ctx, atmos_wavelengths *wl, int *rc)
{
    *ctx = cli_context(1, 0);
    if (!*ctx) {
        *rc = CLI_EXIT_RUNTIME;
        return NULL;
    }
    if (spectral) atmos_wavelengths_spectral(spectral, wl);
    else atmos_wavelengths_rgb(wl);
    atmos_atmosphere_desc ad;
    atmos_atmosphere_defaults(&ad);
    if (albedo >= 0) ad.ground_albedo = albedo;
    ad.kind = kind;
    if (top > 0) ad.thickness_m = top;
    atmos_atmosphere *sky = NULL;
    atmos_status st = atmos_atmosphere_create(*ctx, &ad, wl, &sky);
    if (st != ATMOS_OK) {
        *rc = cli_runtime_error(C, *ctx, st);
        atmos_context_destroy(*ctx);
        *ctx = NULL;
    }
    return sky;
}

/* --table: the model's tables, no view. */
static int sky_table(const char *C, atmos_atmosphere_kind kind, int spectral, double albedo, const char *table,
                     const char *out)
{
    atmos_context *ctx;
    atmos_wavelengths wl;
    int rc = cli_sky_table_check(C, kind, table, out);
    if (rc >= 0) return rc;
    if (cli_output_folder(C, "-o", out)) return CLI_EXIT_RUNTIME;
    atmos_atmosphere *atm = make_sky(C, kind, spectral, albedo, 0, &ctx, &wl, &rc);
    if (!atm) return rc;
    rc = cli_sky_table(C, ctx, atm, table, out);
    atmos_atmosphere_destroy(atm);
    atmos_context_destroy(ctx);
    return rc;
}

typedef struct {
    double sun_el, sun_az, view_el, view_az, alt, dist, albedo, top;
    atmos_atmosphere_kind kind;
    int spectral, json;
} sky_opts;

/* One view: in-scatter, transmittance, the sun and the ground along it, printed. */
static int sky_view(const char *C, const sky_opts *o)
{
    atmos_context *ctx;
    atmos_wavelengths wl;
    int rc;
    atmos_atmosphere *sky = make_sky(C, o->kind, o->spectral, o->albedo, o->top, &ctx, &wl, &rc);
    if (!sky) return rc;
    double sun[3], dir[3], eye[3] = {0, o->alt, 0};
    atmos_direction_from_angles(o->sun_el, o->sun_az, sun);
    atmos_direction_from_angles(o->view_el, o->view_az, dir);
    const double ground0[3] = {0, 0, 0};
    double K = atmos_atmosphere_ground_distance(sky, eye, dir);
    if (o->dist < K) K = o->dist;
    int n = wl.count, hits_ground = !isinf(K) && K == atmos_atmosphere_ground_distance(sky, eye, dir);
    double ins[ATMOS_MAX_WAVELENGTHS], tr[ATMOS_MAX_WAVELENGTHS], sunr[ATMOS_MAX_WAVELENGTHS],
        ground[ATMOS_MAX_WAVELENGTHS], lit[ATMOS_MAX_WAVELENGTHS];
    atmos_atmosphere_inscatter(sky, eye, dir, K, sun, ins);
    atmos_atmosphere_transmittance(sky, eye, dir, K, tr);
    atmos_atmosphere_sun_radiance(sky, eye, sun, sunr);
    atmos_atmosphere_sunlight(sky, ground0, sun, lit);
    if (o->kind == ATMOS_ATMOSPHERE_DOBASHI || o->kind == ATMOS_ATMOSPHERE_SPHERICAL) {
        /* a round ground: what the view ray sees there beyond the air's own light */
        double all[ATMOS_MAX_WAVELENGTHS];
        atmos_atmosphere_radiance(sky, eye, dir, sun, all, NULL);
        for (int i = 0; i < n; i++) ground[i] = hits_ground ? fmax(all[i] - ins[i], 0.0) : 0.0;
    } else {
        const double albedo_pi = atmos_atmosphere_ground_albedo(sky) / 3.14159265358979323846;
        for (int i = 0; i < n; i++) ground[i] = hits_ground && sun[1] > 0 ? albedo_pi * sun[1] * lit[i] * tr[i] : 0.0;
    }
    if (o->json) {
        printf("{\"wavelengths_nm\": ");
        cli_print_json_array(wl.nm, n);
        printf(", \"inscatter\": ");
        cli_print_json_array(ins, n);
        printf(", \"transmittance\": ");
        cli_print_json_array(tr, n);
        printf(", \"sun\": ");
        cli_print_json_array(sunr, n);
        printf(", \"ground\": ");
        cli_print_json_array(ground, n);
        if (isinf(K)) printf(", \"distance_m\": null");
        else printf(", \"distance_m\": %.9g", K);
        printf(", \"hits_ground\": %s}\n", hits_ground ? "true" : "false");
    } else {
        printf("# path: %s", isinf(K) ? "to space" : hits_ground ? "to the ground" : "fixed distance");
        if (!isinf(K)) printf(", %.6g m", K);
        printf("\n# radiance in W m^-2 sr^-1 nm^-1\n");
        printf("%10s %14s %14s %14s %14s\n", "lambda_nm", "inscatter", "transmittance", "sun", "ground");
        for (int i = 0; i < n; i++)
            printf("%10.2f %14.6e %14.6e %14.6e %14.6e\n", wl.nm[i], ins[i], tr[i], sunr[i], ground[i]);
    }
    atmos_atmosphere_destroy(sky);
    atmos_context_destroy(ctx);
    return CLI_EXIT_OK;
}

int cli_cmd_sky(int argc, char **argv)
{
    static const struct option opts[] = {
        {"sun-elevation", required_argument, 0, 'E'}, {"sun-azimuth", required_argument, 0, 'A'},
        {"view-elevation", required_argument, 0, 'e'}, {"view-azimuth", required_argument, 0, 'a'},
        {"altitude", required_argument, 0, 'z'},      {"distance", required_argument, 0, 'K'},
        {"spectral", required_argument, 0, 'n'},      {"albedo", required_argument, 0, 'r'},
        {"json", no_argument, 0, 'j'},                {"help", no_argument, 0, 'H'},
        {"atmosphere", required_argument, 0, 'k'},    {"thickness", required_argument, 0, 't'},
        {"model", required_argument, 0, 'k'},         {"table", required_argument, 0, 'L'},
        {"output", required_argument, 0, 'o'},
        {0, 0, 0, 0}};
    sky_opts o = {NAN, 180, NAN, NAN, 0, INFINITY, -1, 0, ATMOS_ATMOSPHERE_RILEY, 0, 0};
    int c, thickness = 0, li = -1;
    const char *C = "sky", *table = NULL, *out = NULL, *view_opt = NULL;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:h", opts, &li)) != -1) {
        /* the first option of a view, to refuse it with --table */
        if (!view_opt && c > 0 && strchr("EAeazKj", c) && li >= 0) view_opt = opts[li].name;
        switch (c) {
        case 'E': if (!cli_parse_double(C, "--sun-elevation", optarg, &o.sun_el)) return CLI_EXIT_USAGE; break;
        case 'A': if (!cli_parse_azimuth(C, "--sun-azimuth", optarg, &o.sun_az)) return CLI_EXIT_USAGE; break;
        case 'e': if (!cli_parse_double(C, "--view-elevation", optarg, &o.view_el)) return CLI_EXIT_USAGE; break;
        case 'a': if (!cli_parse_azimuth(C, "--view-azimuth", optarg, &o.view_az)) return CLI_EXIT_USAGE; break;
        case 'z': if (!cli_parse_double(C, "--altitude", optarg, &o.alt)) return CLI_EXIT_USAGE; break;
        case 'K': if (!cli_parse_double(C, "--distance", optarg, &o.dist)) return CLI_EXIT_USAGE; break;
        case 'r': if (!cli_parse_double(C, "--albedo", optarg, &o.albedo)) return CLI_EXIT_USAGE; break;
        case 'n': if (!cli_parse_int(C, "--spectral", optarg, 1, ATMOS_MAX_WAVELENGTHS, &o.spectral)) return CLI_EXIT_USAGE; break;
        case 'j': o.json = 1; break;
        case 'L': table = optarg; break;
        case 'o': out = optarg; break;
        case 'k':
            if (!cli_sky_model(optarg, &o.kind))
                return cli_usage_error(C, "--model: expected riley, homogeneous, dobashi or spherical, got '%s'",
                                       optarg);
            break;
        case 't':
            if (!cli_parse_double(C, "--thickness", optarg, &o.top)) return CLI_EXIT_USAGE; /* its message given */
            if (!(o.top >= 1 && o.top <= 1e6))
                return cli_usage_error(C, "--thickness: expected metres in [1, 1000000]");
            thickness = 1;
            break;
        case 'h':
        case 'H': help(); return CLI_EXIT_OK;
        default: return cli_usage_error(C, "unknown or incomplete option '%s'", argv[optind - 1]);
        }
    }
    if (optind < argc) return cli_usage_error(C, "unexpected argument '%s'", argv[optind]);
    /* options that do not apply are refused, as `atmos render` refuses another renderer's */
    if (thickness && o.kind != ATMOS_ATMOSPHERE_HOMOGENEOUS)
        return cli_usage_error(C, "--thickness goes with --model homogeneous (the model here is %s)",
                               cli_sky_model_name(o.kind));
    if (out && !table) return cli_usage_error(C, "-o goes with --table (a view prints to standard output)");
    if (table && view_opt)
        return cli_usage_error(C, "--%s does not go with --table (the tables do not depend on the view)", view_opt);
    if (o.albedo != -1 && (o.albedo < 0 || o.albedo > 1))
        return cli_usage_error(C, "--albedo: must be in [0, 1], got %g", o.albedo);
    if (table) return sky_table(C, o.kind, o.spectral, o.albedo, table, out);
    if (isnan(o.sun_el)) return cli_usage_error(C, "--sun-elevation is required");
    if (isnan(o.view_el)) return cli_usage_error(C, "--view-elevation is required");
    if (isnan(o.view_az)) return cli_usage_error(C, "--view-azimuth is required");
    if (o.sun_el < -90 || o.sun_el > 90) return cli_usage_error(C, "--sun-elevation: must be in [-90, 90], got %g", o.sun_el);
    if (o.view_el < -90 || o.view_el > 90)
        return cli_usage_error(C, "--view-elevation: must be in [-90, 90], got %g", o.view_el);
    if (!(o.alt >= 0 && o.alt <= 1e8)) /* a scene camera's y: atmos render refuses the same */
        return cli_usage_error(C, "--altitude: must be in [0, 100000000] metres, got %g", o.alt);
    if (!(o.dist > 0)) return cli_usage_error(C, "--distance: must be > 0 metres, got %g", o.dist);
    return sky_view(C, &o);
}
