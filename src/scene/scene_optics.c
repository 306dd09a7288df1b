/* The optics of a scene's volume: for every field, the phase table (sigma_ext, albedo and
 * P(theta) per wavelength) of the particle type atmos_volume_field_particle() names, looked
 * up with atmos_scene_particle(), and optionally its multiple-scattering phase functions
 * Ams_n (Riley et al. 2004 Eq. 20-23). Built once per scene and volume (the tables come
 * from the disk cache when they can) and shared by every renderer. */
#include "core/internal.h"

#include <string.h>

void atmos_volume_optics_free(atmos_volume_optics *o)
{
    if (!o) return;
    if (o->owned)
        for (int i = 0; i < o->count; i++) {
            atmos_msphase_destroy((atmos_msphase *)o->ms[i]);
            atmos_phase_table_destroy((atmos_phase_table *)o->phase[i]);
        }
    memset(o, 0, sizeof *o);
}

atmos_status atmos_volume_optics_build(atmos_context *ctx, const atmos_scene *scene, const atmos_volume *volume,
                                       int with_msphase, atmos_volume_optics *out)
{
    if (!scene || !volume || !out) return atmos__error(ctx, ATMOS_E_INVALID_ARG, "volume optics: missing argument");
    memset(out, 0, sizeof *out);
    out->owned = 1;
    atmos_wavelengths wl;
    atmos_status st = atmos_scene_wavelengths(ctx, scene, &wl);
    if (st != ATMOS_OK) return st;
    int nf = atmos_volume_field_count(volume);
    for (int i = 0; i < nf; i++) {
        atmos_particle_desc pd;
        const char *name = atmos_volume_field_particle(volume, i);
        /* a generated volume's cloud droplets take the scene's "particle" (a file's one field
         * has it from the reader already; rain and ice keep their own) */
        if (scene->volume.particle[0] && !strncmp(scene->volume.source, "generate:", 9) && name &&
            !strcmp(name, "cloud"))
            name = scene->volume.particle;
        if ((st = atmos_scene_particle(ctx, scene, name, &pd)) != ATMOS_OK) goto fail;
        atmos_phase_table *t = NULL;
        atmos_phase_table_desc td = {0};
        if ((st = atmos_phase_table_build(ctx, &pd, &wl, &td, &t)) != ATMOS_OK) goto fail;
        out->phase[i] = t;
        out->count = i + 1;
        if (!with_msphase) continue;
        atmos_msphase *m = NULL;
        atmos_msphase_desc md = {0};
        md.max_order = 64;
        if ((st = atmos_msphase_build(ctx, t, &md, &m)) != ATMOS_OK) goto fail;
        out->ms[i] = m;
    }
    out->count = nf;
    return ATMOS_OK;
fail:
    atmos_volume_optics_free(out);
    return st;
}
