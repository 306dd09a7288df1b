/* The fog's optics (scene_fog.h): coefficients and phase function, from the scene's numbers
 * or from a particle type's table. */
#include "scene/scene_fog.h"
#include "core/internal.h"
#include "core/vec.h"

#include <math.h>
#include <string.h>

static double hg_sample(double g, double u)
{
    if (fabs(g) < 1e-4) return 1 - 2 * u;
    const double s = (1 - g * g) / (1 - g + 2 * g * u);
    return atmos__clampd((1 + g * g - s * s) / (2 * g), -1, 1);
}

void atmos__fog_optics_free(atmos__fog_optics *f)
{
    if (!f) return;
    atmos_phase_table_destroy(f->table);
    memset(f, 0, sizeof *f);
}

/* The extinction cross-section of the particle type at 550 nm (m^2). */
static atmos_status cross_section_550(atmos_context *ctx, const atmos_particle_desc *pd, const atmos_wavelengths *wl,
                                      double *c_ext)
{
    atmos_wavelengths one = *wl;
    one.mode = ATMOS_WAVELENGTHS_SPECTRAL;
    one.count = 1, one.nm[0] = 550, one.width_nm[0] = 1;
    atmos_phase_table *t = NULL;
    const atmos_phase_table_desc td = {0};
    const atmos_status st = atmos_phase_table_build(ctx, pd, &one, &td, &t);
    if (st != ATMOS_OK) return st;
    double sca;
    atmos_phase_table_cross_sections(t, 0, c_ext, &sca);
    atmos_phase_table_destroy(t);
    if (!(*c_ext > 0))
        return atmos__error(ctx, ATMOS_E_INVALID_ARG, "fog: particle type '%s' does not extinguish light at 550 nm",
                            pd->name);
    return ATMOS_OK;
}

/* A fog of the particle type s->fog.particle: its number density from the extinction at 550 nm. */
static atmos_status from_particle(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                  atmos__fog_optics *f)
{
    atmos_particle_desc pd;
    atmos_status st = atmos_scene_particle(ctx, s, s->fog.particle, &pd);
    double c550 = 0;
    if (st == ATMOS_OK) st = cross_section_550(ctx, &pd, wl, &c550);
    const atmos_phase_table_desc td = {0};
    if (st == ATMOS_OK) st = atmos_phase_table_build(ctx, &pd, wl, &td, &f->table);
    if (st != ATMOS_OK) return st;
    const double n = s->fog.extinction_per_m / c550; /* particles per m^3 */
    f->nwl = atmos_phase_table_wavelength_count(f->table);
    double ext[ATMOS_MAX_WAVELENGTHS];
    for (int k = 0; k < f->nwl; k++) {
        double e, sc;
        atmos_phase_table_cross_sections(f->table, k, &e, &sc);
        ext[k] = n * e;
        f->sigma_t += n * e / f->nwl, f->sigma_s += n * sc / f->nwl;
        f->g += atmos_phase_table_g(f->table, k) / f->nwl;
    }
    for (int k = 0; k < f->nwl; k++) f->spread = fmax(f->spread, fabs(ext[k] / f->sigma_t - 1));
    if (!(f->sigma_t > 0) || f->sigma_t > 10)
        return atmos__error(ctx, ATMOS_E_INVALID_ARG,
                            "fog: particle type '%s' gives an extinction of %g per m at the scene's wavelengths "
                            "(allowed: (0, 10])", pd.name, f->sigma_t);
    return ATMOS_OK;
}

atmos_status atmos__fog_optics_build(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                     atmos__fog_optics *out)
{
    memset(out, 0, sizeof *out);
    if (!s->fog.enabled) return ATMOS_OK;
    if (!s->fog.particle[0]) {
        out->sigma_t = s->fog.extinction_per_m, out->sigma_s = s->fog.scattering_per_m, out->g = s->fog.g;
        return ATMOS_OK;
    }
    const atmos_status st = from_particle(ctx, s, wl, out);
    if (st != ATMOS_OK) atmos__fog_optics_free(out);
    return st;
}

double atmos__fog_phase(const atmos__fog_optics *f, double mu)
{
    if (!f->table) return atmos_phase_hg(mu, f->g);
    double p = 0;
    for (int k = 0; k < f->nwl; k++) p += atmos_phase_table_eval(f->table, k, mu);
    return p / f->nwl;
}

double atmos__fog_phase_sample(const atmos__fog_optics *f, double u)
{
    if (!f->table) return hg_sample(f->g, u);
    /* the mixture of the wavelengths' densities: a wavelength chosen by u's first part */
    const double v = u * f->nwl;
    int k = (int)v;
    if (k > f->nwl - 1) k = f->nwl - 1;
    return atmos_phase_table_sample(f->table, k, v - k);
}
