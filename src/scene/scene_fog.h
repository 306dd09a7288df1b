/* The optics of a scene's fog (docs/scene-format.md, "fog"): its extinction and scattering
 * coefficients and its phase function, as the renderers that draw lights in fog use them
 * (the beam renderer, the path tracer). A fog given by coefficients has a Henyey-Greenstein
 * phase function; a fog of a particle type ("particle") takes its phase function and
 * albedo from that type's table (Mie for water droplets), with its number density set by the
 * extinction at 550 nm (given, or 3.912 / visibility, Koschmieder's contrast of 2 %). The
 * renderers' fog is grey: its coefficients are the means over the scene's wavelengths, and
 * its phase function is the mean of the wavelengths' (evaluated and sampled exactly as that
 * mean). Not part of the API. */
#ifndef ATMOS_SCENE_FOG_H
#define ATMOS_SCENE_FOG_H

#include <atmos/atmos.h>

/* Koschmieder's constant: visibility V (m) = this / extinction (per m) at 550 nm. */
#define ATMOS__KOSCHMIEDER 3.912

typedef struct atmos__fog_optics {
    double sigma_t, sigma_s;    /* per metre, grey (the means over the wavelengths) */
    double g;                   /* the Henyey-Greenstein asymmetry when table is NULL; else the mean asymmetry */
    atmos_phase_table *table;   /* the particle type's table at the scene's wavelengths (owned), or NULL */
    int nwl;                    /* the table's wavelengths */
    double spread;              /* the largest relative difference of a wavelength's extinction from the mean */
} atmos__fog_optics;

/* The fog of scene s at the wavelengths wl (a fog with "particle" builds or reads its phase
 * tables: progress and cancellation through ctx). A scene without fog gives zeros. */
atmos_status atmos__fog_optics_build(atmos_context *ctx, const atmos_scene *s, const atmos_wavelengths *wl,
                                     atmos__fog_optics *out);
void atmos__fog_optics_free(atmos__fog_optics *f);
/* The phase function (per steradian) at cos(theta) mu. */
double atmos__fog_phase(const atmos__fog_optics *f, double mu);
/* cos(theta) drawn from atmos__fog_phase with one uniform u in [0, 1). */
double atmos__fog_phase_sample(const atmos__fog_optics *f, double u);

#endif
