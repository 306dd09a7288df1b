/* Mie theory and phase tables through the public API:
 *  1. one water droplet (radius R_UM micrometres, default 10) at 550 nm: its efficiencies and
 *     asymmetry parameter from atmos_mie, with the refractive index of water at 550 nm;
 *  2. a particle preset's phase table (default "cloud": Mie over Riley's droplet size
 *     distribution) at a few angles, printed as CSV: the angle, then the phase function at
 *     each of the three rgb wavelengths (per steradian, normalised over the sphere: an
 *     isotropic scatterer's is 1/(4 pi)).
 *
 *   mie_phase [--radius R_UM] [--preset NAME] [--fast]
 *
 * The table is built once and then read from the disk cache (atmos_context's cache_dir). */
#include <atmos/atmos.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(atmos_context *ctx, atmos_status st)
{
    fprintf(stderr, "mie_phase: %s\n", ctx ? atmos_context_error(ctx) : atmos_status_string(st));
    return 1;
}

/* Prints the efficiencies of a water sphere of radius r_um at 550 nm. */
static atmos_status one_droplet(atmos_context *ctx, double r_um)
{
    const double nm = 550.0, pi = 3.14159265358979323846;
    atmos_complex m = atmos_refractive_index_water(nm);
    atmos_mie_result res;
    atmos_status st = atmos_mie(ctx, m, 2.0 * pi * r_um * 1e3 / nm, 0, NULL, NULL, NULL, &res);
    if (st == ATMOS_OK)
        printf("# water droplet r = %g um at %g nm (m = %.4f%+.2ei): Qext %.5f  Qsca %.5f  Qback %.5f  g %.5f  (%d terms)\n",
               r_um, nm, m.re, m.im, res.qext, res.qsca, res.qback, res.g, res.terms);
    return st;
}

/* Prints the preset's asymmetry parameters and its phase function at a few angles. */
static atmos_status preset_table(atmos_context *ctx, const char *name, int fast)
{
    atmos_particle_desc p;
    atmos_phase_table *t = NULL;
    atmos_wavelengths wl;
    atmos_wavelengths_rgb(&wl);
    atmos_status st = atmos_particle_preset(ctx, name, &p);
    p.fast = fast;
    if (st == ATMOS_OK) st = atmos_phase_table_build(ctx, &p, &wl, NULL, &t);
    if (st != ATMOS_OK) return st;
    int nk = atmos_phase_table_wavelength_count(t);
    printf("# preset %s: g", name);
    for (int k = 0; k < nk; k++) printf(" %.4f (%g nm)", atmos_phase_table_g(t, k), atmos_phase_table_wavelength_nm(t, k));
    printf("\ntheta_deg");
    for (int k = 0; k < nk; k++) printf(",p_%g_nm", atmos_phase_table_wavelength_nm(t, k));
    printf("\n");
    static const double theta[] = {0, 0.5, 1, 2, 5, 10, 20, 30, 45, 60, 90, 120, 135, 138, 140, 150, 165, 175, 180};
    for (size_t i = 0; i < sizeof theta / sizeof theta[0]; i++) {
        printf("%g", theta[i]);
        for (int k = 0; k < nk; k++) printf(",%.6g", atmos_phase_table_eval(t, k, cos(theta[i] * 3.14159265358979323846 / 180)));
        printf("\n");
    }
    atmos_phase_table_destroy(t);
    return ATMOS_OK;
}

/* A number in [lo, hi] from text ("abc", "10um" and "" are refused). */
static int number_in(const char *text, double lo, double hi, double *v)
{
    char *end = NULL;
    *v = strtod(text, &end);
    return end != text && !*end && *v >= lo && *v <= hi;
}

int main(int argc, char **argv)
{
    const char *preset = "cloud";
    double r_um = 10.0;
    int fast = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--radius") && i + 1 < argc) {
            if (!number_in(argv[++i], 1e-3, 1e4, &r_um))
                return fprintf(stderr, "mie_phase: --radius %s: expected a radius in micrometres, in [0.001, 10000]\n", argv[i]), 2;
        }
        else if (!strcmp(argv[i], "--preset") && i + 1 < argc) preset = argv[++i];
        else if (!strcmp(argv[i], "--fast")) fast = 1;
        else return fprintf(stderr, "usage: mie_phase [--radius R_UM] [--preset NAME] [--fast]\n"), 2;
    }
    atmos_context *ctx = NULL;
    atmos_status st = atmos_context_create(NULL, &ctx);
    if (st != ATMOS_OK) return fail(NULL, st);
    st = one_droplet(ctx, r_um);
    if (st == ATMOS_OK) st = preset_table(ctx, preset, fast);
    int rc = st == ATMOS_OK ? 0 : fail(ctx, st);
    atmos_context_destroy(ctx);
    return rc;
}
