/* The volume a scene names ("volume" in a scene file): loading or generating it and
 * placing it in the world. */
#include "particles/pcloud.h"
#include "scene/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

const char *const *atmos_scene_generator_names(void)
{
    static const char *all[32];
    if (!all[0]) { /* the volume generators, then the particle clouds' (written once, the same each time) */
        int n = 0;
        for (const char *const *v = atmos_volume_generator_names(); *v && n < 24; v++) all[n++] = *v;
        for (const char *const *v = atmos__pcloud_generator_names(); *v && n < 31; v++) all[n++] = *v;
    }
    return all;
}

int atmos_scene_generator_known(const char *name, char *list, size_t n)
{
    int known = 0;
    if (list && n) list[0] = 0;
    for (const char *const *v = atmos_scene_generator_names(); *v; v++) {
        known |= name && !strcmp(*v, name);
        if (list && n) snprintf(list + strlen(list), n - strlen(list), "%s%s", *v, v[1] ? ", " : "");
    }
    return known;
}

atmos_status atmos_scene_generate_volume(atmos_context *ctx, const char *preset, const atmos_volume_generate_desc *desc,
                                         atmos_volume **out)
{
    for (const char *const *v = atmos__pcloud_generator_names(); *v; v++)
        if (preset && !strcmp(*v, preset)) {
            atmos__pcloud pc;
            double voxel;
            atmos_status st = atmos__pcloud_generate(ctx, preset, desc ? desc->seed : 1, desc ? desc->scale : 1, 0.0, &pc, &voxel);
            if (st == ATMOS_OK)
                st = atmos__pcloud_to_volume(ctx, &pc, desc && desc->voxel_size_m > 0 ? desc->voxel_size_m : voxel, out);
            atmos__pcloud_free(&pc);
            return st;
        }
    char list[512];
    /* the volume generators' own message would leave out the particle clouds' */
    if (!atmos_scene_generator_known(preset, list, sizeof list))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "generate: unknown preset '%s' (known: %s)",
                            preset ? preset : "(null)", list);
    return atmos_volume_generate(ctx, preset, desc, out);
}

atmos_status atmos_scene_load_volume(atmos_context *ctx, const atmos_scene *scene, atmos_volume **out,
                                     double offset_m[3])
{
    if (!scene || !out || !offset_m) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "scene volume: missing argument");
    *out = NULL;
    const atmos_scene_volume *sv = &scene->volume;
    if (!sv->source[0]) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "scene volume: the scene names no volume");
    atmos_status st;
    atmos_volume *vol = NULL;
    if (!strncmp(sv->source, "generate:", 9)) {
        atmos_volume_generate_desc gd;
        memset(&gd, 0, sizeof gd);
        gd.seed = sv->seed;
        gd.voxel_size_m = sv->voxel_size_m;
        gd.scale = sv->scale > 0 ? sv->scale : 1.0;
        st = atmos_scene_generate_volume(ctx, sv->source + 9, &gd, &vol);
    } else if (!strncmp(sv->source, "simulate:", 9)) {
        atmos_sim_desc sd;
        memset(&sd, 0, sizeof sd);
        sd.preset = sv->source + 9;
        sd.minutes = sv->sim_minutes;
        sd.grid = sv->sim_grid;
        sd.refine = sv->sim_refine, sd.detail = sv->sim_detail, sd.ice = sv->sim_ice;
        sd.seed = sv->seed;
        st = atmos_simulate(ctx, &sd, &vol);
    } else {
        atmos_volume_load_desc ld;
        memset(&ld, 0, sizeof ld);
        ld.grids = sv->grids[0] ? sv->grids : NULL;
        ld.field = sv->particle[0] ? sv->particle : NULL;
        ld.time_index = sv->time_index;
        ld.voxel_size_m = sv->voxel_size_m;
        ld.density_unit = sv->density_unit;
        ld.length_scale = sv->scale > 0 ? sv->scale : 1.0;
        ld.subgrid_detail = sv->subgrid_detail;
        st = atmos_volume_load(ctx, sv->source, &ld, &vol);
        if (st != ATMOS_OK) { /* the reader names the file: the scene file and its key go in front */
            return atmos__scene_file_error(ctx, st, scene, sv->source, "/volume/file", st == ATMOS_E_IO);
        }
    }
    if (st != ATMOS_OK) return st;
    atmos_scene_volume_offset(scene, vol, offset_m);
    *out = vol;
    return ATMOS_OK;
}

void atmos_scene_volume_offset(const atmos_scene *scene, const atmos_volume *volume, double offset_m[3])
{
    const atmos_scene_volume *sv = &scene->volume;
    double lo[3], hi[3];
    atmos_volume_bounds(volume, lo, hi);
    if (sv->placed) {
        /* position_m is where the centre of the box's bottom face goes. */
        offset_m[0] = sv->position_m[0] - 0.5 * (lo[0] + hi[0]);
        offset_m[1] = sv->position_m[1] - lo[1];
        offset_m[2] = sv->position_m[2] - 0.5 * (lo[2] + hi[2]);
    } else {
        /* The box's centre moved horizontally to three of its widths (at least 4 km)
         * in front of the camera, at its own altitude. */
        const atmos_camera_desc *c = &scene->camera;
        double f[3];
        for (int k = 0; k < 3; k++) f[k] = c->look_at[k] - c->position[k];
        double fh = sqrt(f[0] * f[0] + f[2] * f[2]);
        if (!(fh > 1e-9)) f[0] = 0, f[2] = -1, fh = 1; /* looking straight up or down: north */
        double width = fmax(hi[0] - lo[0], hi[2] - lo[2]), dist = fmax(3.0 * width, 4000.0);
        offset_m[0] = c->position[0] + f[0] / fh * dist - 0.5 * (lo[0] + hi[0]);
        offset_m[1] = 0.0;
        offset_m[2] = c->position[2] + f[2] / fh * dist - 0.5 * (lo[2] + hi[2]);
        /* An artist's volume has its own local frame (often centred on the origin, half
         * below it): its base goes to a cloud's altitude. */
        const char *fmt = atmos_volume_source_format(volume);
        if (!strcmp(fmt, "openvdb") || !strcmp(fmt, "nanovdb")) offset_m[1] = ATMOS_SCENE_CLOUD_BASE_M - lo[1];
    }
}

/* The camera distance along -f from the box's centre that keeps every corner inside the
 * pinhole's half-angles (tan_h horizontal, tan_v vertical). */
static double framing_distance(const double lo[3], const double hi[3], const double f[3], const double r[3],
                               const double u[3], double tan_h, double tan_v)
{
    double d = 0;
    for (int n = 0; n < 8; n++) {
        double q[3];
        for (int a = 0; a < 3; a++) q[a] = ((n >> a) & 1 ? hi[a] : lo[a]) - 0.5 * (lo[a] + hi[a]);
        double qf = q[0] * f[0] + q[1] * f[1] + q[2] * f[2], qr = q[0] * r[0] + q[1] * r[1] + q[2] * r[2],
               qu = q[0] * u[0] + q[1] * u[1] + q[2] * u[2];
        d = fmax(d, qf + fabs(qr) / tan_h);
        d = fmax(d, qf + fabs(qu) / tan_v);
    }
    return d;
}

void atmos_scene_frame_volume(atmos_scene *scene, const atmos_volume *volume, const double offset_m[3],
                              double view_elevation_deg)
{
    if (!scene || !volume || !offset_m || scene->camera.type != ATMOS_CAMERA_PINHOLE) return;
    atmos_camera_desc *c = &scene->camera;
    double lo[3], hi[3], ctr[3];
    atmos_volume_bounds(volume, lo, hi);
    for (int a = 0; a < 3; a++) lo[a] += offset_m[a], hi[a] += offset_m[a], ctr[a] = 0.5 * (lo[a] + hi[a]);
    /* The view direction: the camera's heading at the view elevation (negative: down). */
    double h[3] = {c->look_at[0] - c->position[0], 0, c->look_at[2] - c->position[2]};
    double hn = sqrt(h[0] * h[0] + h[2] * h[2]);
    if (!(hn > 1e-9)) h[0] = 0, h[2] = -1, hn = 1;
    const double el = view_elevation_deg * ATMOS_DEG2RAD;
    double f[3] = {cos(el) * h[0] / hn, sin(el), cos(el) * h[2] / hn};
    double r[3] = {-f[2], 0, f[0]}, rn = sqrt(r[0] * r[0] + r[2] * r[2]);
    for (int a = 0; a < 3; a++) r[a] /= rn;
    double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    const double aspect = scene->height > 0 ? (double)scene->width / scene->height : 1.0;
    const double tan_v = tan(0.5 * c->fov_deg * ATMOS_DEG2RAD), tan_h = tan_v * aspect;
    const double d = 1.1 * framing_distance(lo, hi, f, r, u, tan_h, tan_v);
    for (int a = 0; a < 3; a++) c->position[a] = ctr[a] - d * f[a];
    if (c->position[1] < 2.0) c->position[1] = 2.0; /* above the ground, still looking at the centre */
    memcpy(c->look_at, ctr, sizeof ctr);
    c->up[0] = 0, c->up[1] = 1, c->up[2] = 0;
    if (fabs(f[1]) > 0.99999) memcpy(c->up, u, sizeof u); /* straight down or up: the heading's way is the top */
}

/* The largest extinction (m^-1) any voxel can have: every field's densest voxel times its
 * largest cross-section over the wavelengths, summed, times the scene's density scale. */
static double peak_extinction(const atmos_scene *scene, const atmos_volume *vol, const atmos_volume_optics *optics)
{
    const double scale = scene->volume.density_scale > 0 ? scene->volume.density_scale : 1.0;
    double peak = 0;
    for (int f = 0; f < optics->count && f < atmos_volume_field_count(vol); f++) {
        atmos_volume_field_stats fs;
        if (!optics->phase[f] || atmos_volume_field_stats_get(NULL, vol, f, &fs) != ATMOS_OK) continue;
        double sigma = 0;
        for (int k = 0; k < atmos_phase_table_wavelength_count(optics->phase[f]); k++) {
            double e = 0, sca = 0;
            atmos_phase_table_cross_sections(optics->phase[f], k, &e, &sca);
            if (e > sigma) sigma = e;
        }
        peak += fs.max * sigma;
    }
    return scale * peak;
}

/* Below the ground (y = 0; none in a vacuum): the box's top at or under it, nothing of the
 * volume is seen from above (a position in km for m, or a model's origin at sea level). */
static void below_ground_warning(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *vol,
                                 const double offset_m[3], const char *name)
{
    double lo[3], hi[3];
    atmos_volume_bounds(vol, lo, hi);
    if (!offset_m || scene->atmosphere.kind == ATMOS_ATMOSPHERE_VACUUM || !(hi[1] + offset_m[1] <= 0)) return;
    atmos__log(ctx, ATMOS_LOG_WARN,
               "%s: below the ground: its box spans %.0f to %.0f m in height (y), all under the ground at 0, so "
               "the image will not show it; raise it (\"position_m\" in \"volume\", or --volume-position on the "
               "command line, in metres, is where the centre of the box's bottom face goes)",
               name, lo[1] + offset_m[1], hi[1] + offset_m[1]);
}

void atmos__scene_volume_warnings(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *vol,
                                  const atmos_volume_optics *optics, const double offset_m[3])
{
    const atmos_scene_volume *sv = &scene->volume;
    const char *name = sv->source[0] ? sv->source : "the volume";
    below_ground_warning(ctx, scene, vol, offset_m, name);
    /* A scene written when VDB values were read as particles per m^3 scaled them by ~1e8;
     * read as a 0..1 fraction (1 = 1e8 m^-3) they would be that much denser again. */
    const char *fmt = atmos_volume_source_format(vol);
    if (sv->density_unit == ATMOS_DENSITY_AUTO && sv->density_scale >= 1e3 &&
        (!strcmp(fmt, "openvdb") || !strcmp(fmt, "nanovdb")))
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "%s: read as a 0..1 density (1 = %g m^-3) and then scaled by %g: for values in particles per m^3 "
                   "give \"density_unit\": \"per_m3\" (--density-unit per_m3)",
                   name, ATMOS_DENSITY_FRACTION_PER_M3, sv->density_scale);
    /* Too thin to see: no ray across the box can have an optical depth above the peak
     * extinction times the box's diagonal. Under 0.01 the volume dims and lights less than
     * 1 % of what crosses it, and the image is the sky alone. */
    if (!optics) return;
    double lo[3], hi[3];
    atmos_volume_bounds(vol, lo, hi);
    const double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                             (hi[2] - lo[2]) * (hi[2] - lo[2]));
    const double peak = peak_extinction(scene, vol, optics), tau = peak * diag;
    if (diag > 0 && !(peak > 0))
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "%s: empty: every value is 0 (or the fields' particles do not scatter), so the image will be the "
                   "sky alone; no density scale can change that (check the file's grids or fields: atmos volume info)",
                   name);
    else if (diag > 0 && tau < ATMOS__SCENE_THIN_TAU)
        atmos__log(ctx, ATMOS_LOG_WARN,
                   "%s: nearly invisible: its peak extinction is %.3g m^-1, so no ray across its %.0f m box has an "
                   "optical depth above %.3g (the image will be the sky alone); if the file's values are not what "
                   "the density unit says, give --density-unit (\"density_unit\": per_m3, g_m3 or fraction), or "
                   "raise --density-scale (\"density_scale\", now %g)",
                   name, peak, diag, tau, sv->density_scale > 0 ? sv->density_scale : 1.0);
}
