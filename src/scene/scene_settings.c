/* The renderers' settings tables (scene.h, atmos_renderer_settings): the one description of
 * every setting of a scene file's renderer sections ("slice", "path", "harris"). The scene's defaults, the
 * JSON parser (scene_json.c), the validator (scene_validate.c), atmos render's options and
 * its --help are all made from these rows, so a setting has one name, one range, one default
 * and one meaning everywhere. */
#include "scene/scene_internal.h"

#include <stddef.h>
#include <string.h>

#define SLICE(field) offsetof(atmos_scene, slice.field)
#define PATH(field) offsetof(atmos_scene, path.field)
#define NISHITA(field) offsetof(atmos_scene, nishita.field)
#define HARRIS(field) offsetof(atmos_scene, harris.field)
#define BEAMS(field) offsetof(atmos_scene, beams.field)

static const char *const update_names[] = {"eq25", "eq24", NULL};
/* indexed by atmos_slice_field */
static const char *const field_names[] = {"auto", "do", "p1", "none", NULL};

static const atmos_setting slice_settings[] = {
    {"slices", "slices", ATMOS_SETTING_INT, "", 0, 8192, 0, 0, 0, NULL, 0,
     "sampling planes across the volume; 0 = chosen from the volume's shape (256 to 2048)", SLICE(slices)},
    {"light_size", "light-size", ATMOS_SETTING_INT, "texels", 8, 8192, 0, 0, 256, NULL, 0,
     "light buffer texels per side", SLICE(light_size)},
    {"xi", "xi", ATMOS_SETTING_REAL, "sr^-1", 0, 100, 0, 0, 0.1 / (4.0 * 3.14159265358979323846), NULL, 0,
     "Riley's back-scatter term added to Ams (Eq. 26); 0 = none", SLICE(xi)},
    {"update", "eq24", ATMOS_SETTING_CHOICE, "", 0, 0, 0, 0, 0, update_names, 1,
     "light-buffer update: eq25 (the paper's) or eq24 (the exact product of F_i; the flag selects it)",
     SLICE(eq24)},
    {"low_albedo", "low-albedo", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 0, NULL, 1,
     "single scattering with the plain phase function, light attenuated by T only, plus xi's ambient (xi 0: the first order alone; Riley Fig. 13)",
     SLICE(low_albedo)},
    {"grid_max_dim", "grid-max-dim", ATMOS_SETTING_INT, "voxels", 8, 2048, 0, 0, 256, NULL, 0,
     "the volume is box-filtered onto a grid of at most this many voxels per axis", SLICE(grid_max_dim)},
    {"eye_scale", "eye-scale", ATMOS_SETTING_REAL, "", 0, 2, 1, 0, 1, NULL, 0,
     "eye buffer resolution relative to the image, per axis, in (0, 1] or 2 (0.5: a quarter of the "
     "rays, upsampled; 2: four rays per pixel, averaged: antialiased)",
     SLICE(eye_scale)},
    {"edge_aa", "edge-aa", ATMOS_SETTING_REAL, "", 0, 1, 0, 0, 0.05, NULL, 0,
     "with eye scale 1: four rays, averaged, in the pixels whose transmittance through the volume "
     "differs from a neighbour's by more than this (the silhouette); 0 = off",
     SLICE(edge_aa)},
    {"max_order", "max-order", ATMOS_SETTING_INT, "", 1, 1000, 0, 0, 64, NULL, 0,
     "orders of Ams tabulated (higher scattering orders use the last)", SLICE(max_order)},
    {"field", "slice-p1", ATMOS_SETTING_CHOICE, "", 0, 0, 0, 0, 0, field_names, ATMOS_SLICE_FIELD_P1,
     "the light scattered more than once: p1 (the flag: Riley's Eq. 24/25, Ams and xi plus a diffusion field of "
     "the light they drop), do (the first order in the delta-M scaled medium, the orders >= 2 by discrete "
     "ordinates, the sky's and the ground's light through its faces), none (Eq. 24/25 alone); auto, the default: "
     "do, but p1 when xi or update is set, none when diffuse is false or low_albedo is set (docs/lightfield.md)",
     SLICE(field)},
    {"diffuse", "no-diffuse", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "a field of the light scattered more than once, as field chooses; false: field none, Riley's Eq. 24/25 "
     "alone, which lose most of the light of dense clouds",
     SLICE(diffuse)},
    {"do", "slice-do", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 0, NULL, 1,
     "the same as field do, the default (its cells nishita.mc_cell render voxels: the one nishita setting it "
     "takes); false in a file without field: p1, what it meant before 2026-12-06",
     SLICE(do_field)},
    {"air_shadows", "no-air-shadows", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "the volume's shadow on the air's single scattering (light shafts, crepuscular rays); "
     "off: the air is lit as if the volume were not there",
     SLICE(air_shadows)},
};

static const atmos_setting path_settings[] = {
    {"spp", "spp", ATMOS_SETTING_INT, "", 1, 1000000, 0, 0, 64, NULL, 0, "samples per pixel", PATH(spp)},
    {"time_budget_s", "time-budget", ATMOS_SETTING_REAL, "s", 0, 1e7, 0, 0, 0, NULL, 0,
     "stop when this much time has passed (a pass it cuts is discarded); 0 = none", PATH(time_budget_s)},
    {"seed", "seed", ATMOS_SETTING_SEED, "", 0, 9007199254740992.0, 0, 0, 1, NULL, 0,
     "random seed: same seed, same image", PATH(seed)},
    {"max_depth", "max-depth", ATMOS_SETTING_INT, "", 0, 100000, 0, 0, 0, NULL, 0,
     "scattering events per path; 0 = the default limit of 10000", PATH(max_depth)},
    {"truncate_deg", "truncate", ATMOS_SETTING_REAL, "deg", 0, 20, 0, 0, 0, NULL, 0,
     "cut every phase function's forward peak at this angle, the part above counting as unscattered "
     "(less noise in droplet clouds, changes light within it of the forward direction); 0 = exact",
     PATH(truncate_deg)},
    {"sky_nee", "no-sky-nee", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "next-event estimation toward the sky (off: same mean, more noise)", PATH(sky_nee)},
    {"forced", "no-forced", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "forced single scattering on camera rays (off: same mean, more noise in thin media)", PATH(forced)},
    {"aureole", "no-aureole", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "the aureole estimate in droplet clouds (off: same mean, more fireflies)", PATH(aureole)},
    {"roulette", "no-roulette", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "with lights and fog, Russian roulette from the 4th event by the lights' nearness (off: same mean, "
     "paths in a fog that absorbs nothing walk to the depth limit)",
     PATH(roulette)},
};

static const atmos_setting nishita_settings[] = {
    {"orders", "nishita-orders", ATMOS_SETTING_INT, "", 1, 3, 0, 0, 3, NULL, 0,
     "with do off, the highest scattering order of the sunlight (1: single scattering; 2, 3: by reference "
     "patterns)",
     NISHITA(orders)},
    {"ratio", "nishita-ratio", ATMOS_SETTING_REAL, "", 0, 1, 1, 0, 0.95, NULL, 0,
     "the share r of the sample space's contribution the reference patterns keep", NISHITA(ratio)},
    {"paths", "nishita-paths", ATMOS_SETTING_INT, "", 1, 100000, 0, 0, 1024, NULL, 0,
     "order-3 paths computed per cell (n1, chosen at random among the pattern's)", NISHITA(paths)},
    {"cells", "nishita-cells", ATMOS_SETTING_INT, "", 4, 96, 0, 0, 32, NULL, 0,
     "the light field's grid: at most this many cells per axis", NISHITA(cells)},
    {"sky", "no-nishita-sky", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "the sky's and the ground's light, by sky elements or the do field's inflow (off: none)", NISHITA(sky)},
    {"step_pct", "nishita-step", ATMOS_SETTING_INT, "%", 5, 400, 0, 0, 50, NULL, 0,
     "eye-ray step, per cent of a render voxel", NISHITA(step_scale_pct)},
    {"diffuse", "nishita-diffuse", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 0, NULL, 1,
     "the slice renderer's diffuse light field of all orders and Riley's scattered forward beam where the "
     "medium is thick, instead of the orders 2-3 and the sky elements there (docs/lightfield.md); off: "
     "orders 1-3 only, which lose most of the light of dense clouds",
     NISHITA(diffuse)},
    {"mc_kphotons", "nishita-mc", ATMOS_SETTING_INT, "", 0, 100000, 0, 0, 0, NULL, 0,
     "diagnostic: orders >= 2 from photons (thousands per wavelength) traced from the sun, the medium "
     "cut at 3 deg, toward the eye (see mc_lmax); in place of the orders 2-3, the sky elements and "
     "the diffuse field, so the sky's light is left out (docs/lightfield.md); 0 = off",
     NISHITA(mc_kphotons)},
    {"mc_cell", "nishita-mc-cell", ATMOS_SETTING_INT, "voxels", 1, 16, 0, 0, 4, NULL, 0,
     "the Monte Carlo field's cell edge, render voxels", NISHITA(mc_cell)},
    {"mc_lmax", "nishita-mc-lmax", ATMOS_SETTING_INT, "", -1, 3, 0, 0, -1, NULL, 0,
     "the Monte Carlo field's angles: -1 = toward the view's centre only; 0-3 = spherical harmonics "
     "of this degree", NISHITA(mc_lmax)},
    {"mc_delta_m", "nishita-mc-delta-m", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 1,
     "on by default; with mc_lmax >= 0: the photons and the field's part of the eye rays in the delta-M "
     "scaled medium of that degree (its forward peak above the degree counted as not scattered)",
     NISHITA(mc_delta_m)},
    {"do", "nishita-do", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 1,
     "on by default: the field of every order >= 2 and the sky's light in spherical harmonics (degree "
     "mc_lmax, 3 if -1) solved by discrete ordinates on its cells, not by photons (docs/lightfield.md); "
     "-D nishita.do=false -D nishita.mc_delta_m=false: Nishita 1996 as written, orders 2-3 by reference "
     "patterns and sky elements, which lose most of a dense cloud's light",
     NISHITA(do_field)},
    {"mc_dm_clip", "nishita-mc-dm-clip", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 0, NULL, 1,
     "with mc_delta_m: the photons sample the scaled phase exactly (the cut phase, its peak clipped until "
     "delta-M's fraction is gone) instead of Henyey-Greenstein of its g*",
     NISHITA(mc_dm_clip)},
    {"edge_aa", "nishita-edge-aa", ATMOS_SETTING_REAL, "", 0, 1, 0, 0, 0.05, NULL, 0,
     "four eye rays, averaged, in the pixels whose transmittance through the volume differs from a "
     "neighbour's by more than this (the silhouette); 0 = one ray a pixel",
     NISHITA(edge_aa)},
};

static const atmos_setting harris_settings[] = {
    {"spacing_m", "spacing", ATMOS_SETTING_REAL, "m", 0, 1e5, 0, 0, 0, NULL, 0,
     "one particle per cell of this edge; 0 = the volume's voxel, coarser until at most max_particles (the "
     "harris_ generators: their own lattice)",
     HARRIS(spacing_m)},
    {"max_particles", "max-particles", ATMOS_SETTING_INT, "", 1, 20000000, 0, 0, 50000, NULL, 0,
     "the most particles made from the volume (with spacing 0)", HARRIS(max_particles)},
    {"sky_lights", "sky-lights", ATMOS_SETTING_INT, "", 0, 16, 0, 0, 6, NULL, 0,
     "sky lights besides the sun: the zenith and directions 30 degrees high (Harris 2002 §2.3.1); 0 = the sun alone",
     HARRIS(sky_lights)},
    {"light_size", "harris-light-size", ATMOS_SETTING_INT, "texels", 0, 4096, 0, 0, 0, NULL, 0,
     "light buffer texels per side; 0 = 0.7 of the smallest particle's width a texel, at most 1024",
     HARRIS(light_size)},
    {"impostors", "no-impostors", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "draw each cloud from an impostor made again when the eye has moved round it (Harris 2002 §3); off: every "
     "particle every frame",
     HARRIS(impostors)},
    {"impostor_tolerance_deg", "impostor-tolerance", ATMOS_SETTING_REAL, "deg", 0, 10, 0, 0, 0.15, NULL, 0,
     "the angle the eye may move round a cloud before its impostor is made again (Harris: 0.15 imperceptible, up to 1)",
     HARRIS(impostor_tolerance_deg)},
    {"impostor_max_res", "impostor-max-res", ATMOS_SETTING_INT, "texels", 16, 4096, 0, 0, 512, NULL, 0,
     "an impostor's texels per side at most", HARRIS(impostor_max_res)},
    {"diffuse", "no-harris-diffuse", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 1, NULL, 0,
     "each particle also scatters the diffuse light field of all orders (the light the forward passes drop, "
     "by the slice renderer's diffusion solve on the volume's grid) toward the eye; off: Harris's forward "
     "shading alone, dense clouds far too dark (docs/particles.md)",
     HARRIS(diffuse)},
};

static const atmos_setting beams_settings[] = {
    {"plane_spacing_m", "plane-spacing", ATMOS_SETTING_REAL, "m", 0, 1e5, 0, 0, 0, NULL, 0,
     "distance between the main sampling planes along the view; 0 = 1/40 of the depth the lights reach in view",
     BEAMS(plane_spacing_m)},
    {"epsilon", "beams-epsilon", ATMOS_SETTING_REAL, "", 0, 1, 1, 0, 0.01, NULL, 0,
     "sub-planes: each may add at most this share of the pixel's unshadowed airlight (Dobashi et al. 2002 §4.2.2)",
     BEAMS(epsilon)},
    {"max_subplanes", "max-subplanes", ATMOS_SETTING_INT, "", 1, 4096, 0, 0, 64, NULL, 0,
     "sub-planes between two main planes at most (1: none, the main planes alone)", BEAMS(max_subplanes)},
    {"shadow_size", "shadow-size", ATMOS_SETTING_INT, "texels", 16, 8192, 0, 0, 512, NULL, 0,
     "shadow map texels per side (per cube face for a point light)", BEAMS(shadow_size)},
    {"sun", "beams-sun", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 0, NULL, 1,
     "the scene's sun lights the fog and the objects too: a directional light with a shadow map", BEAMS(sun)},
    {"interleave", "interleave", ATMOS_SETTING_INT, "pixels", 1, 8, 0, 0, 1, NULL, 0,
     "interleaved sampling (Keller and Heidrich 2001): the pixels of each N x N block sample between the planes at N^2 "
     "different offsets, their airlight averaged over N x N pixels of similar depth (1: off)",
     BEAMS(interleave)},
    {"screen_step", "screen-step", ATMOS_SETTING_INT, "pixels", 1, 16, 0, 0, 16, NULL, 0,
     "the airlight evaluated every N pixels and interpolated across the cells whose corners agree, per pixel "
     "elsewhere, the sky behind on the sky's grid of every N pixels, at most 4 (1: every pixel; with interleave 1)",
     BEAMS(screen_step)},
    {"exact_shadows", "exact-shadows", ATMOS_SETTING_BOOL, "", 0, 1, 0, 0, 0, NULL, 1,
     "the surfaces' shadows of the lights by an exact ray per pixel and light (off: from the shadow maps where "
     "they settle it)",
     BEAMS(exact_shadows)},
};

const atmos_setting *atmos_renderer_settings(atmos_renderer_kind renderer, int *count)
{
    int n = 0;
    const atmos_setting *t = NULL;
    if (renderer == ATMOS_RENDERER_SLICE) t = slice_settings, n = (int)(sizeof slice_settings / sizeof *t);
    if (renderer == ATMOS_RENDERER_PATH) t = path_settings, n = (int)(sizeof path_settings / sizeof *t);
    if (renderer == ATMOS_RENDERER_NISHITA) t = nishita_settings, n = (int)(sizeof nishita_settings / sizeof *t);
    if (renderer == ATMOS_RENDERER_HARRIS) t = harris_settings, n = (int)(sizeof harris_settings / sizeof *t);
    if (renderer == ATMOS_RENDERER_BEAMS) t = beams_settings, n = (int)(sizeof beams_settings / sizeof *t);
    if (count) *count = n;
    return t;
}

const char *atmos_renderer_name(atmos_renderer_kind renderer)
{
    static const char *const names[] = {"sky", "slice", "path", "nishita", "harris", "beams"};
    return renderer >= ATMOS_RENDERER_SKY && renderer <= ATMOS_RENDERER_LAST ? names[renderer] : NULL;
}

const char *atmos_slice_field_name(atmos_slice_field field)
{
    return field >= ATMOS_SLICE_FIELD_AUTO && field <= ATMOS_SLICE_FIELD_NONE ? field_names[field] : NULL;
}

double atmos_scene_setting_get(const atmos_scene *s, const atmos_setting *st)
{
    const char *p = (const char *)s + st->offset;
    switch (st->type) {
    case ATMOS_SETTING_REAL: {
        double v;
        memcpy(&v, p, sizeof v);
        return v;
    }
    case ATMOS_SETTING_SEED: {
        uint64_t v;
        memcpy(&v, p, sizeof v);
        return (double)v;
    }
    default: {
        int v;
        memcpy(&v, p, sizeof v);
        return v;
    }
    }
}

void atmos_scene_setting_set(atmos_scene *s, const atmos_setting *st, double v)
{
    char *p = (char *)s + st->offset;
    if (st->type == ATMOS_SETTING_REAL) {
        memcpy(p, &v, sizeof v);
    } else if (st->type == ATMOS_SETTING_SEED) {
        uint64_t u = v > 0 ? (uint64_t)v : 0;
        memcpy(p, &u, sizeof u);
    } else {
        int i = (int)v;
        memcpy(p, &i, sizeof i);
    }
}

void atmos__settings_defaults(atmos_scene *s)
{
    for (int r = ATMOS_RENDERER_SLICE; r <= ATMOS_RENDERER_LAST; r++) {
        int n;
        const atmos_setting *t = atmos_renderer_settings((atmos_renderer_kind)r, &n);
        for (int i = 0; i < n; i++) atmos_scene_setting_set(s, &t[i], t[i].def);
    }
}
